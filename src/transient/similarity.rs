//! similarity — Magic Formula forces at a slip point on a road of friction
//! scale `s` (the similarity method), the hot-path evaluations every model
//! of this module calls, and the [`Slip`] point they take.
//!
//! Must never: allocate, or change a bit of the result when `s = 1`.

use super::Kinematics;
use crate::mf::{Forces, LoadTerms, MfInput, SlipProps, Tyre, UseMode};

/// Magic Formula forces at slips (κ, tan α) on a road of friction scale `s`
/// (the hot-path [`Tyre::forces`]; the slip-independent outputs come from the
/// probe, see [`tyre_props`](super::tyre_props)).
///
/// `mu_scale` is applied by the similarity method (Pacejka 3rd ed. §4.3.2;
/// Radt & Pacejka): a friction change by `s` that leaves the slip stiffness
/// unchanged maps the pure-slip curve as F_s(κ) = s·F(κ/s), exactly for
/// D = μFz with B·C·D fixed (what LMUX/LMUY do to the MF core), approximately
/// for the shifts, the combined-slip weights and Mz (scaled by s: the trail
/// times the scaled Fy, the residual torque's D ∝ μy). Mx is the MF's own
/// overturning moment at the scaled Fy ([`Tyre::overturning_moment`], one
/// more Mx evaluation when s ≠ 1): its inclination and load terms do not
/// depend on the road's friction, and scaling them by s had given
/// |Mx| > 10·Fz·R0 at 86° inclination with μ ×4.3 (the FMU fuzzer,
/// 1 Dec 2026). My is unscaled. No parameter copy.
/// A native `mu_scale` in `MfInput` (scaling LMUX/LMUY inside the MF) would
/// make this exact — see the transient report.
#[inline]
pub fn mf_at(tyre: &Tyre, base: &MfInput, mode: UseMode, slip: Slip, s: f64) -> Forces {
    similar_forces(
        tyre,
        base,
        mode,
        tyre.forces(&similar_input(base, slip, s), mode),
        s,
    )
}

/// [`mf_at`] without My (NaN; [`Tyre::forces_with`]) and with the step's
/// [`LoadTerms`] (the same bits): the transient models take My from the
/// zero-slip probe.
#[inline]
pub(crate) fn mf_at_no_my(
    tyre: &Tyre,
    base: &MfInput,
    mode: UseMode,
    slip: Slip,
    s: f64,
    pre: Option<&LoadTerms<f64>>,
) -> Forces {
    let f = tyre.forces_with(&similar_input(base, slip, s), mode, 1.0, false, pre);
    similar_forces(tyre, base, mode, f, s)
}

/// [`mf_at`] plus the slip-independent properties of the same evaluation
/// ([`Tyre::forces_and_props`]; at the MF's own friction, as the probe).
#[inline]
pub(crate) fn mf_at_props(
    tyre: &Tyre,
    base: &MfInput,
    mode: UseMode,
    slip: Slip,
    s: f64,
) -> (Forces, SlipProps) {
    let (f, p) = tyre.forces_and_props(&similar_input(base, slip, s), mode, 1.0);
    (similar_forces(tyre, base, mode, f, s), p)
}

/// The similarity method's scaling of [`mf_at`]: Fx, Fy, Mz × s, Mx the
/// MF's at the scaled Fy (the inclination, load and pressure of `base`).
#[inline]
fn similar_forces(tyre: &Tyre, base: &MfInput, mode: UseMode, mut o: Forces, s: f64) -> Forces {
    if s != 1.0 {
        o.fx *= s;
        o.fy *= s;
        o.mz *= s;
        o.mx = tyre.overturning_moment(base, mode, o.fy);
    }
    o
}

/// Fx, Fy of [`mf_at`] only (bit-identical to its), without the moment
/// equations ([`Tyre::forces_xy`]); `pre`: the step's [`LoadTerms`] where
/// they belong to the same Fz, p, γ (the same bits either way).
#[inline]
pub fn mf_at_xy(
    tyre: &Tyre,
    base: &MfInput,
    mode: UseMode,
    slip: Slip,
    s: f64,
    pre: Option<&LoadTerms<f64>>,
) -> (f64, f64) {
    let (fx, fy) = tyre.forces_xy(&similar_input(base, slip, s), mode, 1.0, pre);
    if s != 1.0 {
        (fx * s, fy * s)
    } else {
        (fx, fy)
    }
}

/// The MF input of [`mf_at`]: the slips divided by the friction scale `s`
/// (the similarity method), as given for `s = 1`.
#[inline]
fn similar_input(base: &MfInput, slip: Slip, s: f64) -> MfInput {
    let mut mi = *base;
    if s == 1.0 {
        mi.kappa = slip.kappa;
        mi.alpha = slip.alpha;
    } else {
        mi.kappa = slip.kappa / s;
        mi.alpha = (slip.tan_alpha / s).atan();
    }
    mi
}

/// A slip point: κ, tan α and α (kept together so α = atan(tan α) is computed once).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Slip {
    /// Longitudinal slip ratio κ (–), positive when driving.
    pub kappa: f64,
    /// Tangent of the slip angle, tan α (–; ISO-W sign).
    pub tan_alpha: f64,
    /// Slip angle α = atan(tan α) (rad).
    pub alpha: f64,
}

impl Slip {
    /// From κ and tan α.
    #[inline]
    pub fn new(kappa: f64, tan_alpha: f64) -> Slip {
        Slip {
            kappa,
            tan_alpha,
            alpha: tan_alpha.atan(),
        }
    }
    /// The kinematic slips of a step.
    #[inline]
    pub fn of(k: &Kinematics) -> Slip {
        Slip {
            kappa: k.kappa,
            tan_alpha: k.tan_alpha,
            alpha: k.alpha,
        }
    }
}

/// The slips scaled by a slip-stiffness scale `c` (see [`StepCtx::stiff`]).
#[inline]
pub(crate) fn stiff_slip(c: f64, sl: Slip) -> Slip {
    if c == 1.0 {
        sl
    } else {
        Slip::new(c * sl.kappa, c * sl.tan_alpha)
    }
}
