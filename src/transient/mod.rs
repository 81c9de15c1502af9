//! transient — tyre dynamics between the wheel's motion and the steady Magic
//! Formula: wheel kinematics (slip from velocities), and the transient models
//! (`Steady`, first-order `Relaxation` in deflection form, `LuGre` dynamic friction).
//! This is exactly what the FMU steps and what `replay` steps.
//!
//! Must never: divide by the speed without a guard, allocate in `step`, or
//! leave the state changed when a step is refused (bad input).
//!
//! STUB: the API below is the contract the FMU and replay build on; only the
//! `Steady` model is implemented here, the transient issue fills in the others.

use crate::mf::{Forces, MfInput, Tyre, UseMode};

/// Which dynamics sit between the wheel's motion and the Magic Formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum TransientKind {
    /// No dynamics: the Magic Formula of the instantaneous slips.
    #[default]
    Steady,
    /// First-order relaxation-length slip lag (contact deflection states).
    Relaxation,
    /// Average lumped LuGre dynamic friction.
    LuGre,
}

impl TransientKind {
    /// Parse `steady` | `relaxation` | `lugre` (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "steady" => Some(Self::Steady),
            "relaxation" => Some(Self::Relaxation),
            "lugre" => Some(Self::LuGre),
            _ => None,
        }
    }
    /// The name as accepted by [`TransientKind::parse`].
    pub fn name(self) -> &'static str {
        match self {
            Self::Steady => "steady",
            Self::Relaxation => "relaxation",
            Self::LuGre => "lugre",
        }
    }
}

/// How the wheel's slip is given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum InputMode {
    /// From velocities: vx, vy, omega (the slips are computed).
    #[default]
    Velocities,
    /// Prescribed slips: kappa_in, alpha_in (rigs that prescribe slip); vx still sets the speed.
    Slips,
}

/// One step's inputs, ISO-W, SI (the FMU's input variables).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelInput {
    /// Longitudinal speed of the wheel centre in the wheel plane (m/s).
    pub vx: f64,
    /// Lateral speed of the contact point (m/s).
    pub vy: f64,
    /// Wheel spin rate (rad/s).
    pub omega: f64,
    /// Normal load (N).
    pub fz: f64,
    /// Inclination angle (rad).
    pub gamma: f64,
    /// Inflation pressure (Pa).
    pub p: f64,
    /// Turn slip (1/m).
    pub phit: f64,
    /// Road friction scale (–), multiplies the friction coefficients.
    pub mu_scale: f64,
    /// Prescribed longitudinal slip (used in [`InputMode::Slips`]).
    pub kappa_in: f64,
    /// Prescribed slip angle (rad, used in [`InputMode::Slips`]).
    pub alpha_in: f64,
}

/// One step's outputs, ISO-W, SI (the FMU's output variables).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelOutput {
    pub fx: f64,
    pub fy: f64,
    pub mx: f64,
    pub my: f64,
    pub mz: f64,
    /// Longitudinal slip the force model used.
    pub kappa: f64,
    /// Slip angle the force model used (rad).
    pub alpha: f64,
    /// Effective rolling radius (m).
    pub re: f64,
    pub mux: f64,
    pub muy: f64,
    /// Longitudinal slip speed of the contact point (m/s).
    pub vsx: f64,
    /// Lateral slip speed of the contact point (m/s).
    pub vsy: f64,
    /// Longitudinal relaxation length in use (m).
    pub sigma_x: f64,
    /// Lateral relaxation length in use (m).
    pub sigma_y: f64,
}

/// Number of `f64` state slots of any transient model (fixed so FMU states serialise simply).
pub const N_STATES: usize = 8;

/// The complete dynamic state, plain data (copied by fmi2GetFMUstate, serialised as bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransientState {
    /// State slots; their meaning depends on the model.
    pub x: [f64; N_STATES],
}

/// Settings of a transient model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransientConfig {
    pub kind: TransientKind,
    pub input_mode: InputMode,
    pub use_mode: UseMode,
}

/// A tyre's dynamics: configuration plus state. One per FMU instance / replay.
#[derive(Clone, Debug, Default)]
pub struct TransientModel {
    pub config: TransientConfig,
    pub state: TransientState,
}

impl TransientModel {
    /// A model at rest (zero state).
    pub fn new(config: TransientConfig) -> Self {
        TransientModel {
            config,
            state: TransientState::default(),
        }
    }

    /// Back to the initial (zero) state.
    pub fn reset(&mut self) {
        self.state = TransientState::default();
    }

    /// Advance by `dt` seconds with inputs held constant over the step and
    /// return the outputs at the end of the step. On error the state is unchanged.
    pub fn step(&mut self, tyre: &Tyre, inp: &WheelInput, dt: f64) -> crate::Result<WheelOutput> {
        let _ = dt;
        if self.config.kind != TransientKind::Steady {
            return Err(crate::Error::Input(format!(
                "transient model '{}' is not available yet",
                self.config.kind.name()
            )));
        }
        let re = tyre.params().p.unloaded_radius;
        let (kappa, alpha) = match self.config.input_mode {
            InputMode::Slips => (inp.kappa_in, inp.alpha_in),
            InputMode::Velocities => {
                let v = inp.vx.abs().max(1e-3);
                ((inp.omega * re - inp.vx) / v, (inp.vy / v).atan())
            }
        };
        let mi = MfInput {
            fz: inp.fz,
            kappa,
            alpha,
            gamma: inp.gamma,
            phit: inp.phit,
            vx: inp.vx,
            p: inp.p,
            omega: inp.omega,
        };
        let f: Forces = tyre.forces(&mi, self.config.use_mode);
        Ok(WheelOutput {
            fx: f.fx,
            fy: f.fy,
            mx: f.mx,
            my: f.my,
            mz: f.mz,
            kappa,
            alpha,
            re,
            ..Default::default()
        })
    }
}
