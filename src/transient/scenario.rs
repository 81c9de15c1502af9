//! scenario — a quarter-vehicle straight-line braking run through
//! [`TransientModel::step`] (the same call the FMU makes each communication
//! step): a mass on one wheel with inertia, a brake torque that builds up
//! linearly over τ, once with the wheel allowed to lock and once with a simple
//! slip controller (as ABS does). Reports the stopping distance beside the
//! textbook estimate S = v0·τ/2 + v0²/(2·a_max) (e.g. Mitschke & Wallentowitz,
//! *Dynamik der Kraftfahrzeuge*, braking-distance estimate with a linear
//! brake build-up of duration τ; a_max = |Fx|/m of the steady Magic Formula
//! at the slip the wheel runs at).
//!
//! Must never: be used in the FMU hot path (it is a test and demo helper).

use super::{
    InputMode, TransientConfig, TransientKind, TransientModel, TransientOptions, WheelInput,
};
use crate::mf::{MfInput, Tyre};

/// How the brake torque is commanded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BrakeControl {
    /// The full (ramped) torque: the wheel locks.
    Locked,
    /// Hold the slip at `target` (magnitude, e.g. 0.15) above `min_speed`;
    /// below it brake with the full torque (ABS switches off near standstill).
    SlipControl {
        /// Braking slip to hold, (V − Ω·Re)/V (–, positive).
        target: f64,
        /// Vehicle speed (m/s) below which the controller hands over to the
        /// full torque.
        min_speed: f64,
    },
}

/// A quarter-vehicle braking run.
#[derive(Clone, Copy, Debug)]
pub struct BrakingScenario {
    /// Quarter-vehicle mass (kg); the normal load is mass·g (no load transfer).
    pub mass: f64,
    /// Wheel polar inertia (kg m²).
    pub wheel_inertia: f64,
    /// Initial speed (m/s).
    pub v0: f64,
    /// Largest brake torque (N m).
    pub brake_torque: f64,
    /// Brake build-up time τ (s): the torque ramps linearly from 0 over τ.
    pub tau: f64,
    /// Brake command.
    pub control: BrakeControl,
    /// Communication step (s).
    pub dt: f64,
    /// Give up after this long (s).
    pub t_max: f64,
    /// Transient model run at the wheel.
    pub kind: TransientKind,
    /// Options of that model (relaxation variant, LuGre parameters, brush).
    pub options: TransientOptions,
}

impl Default for BrakingScenario {
    /// 400 kg on a passenger-car wheel (1.2 kg m²) from 100 km/h, 3000 N m
    /// (enough to lock), τ = 0.2 s, locked wheel, 1 ms steps, relaxation model.
    fn default() -> Self {
        BrakingScenario {
            mass: 400.0,
            wheel_inertia: 1.2,
            v0: 100.0 / 3.6,
            brake_torque: 3000.0,
            tau: 0.2,
            control: BrakeControl::Locked,
            dt: 1e-3,
            t_max: 20.0,
            kind: TransientKind::Relaxation,
            options: TransientOptions::default(),
        }
    }
}

/// What a braking run gives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrakingResult {
    /// Distance travelled until the speed first reaches 0 (m).
    pub stopping_distance: f64,
    /// Time until then (s).
    pub stopping_time: f64,
    /// Whether the vehicle stopped before `t_max`.
    pub stopped: bool,
    /// Deceleration of the steady MF at the slip the wheel runs at (m/s²).
    pub a_max: f64,
    /// Textbook estimate S = v0·τ/2 + v0²/(2·a_max) (m).
    pub textbook_distance: f64,
    /// Mean longitudinal slip while braking above 3 m/s after the build-up.
    pub mean_slip: f64,
    /// Largest distance from the stopping point during the 2 s after stopping
    /// (m): the tyre's elastic spring-back (and any roll-away).
    pub rebound: f64,
    /// Mean position relative to the stopping point over the second of those
    /// 2 s (m): where the vehicle comes to rest on its tyre spring.
    pub rest_offset: f64,
}

