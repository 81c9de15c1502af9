//! transient — the brush as the steady-state force model of the transient
//! models (`TransientOptions::brush`): the step's tyre properties from the
//! brush (slip stiffnesses, relaxation lengths from the brush's own
//! cornering stiffness and the carcass stiffness, friction) and its forces at
//! the slips the transient model hands over.
//!
//! Must never: allocate, or leave a Magic Formula zero-slip force (shifts,
//! camber thrust) in the properties: the brush has none.

use super::params::BrushParams;
use super::solver::{cornering_stiffness_on, evaluate, slip_stiffness_on, BrushInput, Patch};
use crate::mf::Forces;
use crate::transient::{Slip, TyreProps, SIGMA_MAX, SIGMA_MIN};

/// Replace the MF-derived properties of a step by the brush's at load `fz`:
/// Kxκ = C_κ, Kyα = −C_y (ISO sign, as the MF's), lateral carcass stiffness
/// C_Fy of the string ([`super::StringCarcass::lateral_stiffness`]; the MF's
/// Cy for a rigid carcass), σα = C_y/C_Fy (≥ a), σκ = C_κ/Cx with the MF's
/// longitudinal carcass stiffness Cx (Pacejka 3rd ed. §7.2, eq. 7.12), μ =
/// μk, the deflections friction holds μ·Fz/C, no zero-slip force.
pub(crate) fn step_props(b: &BrushParams, props: &mut TyreProps, fz: f64) {
    let patch = Patch::new(b, fz);
    if patch.a <= 0.0 {
        return;
    }
    let cy = cornering_stiffness_on(b, &patch);
    let ck = slip_stiffness_on(b, &patch);
    let cfy = b.carcass().lateral_stiffness(patch.a);
    if cfy.is_finite() && cfy > 0.0 {
        props.cy = cfy;
    }
    let clamp = |s: f64| {
        if s.is_finite() {
            s.clamp(SIGMA_MIN, SIGMA_MAX)
        } else {
            SIGMA_MIN
        }
    };
    props.sigma_y = clamp(if b.carcass().rigid() {
        patch.a
    } else {
        (cy / cfy).max(patch.a)
    });
    props.sigma_x = clamp(ck / props.cx);
    props.kxk = ck;
    props.kya = -cy;
    let (_, mu) = super::solver::friction(b, fz, 1.0);
    props.mux = mu;
    props.muy = mu;
    props.ux_max = mu * fz / props.cx;
    props.uy_max = mu * fz / props.cy;
    props.fx0 = 0.0;
    props.fy0 = 0.0;
}

/// Brush forces at slips `sl` (κ = −Vsx/|Vx|, tan α = Vsy/|Vx|) on a road of
/// friction scale `s`; `vx` only for the direction of rolling: rolling
/// backwards the leading edge is at the rear, so Mz changes sign. Mx = 0 (the
/// brush has no overturning moment), My = NaN (taken from the MF's probe).
pub(crate) fn forces(b: &BrushParams, fz: f64, sl: Slip, s: f64, vx: f64) -> Forces {
    let f = evaluate(
        b,
        &BrushInput {
            fz,
            kappa: sl.kappa,
            tan_alpha: sl.tan_alpha,
            mu_scale: s,
        },
    );
    Forces {
        fx: f.fx,
        fy: f.fy,
        mx: 0.0,
        my: f64::NAN,
        mz: if vx < 0.0 { -f.mz } else { f.mz },
    }
}
