//! slip_reference — which speed a flat-belt recording's longitudinal slip
//! refers to, read from the free-rolling samples.
//!
//! A flat-belt rig records the belt speed V and the wheel speed Ω. The wheel
//! centre moves at V relative to the belt; its component in the wheel plane
//! is Vx = V·cos α, and the Magic Formula's slip is κ = (Ω·Re − Vx)/Vx
//! (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §2.2, eq. 2.9): the
//! **wheel-plane** reference. Rig software (and rig simulators) often define
//! the slip ratio SR = Ω·Re/V − 1 on the belt speed itself and feed the tyre
//! that: the **belt** reference, Vx = V. At α = 6° the two differ by
//! 1/cos α − 1 = 0.55 % of slip, ≈ 10 % of Fz of Fx on a car tyre.
//!
//! The signature in the data: while the tyre rolls freely through a lateral
//! sweep, its slip stays where the free-rolling torque balance puts it. In
//! the tyre's own reference, ln(V/Ω) = ln Re − ln(1 + κ) + ln(V/Vx), so the
//! coefficient s of x = −ln cos α in a regression of ln(V/Ω) over the
//! free-rolling samples (with a smooth Re(Fz)) is 1 for the wheel-plane
//! reference and 0 for the belt one — plus a drift of one sign: free-rolling
//! Fx is the rolling resistance (Fx ≤ 0), and the combined-slip weight
//! Gxα ≤ 1 (Pacejka eq. 4.E57) makes the same Fx need more braking slip at
//! larger |α|, which raises V/Ω further. Hence with Fx ≤ 0 the wheel-plane
//! reading needs s ≥ 1 and the belt reading s ≥ 0: an s well below 1
//! contradicts the wheel-plane reading and leaves only the belt one (and the
//! mirror rule holds for a free-rolling Fx > 0). [`detect`] applies that
//! test with a margin of [`MARGIN`] for noise; when the data cannot decide
//! (no wheel speed, too few free-rolling samples, no slip-angle leverage) the
//! textbook wheel-plane reference stays.
//!
//! Must never: switch the reference on a recording that states Vx itself,
//! or decide from fewer samples than [`MIN_FREE`] / [`MIN_WIDE`].

use super::Sample;

/// The speed κ = Ω·Re/Vx − 1 refers to on a flat-belt rig.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum SlipReference {
    /// Vx = V·cos α: the wheel-centre velocity in the wheel plane (ISO, Pacejka §2.2).
    #[default]
    WheelPlane,
    /// Vx = V: the slip ratio is referred to the belt speed (SR = Ω·Re/V − 1).
    Belt,
}

impl SlipReference {
    /// The longitudinal speed of the wheel centre for belt speed `v` at slip angle `alpha`.
    #[inline]
    pub fn vx(self, v: f64, alpha: f64) -> f64 {
        match self {
            SlipReference::WheelPlane if alpha.is_finite() => v * alpha.cos(),
            _ => v,
        }
    }

    /// Short statement for reports.
    pub fn describe(self) -> &'static str {
        match self {
            SlipReference::WheelPlane => "Vx = V·cos α (wheel plane)",
            SlipReference::Belt => "Vx = V (slip referred to the belt speed)",
        }
    }
}

/// Margin on the share s for noise and unmodelled drift: the wheel-plane
/// reading is rejected only when s < 1 − MARGIN (Fx ≤ 0), i.e. when at least
/// a quarter of the 1/cos α growth of V/Ω it predicts is missing — several
/// times the scatter of s between recordings of one tyre (≈ 0.05–0.1).
pub const MARGIN: f64 = 0.25;
/// Fewest free-rolling samples a decision needs.
pub const MIN_FREE: usize = 200;
/// Fewest free-rolling samples at |α| > 3° (the leverage of the regression).
pub const MIN_WIDE: usize = 100;

/// What [`detect`] found.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SlipReferenceEvidence {
    /// The reference the data support.
    pub reference: SlipReference,
    /// Coefficient s of −ln cos α in ln(V/Ω) over the free-rolling samples.
    pub share: f64,
    /// Median Fx/Fz of the free-rolling samples (0 when Fx is not recorded).
    pub free_fx_ratio: f64,
    /// Free-rolling samples used.
    pub samples: usize,
}

impl SlipReferenceEvidence {
    /// One line for `data summary` / `fit`.
    pub fn describe(&self) -> String {
        format!(
            "{}: free-rolling V/Ω grows with s = {:.2} × (1/cos α) over {} samples (wheel plane needs s ≥ 1, belt s ≥ 0, at free-rolling Fx/Fz = {:+.3})",
            self.reference.describe(),
            self.share,
            self.samples,
            self.free_fx_ratio
        )
    }
}

