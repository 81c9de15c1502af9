//! input — the one adapter from a recorded [`Sample`] (ISO-W, SI) to the
//! model's inputs: [`mf_input`] for a steady Magic Formula evaluation,
//! [`wheel_input`] for a step of the transient model the FMU runs.
//!
//! Missing optional inputs read as: κ, γ, φt → 0; pressure → 0 (= the
//! `.tir`'s INFLPRES); Ω → (1 + κ)·Vx / R0 (the free-rolling wheel speed
//! at the recorded slip with the unloaded radius). Where κ follows the rig's
//! slip ratio, Ω is the wheel speed that slip implies (see [`wheel_input`]). The lateral slip speed
//! is Vy = tan α·|Vx| (ISO-W, Pacejka 3rd ed. eq. 2.12), so that the
//! velocities input mode sees the recorded α exactly.
//!
//! Must never: invent a core input (Vx, Fz, α): a sample missing one has
//! no model input (`None`).

use crate::data::Sample;
use crate::mf::{MfInput, Tyre};
use crate::transient::WheelInput;

/// `x`, or 0 when it is not finite (an optional channel the recording lacks).
fn or0(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// Whether the sample has the core inputs Vx, Fz and α.
pub fn has_core_inputs(s: &Sample) -> bool {
    s.vx.is_finite() && s.fz.is_finite() && s.alpha.is_finite()
}

/// The steady model's input for one sample (optional inputs as in the module docs).
pub fn mf_input(s: &Sample) -> MfInput {
    MfInput {
        fz: s.fz,
        kappa: or0(s.kappa),
        alpha: s.alpha,
        gamma: or0(s.gamma),
        phit: or0(s.phit),
        vx: s.vx,
        p: or0(s.p),
        omega: or0(s.omega),
    }
}

/// The transient model's input for one sample (None when a core input is
/// missing). Ω: where the loader took κ from the rig's slip ratio, the
/// wheel speed that slip implies with the rig's radius, (1 + κ)·Vx /
/// `slip_radius` ([`crate::data::slip::SLIP_RADIUS_CHANNEL`]: the recorded
/// speeds carry noise the rig's slip does not); else the recorded Ω; else,
/// missing, (1 + κ)·Vx / R0 of `tyre`.
pub fn wheel_input(tyre: &Tyre, s: &Sample, slip_radius: Option<f64>) -> Option<WheelInput> {
    if !has_core_inputs(s) {
        return None;
    }
    let m = mf_input(s);
    let from_slip = slip_radius
        .filter(|r| r.is_finite() && *r > 0.0 && s.kappa.is_finite() && s.omega.is_finite())
        .map(|r| (1.0 + s.kappa) * s.vx / r);
    let omega = if let Some(w) = from_slip {
        w
    } else if s.omega.is_finite() {
        s.omega
    } else {
        let r0 = tyre.params().p.unloaded_radius;
        let r0 = if r0.is_finite() && r0 > 0.0 { r0 } else { 0.3 };
        (1.0 + m.kappa) * s.vx / r0
    };
    Some(WheelInput {
        vx: s.vx,
        vy: s.alpha.tan() * s.vx.abs(),
        omega,
        fz: s.fz,
        gamma: m.gamma,
        p: m.p,
        phit: m.phit,
        mu_scale: 0.0,
        kappa_in: m.kappa,
        alpha_in: s.alpha,
    })
}
