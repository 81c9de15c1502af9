//! The old benchmark stand-in, now test support only (the fitter tests use it
//! as a cheap, independent model; included by `#[path]`): a pure-lateral Magic-Formula-shaped fit of 18
//! parameters to 100 000 synthetic samples, by this crate's fitter and by
//! SciPy `least_squares` over NumPy (`python/bench_fit.py`) on the SAME model,
//! data, start and bounds; wall time and final cost of both, and the ratio.
//!
//! BENCHMARK STAND-IN: the model below ([`LateralStandIn`]) is a compact
//! pure-lateral Magic Formula written here only so the fitter can be timed
//! before the generic (AD-capable) `mf` module lands. It is NOT the project's
//! Magic Formula and must not be used for anything else. Its equations follow
//! the MF 6.1 pure-Fy structure (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed.,
//! eqs. 4.E19–4.E30) without scaling factors, turn slip, pressure or the
//! E ≤ 1 limit:
//!   dfz = (Fz − Fz0)/Fz0,  γ inclination,
//!   SHy = PHY1 + PHY2·dfz + PHY3·γ,  αy = α + SHy,
//!   C = PCY1,  D = (PDY1 + PDY2·dfz)(1 − PDY3·γ²)·Fz,
//!   Ky = PKY1·Fz0·sin(2·atan(Fz/(PKY2·Fz0)))·(1 − PKY3·|γ|),  B = Ky/(C·D),
//!   E = (PEY1 + PEY2·dfz)(1 − (PEY3 + PEY4·γ)·sgn αy),
//!   SVy = Fz·(PVY1 + PVY2·dfz + (PVY3 + PVY4·dfz)·γ),
//!   Fy = D·sin(C·atan(B·αy − E·(B·αy − atan(B·αy)))) + SVy.
//! `python/bench_fit.py` implements the same equations in NumPy.
//!
//! Must never: assert on timings, or be mistaken for the real MF.

use nalgebra::DMatrixViewMut;
use rand::{Rng, SeedableRng};
use tyrekit::fit::problem::par_rows;
use tyrekit::fit::{Param, Problem};

/// Parameter names of the stand-in, in θ order.
pub const NAMES: [&str; 18] = [
    "pcy1", "pdy1", "pdy2", "pdy3", "pey1", "pey2", "pey3", "pey4", "pky1", "pky2", "pky3", "phy1",
    "phy2", "phy3", "pvy1", "pvy2", "pvy3", "pvy4",
];
/// The "true" tyre the data are generated from (a typical passenger-car set).
pub const TRUTH: [f64; 18] = [
    1.3, 1.05, -0.08, 2.0, -0.8, -0.6, 0.1, -6.0, -18.0, 1.9, 0.4, 0.002, 0.001, 0.03, 0.02, -0.01,
    -0.2, 0.1,
];
/// A different tyre to start from.
pub const START: [f64; 18] = [
    1.5, 0.9, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -12.0, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
];
/// Bounds.
pub const LOWER: [f64; 18] = [
    1.0, 0.1, -1.0, -10.0, -5.0, -5.0, -1.0, -20.0, -100.0, 0.3, -2.0, -0.1, -0.1, -1.0, -0.5,
    -0.5, -2.0, -2.0,
];
pub const UPPER: [f64; 18] = [
    2.0, 3.0, 1.0, 10.0, 0.9, 5.0, 1.0, 20.0, -1.0, 5.0, 2.0, 0.1, 0.1, 1.0, 0.5, 0.5, 2.0, 2.0,
];
/// Nominal load (N).
pub const FZ0: f64 = 4000.0;