impl BrakingScenario {
    /// Run the scenario.
    pub fn run(&self, tyre: &Tyre) -> crate::Result<BrakingResult> {
        let g = 9.81;
        let fz = self.mass * g;
        if !(self.mass > 0.0 && self.wheel_inertia > 0.0 && self.dt > 0.0 && self.tau >= 0.0) {
            return Err(crate::Error::Input(format!(
                "braking scenario: mass, wheel inertia and dt must be > 0 and tau >= 0 (got {self:?})"
            )));
        }
        let cfg = TransientConfig {
            kind: self.kind,
            input_mode: InputMode::Velocities,
            use_mode: Default::default(),
        };
        let mut model = TransientModel::with_options(cfg, self.options);
        let re0 = tyre.params().p.unloaded_radius;
        let (mut v, mut x, mut t) = (self.v0, 0.0, 0.0);
        let mut omega = self.v0 / re0;
        let mut res = BrakingResult::default();
        let (mut slip_sum, mut slip_n) = (0.0, 0usize);
        let mut t_stop = f64::INFINITY;
        let (mut off_sum, mut off_n) = (0.0, 0usize);
        let n_steps = (self.t_max / self.dt).ceil() as usize;
        for _ in 0..n_steps {
            let inp = WheelInput {
                vx: v,
                omega,
                fz,
                mu_scale: 1.0,
                ..Default::default()
            };
            let out = model.step(tyre, &inp, self.dt)?;
            let re = out.re;
            let ramp = if self.tau > 0.0 {
                (t / self.tau).min(1.0)
            } else {
                1.0
            };
            let available = self.brake_torque * ramp;
            let tb = match self.control {
                BrakeControl::Locked => available,
                BrakeControl::SlipControl { target, min_speed } => {
                    if v > min_speed {
                        // Wheel torque balance (the torque that keeps the slip
                        // constant while the vehicle decelerates at Fx/m) plus a
                        // proportional correction whose time constant Iw/(Re·k)
                        // is 20 ms at every speed.
                        let k = 1.0 / (re * 0.02) * self.wheel_inertia;
                        let s = (v - omega * re) / v;
                        let spin_down =
                            -self.wheel_inertia * (1.0 - target) * out.fx / (self.mass * re);
                        (-out.fx * re + spin_down + k * v * (target - s)).clamp(0.0, available)
                    } else {
                        available
                    }
                }
            };
            // Vehicle (semi-implicit Euler) and wheel with a sticking brake.
            v += out.fx / self.mass * self.dt;
            x += v * self.dt;
            let free = omega - out.fx * re / self.wheel_inertia * self.dt;
            let brake = tb / self.wheel_inertia * self.dt;
            omega = if free >= 0.0 {
                (free - brake).max(0.0)
            } else {
                (free + brake).min(0.0)
            };
            t += self.dt;
            if t > self.tau && v > 3.0 {
                slip_sum += (omega * re - v) / v;
                slip_n += 1;
            }
            if !res.stopped && v <= 0.0 {
                res.stopped = true;
                res.stopping_distance = x;
                res.stopping_time = t;
                t_stop = t;
            }
            if res.stopped {
                let d = x - res.stopping_distance;
                res.rebound = res.rebound.max(d.abs());
                if t > t_stop + 1.0 {
                    off_sum += d;
                    off_n += 1;
                }
                if t > t_stop + 2.0 {
                    break;
                }
            }
        }
        if !res.stopped {
            res.stopping_distance = x;
            res.stopping_time = t;
        }
        res.rest_offset = if off_n > 0 {
            off_sum / off_n as f64
        } else {
            0.0
        };
        res.mean_slip = if slip_n > 0 {
            slip_sum / slip_n as f64
        } else {
            0.0
        };
        let kappa = match self.control {
            BrakeControl::Locked => -1.0,
            BrakeControl::SlipControl { target, .. } => -target,
        };
        let f = tyre.forces(
            &MfInput {
                fz,
                kappa,
                vx: self.v0,
                ..Default::default()
            },
            Default::default(),
        );
        res.a_max = f.fx.abs() / self.mass;
        res.textbook_distance = if res.a_max > 0.0 {
            self.v0 * self.tau / 2.0 + self.v0 * self.v0 / (2.0 * res.a_max)
        } else {
            f64::INFINITY
        };
        Ok(res)
    }
}