/// Decide the slip reference from samples with belt speed `belt_speed` (m/s,
/// one per sample) and wheel speed `Sample::omega`; `None` when the data
/// cannot decide (see the module doc).
pub fn detect(samples: &[Sample], belt_speed: &[f64]) -> Option<SlipReferenceEvidence> {
    let fz_max = samples
        .iter()
        .map(|s| s.fz)
        .filter(|f| f.is_finite())
        .fold(0.0f64, f64::max);
    if !(fz_max > 0.0) {
        return None;
    }
    let lim = 15f64.to_radians();
    // (F = Fz/Fz_max, x = −ln cos α, y = ln(V/Ω), Fx/Fz)
    let rows: Vec<(f64, f64, f64, f64)> = samples
        .iter()
        .zip(belt_speed)
        .filter(|(s, &v)| s.fz > 0.05 * fz_max && v > 1.0 && s.omega > 1.0 && s.alpha.abs() < lim)
        .map(|(s, &v)| {
            (
                s.fz / fz_max,
                -s.alpha.cos().ln(),
                (v / s.omega).ln(),
                s.fx / s.fz,
            )
        })
        .collect();
    // Free rolling: V/Ω near the straight-running ln Re(Fz) (a quadratic in
    // Fz fitted at |α| < 1°, trimmed twice to the bulk so drive/brake runs
    // do not pull it). ±3 % of ln(V/Ω) keeps the lateral sweeps (slip of a
    // few 0.1 %, plus ≤ 2.3 % of 1/cos α at 12°) and drops driven rows.
    let straight = 1f64.to_radians();
    let straight_x = -straight.cos().ln();
    let mut base: Option<[f64; 3]> = None;
    for tol in [f64::INFINITY, 0.05, 0.02] {
        let pts = rows
            .iter()
            .filter(|r| r.1 < straight_x && base.is_none_or(|c| (r.2 - quad(&c, r.0)).abs() < tol));
        base = Some(lsq::<3>(pts.map(|r| ([1.0, r.0, r.0 * r.0], r.2)))?);
    }
    let base = base?;
    let free: Vec<&(f64, f64, f64, f64)> = rows
        .iter()
        .filter(|r| (r.2 - quad(&base, r.0)).abs() < 0.03)
        .collect();
    let wide_x = -(3f64.to_radians().cos().ln());
    let wide = free.iter().filter(|r| r.1 > wide_x).count();
    if free.len() < MIN_FREE || wide < MIN_WIDE {
        return None;
    }
    let c = lsq::<4>(free.iter().map(|r| ([1.0, r.0, r.0 * r.0, r.1], r.2)))?;
    let share = c[3];
    let mut fx: Vec<f64> = free.iter().map(|r| r.3).filter(|u| u.is_finite()).collect();
    let free_fx_ratio = if fx.is_empty() {
        0.0
    } else {
        let m = fx.len() / 2;
        *fx.select_nth_unstable_by(m, f64::total_cmp).1
    };
    // Fx ≤ 0: wheel plane needs s ≥ 1; Fx > 0 mirrors: belt needs s ≤ 0.
    let belt = if free_fx_ratio <= 0.0 {
        share < 1.0 - MARGIN
    } else {
        share < MARGIN
    };
    Some(SlipReferenceEvidence {
        reference: if belt {
            SlipReference::Belt
        } else {
            SlipReference::WheelPlane
        },
        share,
        free_fx_ratio,
        samples: free.len(),
    })
}

fn quad(c: &[f64; 3], f: f64) -> f64 {
    c[0] + c[1] * f + c[2] * f * f
}

/// Least squares through the normal equations (N ≤ 4 regressors, scaled
/// O(1)); `None` when singular or fewer than 20 rows.
fn lsq<const N: usize>(rows: impl Iterator<Item = ([f64; N], f64)>) -> Option<[f64; N]> {
    let mut ata = nalgebra::SMatrix::<f64, N, N>::zeros();
    let mut atb = nalgebra::SVector::<f64, N>::zeros();
    let mut n = 0usize;
    for (a, y) in rows {
        if !y.is_finite() || a.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let a = nalgebra::SVector::<f64, N>::from(a);
        ata += a * a.transpose();
        atb += a * y;
        n += 1;
    }
    if n < 20 {
        return None;
    }
    // A relative ridge of 1e-10 keeps a single-load recording (F constant)
    // solvable: the Fz terms then take the minimum-norm share of the mean.
    let ridge = 1e-10 * ata.trace() / N as f64;
    for i in 0..N {
        ata[(i, i)] += ridge;
    }
    let x = ata.cholesky()?.solve(&atb);
    x.iter().all(|v| v.is_finite()).then(|| x.into())
}