/// Fy of the stand-in and, if `grad` is given, ∂Fy/∂θ (all 18) by the chain rule.
pub fn lateral_fy(t: &[f64], alpha: f64, fz: f64, gamma: f64, grad: Option<&mut [f64; 18]>) -> f64 {
    let dfz = (fz - FZ0) / FZ0;
    let sh = t[11] + t[12] * dfz + t[13] * gamma;
    let ay = alpha + sh;
    let c = t[0];
    let mu0 = t[1] + t[2] * dfz;
    let cg = 1.0 - t[3] * gamma * gamma;
    let d = mu0 * cg * fz;
    let u = fz / (t[9] * FZ0);
    // sin(2·atan u) = 2u/(1+u²), cos(2·atan u) = (1−u²)/(1+u²)
    let s2 = 2.0 * u / (1.0 + u * u);
    let kg = 1.0 - t[10] * gamma.abs();
    let ky = t[8] * FZ0 * s2 * kg;
    let b = ky / (c * d);
    let sg = if ay > 0.0 {
        1.0
    } else if ay < 0.0 {
        -1.0
    } else {
        0.0
    };
    let e0 = t[4] + t[5] * dfz;
    let es = 1.0 - (t[6] + t[7] * gamma) * sg;
    let e = e0 * es;
    let sv = fz * (t[14] + t[15] * dfz + (t[16] + t[17] * dfz) * gamma);
    let x = b * ay;
    let atx = x.atan();
    let phi = x - e * (x - atx);
    let atphi = phi.atan();
    let y = c * atphi;
    let (sy, cy) = y.sin_cos();
    let fy = d * sy + sv;
    if let Some(g) = grad {
        let gphi = d * cy * c / (1.0 + phi * phi); // ∂Fy/∂φ
        let dphidx = 1.0 - e * x * x / (1.0 + x * x);
        let dfe = -gphi * (x - atx); // ∂Fy/∂E
        let dfb = gphi * dphidx * ay; // ∂Fy/∂B
        let dfsh = gphi * dphidx * b; // ∂Fy/∂SHy
        let dfc = d * cy * atphi - dfb * b / c; // ∂Fy/∂C (direct + via B)
        let dfd = sy - dfb * b / d; // ∂Fy/∂D (direct + via B)
        let dfky = dfb / (c * d); // ∂Fy/∂Ky
        g[0] = dfc;
        g[1] = dfd * cg * fz;
        g[2] = dfd * cg * fz * dfz;
        g[3] = -dfd * mu0 * gamma * gamma * fz;
        g[4] = dfe * es;
        g[5] = dfe * es * dfz;
        g[6] = -dfe * e0 * sg;
        g[7] = -dfe * e0 * sg * gamma;
        g[8] = dfky * FZ0 * s2 * kg;
        // d sin(2 atan u)/dPKY2 = cos(2 atan u)·2/(1+u²)·(−u/PKY2)
        g[9] = dfky * t[8] * FZ0 * kg * (1.0 - u * u) / (1.0 + u * u) * 2.0 / (1.0 + u * u)
            * (-u / t[9]);
        g[10] = -dfky * t[8] * FZ0 * s2 * gamma.abs();
        g[11] = dfsh;
        g[12] = dfsh * dfz;
        g[13] = dfsh * gamma;
        g[14] = fz;
        g[15] = fz * dfz;
        g[16] = fz * gamma;
        g[17] = fz * dfz * gamma;
    }
    fy
}

/// The synthetic lateral data set: columns α (rad), Fz (N), γ (rad), Fy (N).
pub struct LateralData {
    pub alpha: Vec<f64>,
    pub fz: Vec<f64>,
    pub gamma: Vec<f64>,
    pub fy: Vec<f64>,
}

