//! loss — robust loss functions ρ(z) of the squared, scaled residual
//! z = w·r²/c², applied by iteratively re-weighted least squares (IRLS).
//!
//! The definitions are those of SciPy's `least_squares` (so costs compare
//! one-to-one in the benchmark): the cost of a residual is ½·c²·ρ(z), and the
//! IRLS weight is ρ'(z), which makes the Gauss–Newton gradient exact
//! (∇ = Σ ρ'(z)·w·r·∇r).
//!
//! Must never: return a negative weight, or a non-finite value for finite z.

/// Robust loss kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
pub enum LossKind {
    /// ρ(z) = z: plain least squares.
    #[default]
    Linear,
    /// ρ(z) = z for z ≤ 1, 2√z − 1 beyond (quadratic core, linear tails).
    Huber,
    /// ρ(z) = 2(√(1+z) − 1): a smooth Huber.
    SoftL1,
    /// ρ(z) = ln(1+z): redescending influence, strongest outlier rejection.
    Cauchy,
}

/// A loss: its kind and the residual scale c where it leaves the quadratic
/// regime (in residual units, e.g. newtons).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Loss {
    /// Shape ρ of the loss.
    pub kind: LossKind,
    /// Residual scale c (> 0, residual units); irrelevant for
    /// [`LossKind::Linear`].
    pub scale: f64,
}

impl Default for Loss {
    fn default() -> Self {
        Loss {
            kind: LossKind::Linear,
            scale: 1.0,
        }
    }
}

impl Loss {
    /// Plain least squares.
    pub fn linear() -> Loss {
        Loss::default()
    }

    /// A robust loss with scale `c` (> 0).
    pub fn new(kind: LossKind, scale: f64) -> Loss {
        Loss { kind, scale }
    }

    /// Parse "linear", "huber", "soft_l1" (or "soft-l1"), "cauchy".
    pub fn parse_kind(s: &str) -> crate::Result<LossKind> {
        match s.to_ascii_lowercase().replace('-', "_").as_str() {
            "linear" | "ls" => Ok(LossKind::Linear),
            "huber" => Ok(LossKind::Huber),
            "soft_l1" => Ok(LossKind::SoftL1),
            "cauchy" => Ok(LossKind::Cauchy),
            other => Err(crate::Error::Input(format!(
                "loss '{other}': expected linear, huber, soft_l1 or cauchy"
            ))),
        }
    }

    /// ρ(z) and ρ'(z) for z ≥ 0.
    #[inline]
    pub fn rho(&self, z: f64) -> (f64, f64) {
        match self.kind {
            LossKind::Linear => (z, 1.0),
            LossKind::Huber => {
                if z <= 1.0 {
                    (z, 1.0)
                } else {
                    let s = z.sqrt();
                    (2.0 * s - 1.0, 1.0 / s)
                }
            }
            LossKind::SoftL1 => {
                let s = (1.0 + z).sqrt();
                (2.0 * (s - 1.0), 1.0 / s)
            }
            LossKind::Cauchy => ((1.0 + z).ln(), 1.0 / (1.0 + z)),
        }
    }

    /// Cost contribution ½c²ρ(w r²/c²) and the IRLS weight w·ρ'(w r²/c²) of
    /// one residual `r` with data weight `w`.
    #[inline]
    pub fn cost_and_weight(&self, r: f64, w: f64) -> (f64, f64) {
        if self.kind == LossKind::Linear {
            return (0.5 * w * r * r, w);
        }
        let c2 = self.scale * self.scale;
        let (rho, drho) = self.rho(w * r * r / c2);
        (0.5 * c2 * rho, w * drho)
    }

    /// Total cost ½ Σ c²ρ(wᵢ rᵢ²/c²).
    pub fn cost(&self, r: &[f64], w: Option<&[f64]>) -> f64 {
        match w {
            Some(w) => r
                .iter()
                .zip(w)
                .map(|(&r, &w)| self.cost_and_weight(r, w).0)
                .sum(),
            None => r.iter().map(|&r| self.cost_and_weight(r, 1.0).0).sum(),
        }
    }
}

/// A robust estimate of the residual scale: 1.4826 × the median absolute
/// residual (the MAD about zero, consistent with σ for Gaussian noise).
/// Useful to set [`Loss::scale`] from a first plain fit.
pub fn mad_scale(r: &[f64]) -> f64 {
    if r.is_empty() {
        return 0.0;
    }
    let mut a: Vec<f64> = r.iter().map(|x| x.abs()).filter(|x| !x.is_nan()).collect();
    if a.is_empty() {
        return 0.0;
    }
    let mid = a.len() / 2;
    let (_, m, _) = a.select_nth_unstable_by(mid, |x, y| x.total_cmp(y));
    1.4826 * *m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ρ' must be the derivative of ρ: check by central differences at a few z
    /// (step 1e-6, error O(h²)·ρ''' ≈ 1e-12, so 1e-8 is generous).
    #[test]
    fn derivative_matches_rho() {
        for kind in [
            LossKind::Linear,
            LossKind::Huber,
            LossKind::SoftL1,
            LossKind::Cauchy,
        ] {
            let l = Loss::new(kind, 1.0);
            for z in [0.1, 0.5, 2.0, 10.0, 100.0] {
                let h = 1e-6;
                let num = (l.rho(z + h).0 - l.rho(z - h).0) / (2.0 * h);
                assert!((num - l.rho(z).1).abs() < 1e-8, "{kind:?} z={z}");
            }
            // all losses agree with least squares near zero: ρ(z) ≈ z
            assert!((l.rho(1e-8).0 - 1e-8).abs() < 1e-15);
        }
    }

    #[test]
    fn mad_of_known_values() {
        // |r| = 1,2,3,4,5 → median 3
        assert!((mad_scale(&[-1.0, 2.0, -3.0, 4.0, 5.0]) - 1.4826 * 3.0).abs() < 1e-12);
    }
}
