//! kinematics — the one place where the wheel's motion becomes slip (ISO-W):
//! κ, tan α and the slip speeds from the velocities, or the prescribed slips
//! with the slip speeds they imply.
//!
//! Must never: divide by |Vx| without the [`V_EPS`] floor.

use super::{InputMode, WheelInput, V_EPS};

/// Kinematic slip quantities of one step (ISO-W): the single place where slips
/// are computed from velocities.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kinematics {
    /// |Vx| (m/s).
    pub vx_abs: f64,
    /// Longitudinal slip speed Vsx = Vx − Ω·Re (m/s).
    pub vsx: f64,
    /// Lateral slip speed Vsy (m/s).
    pub vsy: f64,
    /// κ = −Vsx/|Vx| (|Vx| floored at [`V_EPS`]).
    pub kappa: f64,
    /// tan α = Vsy/|Vx| (|Vx| floored at [`V_EPS`]).
    pub tan_alpha: f64,
    /// Rolling speed of the contact |Vx − Vsx| (= |Ω·Re| from velocities) (m/s).
    pub v_roll: f64,
    /// α = atan(tan α) (rad); exactly `alpha_in` for prescribed slips.
    pub alpha: f64,
}

/// Slip from the wheel's motion (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed.,
/// §2.2, eqs 2.10–2.12 in ISO-W: κ = −Vsx/|Vx|, tan α = Vsy/|Vx|,
/// Vsx = Vx − Ω·Re), or the prescribed slips with Vsx = −κ·|Vx|, Vsy = tan α·|Vx|.
pub fn kinematics(mode: InputMode, inp: &WheelInput, re: f64) -> Kinematics {
    let vx_abs = inp.vx.abs();
    match mode {
        InputMode::Velocities => {
            let vsx = inp.vx - inp.omega * re;
            let vsy = inp.vy;
            let v = vx_abs.max(V_EPS);
            Kinematics {
                vx_abs,
                vsx,
                vsy,
                kappa: -vsx / v,
                tan_alpha: vsy / v,
                v_roll: (inp.vx - vsx).abs(),
                alpha: (vsy / v).atan(),
            }
        }
        InputMode::Slips => {
            let tan_alpha = inp.alpha_in.tan();
            Kinematics {
                vx_abs,
                vsx: -inp.kappa_in * vx_abs,
                vsy: tan_alpha * vx_abs,
                kappa: inp.kappa_in,
                tan_alpha,
                v_roll: (inp.vx + inp.kappa_in * vx_abs).abs(),
                alpha: inp.alpha_in,
            }
        }
    }
}