impl LateralData {
    /// `n` samples: slip sweeps ±0.25 rad at loads 2–8 kN and inclinations
    /// −3°, 0°, +3°, with Gaussian noise of 1 % of the nominal peak force
    /// (seeded, so every run sees the same data).
    pub fn generate(n: usize, seed: u64) -> LateralData {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let loads = [2000.0, 4000.0, 6000.0, 8000.0];
        let gammas = [-0.0524, 0.0, 0.0524];
        let conds = loads.len() * gammas.len();
        let per = n.div_ceil(conds);
        let sd = 0.01 * TRUTH[1] * FZ0;
        let mut d = LateralData {
            alpha: Vec::with_capacity(n),
            fz: Vec::with_capacity(n),
            gamma: Vec::with_capacity(n),
            fy: Vec::with_capacity(n),
        };
        'o: for &fz in &loads {
            for &g in &gammas {
                for i in 0..per {
                    if d.alpha.len() == n {
                        break 'o;
                    }
                    // triangle sweep +0.25 → −0.25 → +0.25 rad
                    let ph = i as f64 / per as f64;
                    let a = -0.25 * (1.0 - 4.0 * (ph - 0.5).abs());
                    // Box–Muller
                    let (u1, u2): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
                    let z = (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos();
                    d.alpha.push(a);
                    d.fz.push(fz);
                    d.gamma.push(g);
                    d.fy.push(lateral_fy(&TRUTH, a, fz, g, None) + sd * z);
                }
            }
        }
        d
    }
}

/// The stand-in as a fit [`Problem`]: residual = model − measured Fy.
pub struct LateralStandIn {
    pub data: LateralData,
    pub params: Vec<Param>,
    /// Threads for evaluating rows (results do not depend on it).
    pub threads: usize,
}

impl LateralStandIn {
    pub fn new(data: LateralData) -> LateralStandIn {
        let params = (0..18)
            .map(|i| Param::new(NAMES[i], START[i], LOWER[i], UPPER[i]))
            .collect();
        LateralStandIn {
            data,
            params,
            threads: 1,
        }
    }
}

impl Problem for LateralStandIn {
    fn params(&self) -> &[Param] {
        &self.params
    }
    fn n_residuals(&self) -> usize {
        self.data.fy.len()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        let d = &self.data;
        par_rows(self.threads, 0, r, None, &|first, r: &mut [f64], _| {
            for (k, rk) in r.iter_mut().enumerate() {
                let i = first + k;
                *rk = lateral_fy(theta, d.alpha[i], d.fz[i], d.gamma[i], None) - d.fy[i];
            }
        });
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        let d = &self.data;
        par_rows(
            self.threads,
            0,
            r,
            Some(jac),
            &|first, r: &mut [f64], jac| {
                let Some(jac) = jac else { return };
                let mut g = [0.0; 18];
                for (k, rk) in r.iter_mut().enumerate() {
                    let i = first + k;
                    *rk =
                        lateral_fy(theta, d.alpha[i], d.fz[i], d.gamma[i], Some(&mut g)) - d.fy[i];
                    for (j, &c) in cols.iter().enumerate() {
                        jac[(k, j)] = g[c];
                    }
                }
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stand-in's analytic gradient against central differences
    /// (step 1e-6·max(|θ|,1); truncation O(h²) ≈ 1e-12 relative, rounding
    /// ≈ 1e-16·|Fy|/h ≈ 1e-6 N → 1e-5 relative to the larger of the two is ample).
    #[test]
    fn stand_in_gradient_matches_finite_differences() {
        for &(a, fz, g) in &[
            (0.05, 3000.0, 0.03),
            (-0.12, 7000.0, -0.05),
            (0.2, 5000.0, 0.0),
        ] {
            let mut grad = [0.0; 18];
            lateral_fy(&TRUTH, a, fz, g, Some(&mut grad));
            for k in 0..18 {
                let h = 1e-6 * TRUTH[k].abs().max(1.0);
                let mut tp = TRUTH;
                let mut tm = TRUTH;
                tp[k] += h;
                tm[k] -= h;
                let num =
                    (lateral_fy(&tp, a, fz, g, None) - lateral_fy(&tm, a, fz, g, None)) / (2.0 * h);
                let scale = num.abs().max(grad[k].abs()).max(1e-3);
                assert!(
                    (num - grad[k]).abs() < 1e-5 * scale,
                    "{} at α={a}: {num} vs {}",
                    NAMES[k],
                    grad[k]
                );
            }
        }
    }
}
