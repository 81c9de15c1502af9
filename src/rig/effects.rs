//! rig::effects — concealed-effect truth models for the rig simulator: the
//! steady Magic Formula of a real tyre plus ONE piece of physics the plain MF
//! leaves out, with a physical parameter and a strength. They are the proof
//! material of the diagnosis (issue 7): present, but small enough that a
//! plain steady fit still looks reasonable (a few % of the peak force).
//!
//! Each effect is deliberately a *different formulation* from the candidate
//! models the diagnosis fits (e.g. the relaxation truth lags the slips
//! themselves, the transient model lags contact deflections; the thermal
//! truth's friction curve is a parabola around an optimum temperature), so
//! that a detection keyed to a formula rather than to the physical signature
//! would show here.
//!
//! Friction and stiffness changes are applied with the similarity method
//! ([`crate::transient::mf_at`], Pacejka 3rd ed. §4.3.2): a friction scale
//! `s` and a slip-stiffness scale `c` map the pure-slip curve as
//! F(κ) → s·F(c·κ/s) (peak × s, stiffness × c).
//!
//! Must never: allocate per sample, or use a random source (truths are
//! deterministic; noise is the rig's business).

use super::{radii, RigInput, SteadyMf, TruthModel, TruthOutput};
use crate::mf::{Forces, MfInput, Tyre, UseMode};
use crate::transient::{
    mf_at, InputMode, Slip, TransientConfig, TransientKind, TransientModel, WheelInput,
};

/// Names of the effects, as the diagnosis names its candidates.
pub const EFFECTS: [&str; 9] = [
    "none",
    "relaxation",
    "lugre",
    "thermal",
    "load_sensitivity",
    "pressure",
    "speed_friction",
    "rolling_radius",
    "camber",
];

/// Steady MF forces at slips (κ, tan α) with friction scale `s` and slip
/// stiffness scale `c` (similarity method, see the module docs).
fn scaled(m: &SteadyMf, mi: &MfInput, kappa: f64, tan_alpha: f64, s: f64, c: f64) -> Forces {
    let s = s.max(1e-3);
    mf_at(&m.tyre, mi, m.mode, Slip::new(kappa * c, tan_alpha * c), s)
}

/// A truth output from forces at the input's load (radii from the MF).
fn output(m: &SteadyMf, inp: &RigInput, forces: Forces, tread_temp: f64) -> TruthOutput {
    let o = m.tyre.evaluate(
        &MfInput {
            kappa: 0.0,
            alpha: 0.0,
            ..inp.mf
        },
        m.mode,
    );
    let (re, rl) = radii(&m.tyre, inp.mf.fz, o.re, o.rl);
    TruthOutput {
        forces,
        re,
        rl,
        tread_temp,
    }
}

/// Nominal load (N) and pressure (Pa) of a tyre, with fallbacks.
fn nominal(t: &Tyre) -> (f64, f64) {
    let p = &t.params().p;
    (
        if p.fnomin > 0.0 { p.fnomin } else { 4000.0 },
        if p.nompres > 0.0 { p.nompres } else { 2e5 },
    )
}

/// Transient slip lag: κ and tan α follow the imposed slips over relaxation
/// lengths σκ, σα (m) of rolled distance (Pacejka 3rd ed. eq. 7.11, slip
/// form). Signature: Fy lags behind α — hysteresis between rising and falling
/// sweeps, growing with slip rate / speed.
pub struct Relaxation {
    /// The steady MF the lagged slips are fed to.
    pub inner: SteadyMf,
    /// Relaxation length σκ of the slip ratio (m of rolled distance).
    pub sigma_x: f64,
    /// Relaxation length σα of tan α (m of rolled distance).
    pub sigma_y: f64,
    kappa: f64,
    tan_alpha: f64,
}

impl Relaxation {
    /// Relaxation truth over `tyre` with lengths σκ = `sigma_x`, σα =
    /// `sigma_y` (m); the lagged slips start at zero.
    pub fn new(tyre: Tyre, sigma_x: f64, sigma_y: f64) -> Self {
        Relaxation {
            inner: SteadyMf::new(tyre),
            sigma_x,
            sigma_y,
            kappa: 0.0,
            tan_alpha: 0.0,
        }
    }
}

impl TruthModel for Relaxation {
    fn sample(&mut self, inp: &RigInput, dt: f64) -> TruthOutput {
        let travel = inp.mf.vx.abs() * dt;
        let w = |sigma: f64| 1.0 - (-travel / sigma.max(1e-4)).exp();
        self.kappa += (inp.mf.kappa - self.kappa) * w(self.sigma_x);
        self.tan_alpha += (inp.mf.alpha.tan() - self.tan_alpha) * w(self.sigma_y);
        let f = scaled(&self.inner, &inp.mf, self.kappa, self.tan_alpha, 1.0, 1.0);
        output(&self.inner, inp, f, f64::NAN)
    }
    fn reset(&mut self) {
        self.kappa = 0.0;
        self.tan_alpha = 0.0;
    }
    fn describe(&self) -> String {
        format!(
            "{} + relaxation σκ = {} m, σα = {} m",
            self.inner.describe(),
            self.sigma_x,
            self.sigma_y
        )
    }
}

/// LuGre dynamic friction (bristle hysteresis): this project's transient
/// LuGre model (Canudas de Wit et al. 2003, average lumped) driven with the
/// rig's prescribed slips. Strength `level`: bristle stiffness
/// σ0 = K/(Fz0·L·level) per direction (K the MF's slip stiffness at the
/// nominal load, L = 0.2 m longitudinal, 0.35 m lateral: at small slip the
/// bristles lag like those relaxation lengths; a tyre file's own carcass
/// stiffness can give metres), so level 2 has twice the lag at small slip.
pub struct LuGre {
    /// The steady MF supplying the radii (and the model's tyre).
    pub inner: SteadyMf,
    /// The LuGre transient model, fed the rig's prescribed slips
    /// ([`InputMode::Slips`]).
    pub model: TransientModel,
}

impl LuGre {
    /// LuGre truth over `tyre` at strength `level` (bristle stiffnesses
    /// σ0x, σ0y from the slip stiffnesses as in the type docs).
    pub fn new(tyre: Tyre, level: f64) -> Self {
        let (fnom, _) = nominal(&tyre);
        let o = tyre.slip_properties(
            &MfInput {
                fz: fnom,
                vx: 11.0,
                ..Default::default()
            },
            UseMode {
                limits: false,
                alpha_star: false,
                turn_slip: false,
            },
        );
        let l = level.max(1e-3);
        // At small slip LuGre lags like a relaxation length K/(Fz·σ0).
        let k = |stiff: f64, len: f64| {
            let x = stiff.abs() / (fnom * len * l);
            if x.is_finite() && x > 0.0 {
                x
            } else {
                0.0
            }
        };
        let lugre = crate::transient::LuGreParams {
            sigma0x: k(o.kxk, 0.2),
            sigma0y: k(o.kya, 0.35),
            ..Default::default()
        };
        LuGre {
            inner: SteadyMf::new(tyre),
            model: TransientModel::with_options(
                TransientConfig {
                    kind: TransientKind::LuGre,
                    input_mode: InputMode::Slips,
                    use_mode: UseMode {
                        limits: false,
                        alpha_star: false,
                        turn_slip: false,
                    },
                },
                crate::transient::TransientOptions {
                    lugre,
                    ..Default::default()
                },
            ),
        }
    }
}

impl TruthModel for LuGre {
    fn sample(&mut self, inp: &RigInput, dt: f64) -> TruthOutput {
        let w = WheelInput {
            vx: inp.mf.vx,
            vy: 0.0,
            omega: inp.mf.omega,
            fz: inp.mf.fz,
            gamma: inp.mf.gamma,
            p: inp.mf.p,
            phit: 0.0,
            mu_scale: 1.0,
            kappa_in: inp.mf.kappa,
            alpha_in: inp.mf.alpha,
        };
        let f = match self.model.step(&self.inner.tyre, &w, dt) {
            Ok(o) => Forces {
                fx: o.fx,
                fy: o.fy,
                mx: o.mx,
                my: o.my,
                mz: o.mz,
            },
            Err(_) => Forces::default(),
        };
        output(&self.inner, inp, f, f64::NAN)
    }
    fn reset(&mut self) {
        self.model.reset()
    }
    fn describe(&self) -> String {
        format!("{} + LuGre", self.inner.describe())
    }
}

/// Tread temperature T (°C), a lumped heat balance C·dT/dt = q·P − h·(T − Tamb)
/// with P = |Fx·Vsx| + |Fy·Vsy| the frictional power and q the share of it
/// heating the tread; friction follows a parabola around the optimum
/// Topt: μ(T)/μ(Topt) = 1 − k·((T − Topt)/50 K)². Signature: residuals that
/// drift with accumulated frictional energy / time in the run, tread
/// temperature correlated with them. The temperature is what the rig writes
/// to its tread-temperature channels.
pub struct Thermal {
    /// The steady MF whose friction the temperature scales.
    pub inner: SteadyMf,
    /// Heat capacity of the tread layer (J/K).
    pub capacity: f64,
    /// Heat loss to air/belt (W/K).
    pub cooling: f64,
    /// Share of frictional power into the tread (–).
    pub share: f64,
    /// Optimum temperature (°C).
    pub t_opt: f64,
    /// Friction loss at 50 K from the optimum (–): the strength.
    pub k: f64,
    /// The temperature–friction curve.
    pub curve: ThermalCurve,
    /// Ambient temperature Tamb (°C); the tread starts at it after [`TruthModel::reset`].
    pub ambient: f64,
    temp: f64,
    last_power: f64,
}

impl Thermal {
    /// Defaults: C = 4 kJ/K, h = 40 W/K (time constant 100 s), q = 0.5,
    /// Topt = 70 °C, ambient 25 °C, strength k.
    pub fn new(tyre: Tyre, k: f64) -> Self {
        Thermal {
            inner: SteadyMf::new(tyre),
            capacity: 4000.0,
            cooling: 40.0,
            share: 0.5,
            t_opt: 70.0,
            k,
            curve: ThermalCurve::Parabola,
            ambient: 25.0,
            temp: 25.0,
            last_power: 0.0,
        }
    }
    /// Friction scale at tread temperature `t`.
    pub fn mu_scale(&self, t: f64) -> f64 {
        match self.curve {
            ThermalCurve::Parabola => {
                let x = (t - self.t_opt) / 50.0;
                (1.0 - self.k * x * x).max(0.3)
            }
            ThermalCurve::Softening => {
                (1.0 - self.k * ((t - self.ambient) / 40.0).max(0.0).tanh()).max(0.3)
            }
        }
    }
}

/// Temperature–friction curves of the thermal truth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ThermalCurve {
    /// μ(T)/μ(Topt) = 1 − k·((T − Topt)/50 K)²: grip peaks at an optimum.
    Parabola,
    /// μ(T)/μ(Tamb) = 1 − k·tanh((T − Tamb)/40 K): the compound softens and
    /// loses grip monotonically as it heats (a second formulation).
    Softening,
}

impl TruthModel for Thermal {
    fn sample(&mut self, inp: &RigInput, dt: f64) -> TruthOutput {
        // Exact update of the linear heat balance with the last step's power held.
        let tau = self.capacity / self.cooling.max(1e-9);
        let t_eq = self.ambient + self.share * self.last_power / self.cooling.max(1e-9);
        self.temp = t_eq + (self.temp - t_eq) * (-dt / tau).exp();
        let s = self.mu_scale(self.temp);
        let f = scaled(
            &self.inner,
            &inp.mf,
            inp.mf.kappa,
            inp.mf.alpha.tan(),
            s,
            1.0,
        );
        let vx = inp.mf.vx.abs();
        self.last_power = if inp.mf.fz > 0.0 {
            (f.fx * inp.mf.kappa * vx).abs() + (f.fy * inp.mf.alpha.tan() * vx).abs()
        } else {
            0.0
        };
        output(&self.inner, inp, f, self.temp)
    }
    fn reset(&mut self) {
        self.temp = self.ambient;
        self.last_power = 0.0;
    }
    fn describe(&self) -> String {
        format!(
            "{} + thermal friction k = {} (Topt {} °C)",
            self.inner.describe(),
            self.k,
            self.t_opt
        )
    }
}

/// A static scaling effect: friction scale `s` and stiffness scale `c`
/// computed from the imposed inputs, with an optional slip shift.
pub struct Scaling {
    /// The steady MF being scaled.
    pub inner: SteadyMf,
    /// Which static effect.
    pub kind: ScalingKind,
    /// Strength (meaning per kind, see [`ScalingKind`]).
    pub strength: f64,
    fnom: f64,
    pnom: f64,
}

/// The static effects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScalingKind {
    /// Peak friction and stiffness fall with load beyond the MF forms:
    /// s = exp(−a·dfz²)·(1 − a·dfz), c = 1 − a·dfz/2, dfz = Fz/Fnom − 1 (a = strength).
    LoadSensitivity,
    /// Inflation: friction falls, stiffness rises with pressure:
    /// s = 1 − a·dp, c = 1 + a·dp, dp = P/Pnom − 1 (a = strength).
    Pressure,
    /// Friction falls with sliding speed Vs = Vx·√(κ² + tan²α):
    /// s = 1/(1 + a·Vs) (a = strength, s/m).
    SpeedFriction,
    /// The effective rolling radius varies with load more than the MF says:
    /// Re_true = Re·(1 + a·dfz), so the slip the tyre sees is
    /// κ' = (1 + κ)·Re_true/Re − 1 (a = strength).
    RollingRadius,
    /// Camber acts as extra slip angle and costs friction:
    /// tan α' = tan α + a·γ·0.1, s = 1 − 2a·γ² (a = strength, γ in rad).
    Camber,
    /// A second speed–friction form: friction decays exponentially towards a
    /// sliding level, s = 1 − a·(1 − exp(−Vs/3 m/s)) (a = strength).
    SpeedFrictionExp,
    /// A second load-sensitivity form: the classical power law of peak
    /// friction, s = (Fz/Fnom)^(−a), stiffness unchanged (a = strength).
    LoadPowerLaw,
    /// A third load-sensitivity form: peak friction linear in load,
    /// s = 1 − a·dfz, stiffness unchanged (a = strength).
    LoadLinear,
    /// A fourth load-sensitivity form, saturating: friction and stiffness
    /// level off at both ends of the load range,
    /// s = 1 − a·tanh(2·dfz), c = 1 + a·tanh(2·dfz) (a = strength).
    LoadSaturating,
}

impl Scaling {
    /// Static effect `kind` of `strength` over `tyre` (nominal load and
    /// pressure from the tyre file, else 4000 N and 200 kPa).
    pub fn new(tyre: Tyre, kind: ScalingKind, strength: f64) -> Self {
        let (fnom, pnom) = nominal(&tyre);
        Scaling {
            inner: SteadyMf::new(tyre),
            kind,
            strength,
            fnom,
            pnom,
        }
    }
}

impl TruthModel for Scaling {
    fn sample(&mut self, inp: &RigInput, _dt: f64) -> TruthOutput {
        let a = self.strength;
        let m = &inp.mf;
        let dfz = m.fz / self.fnom - 1.0;
        let p = if m.p > 0.0 { m.p } else { self.pnom };
        let dp = p / self.pnom - 1.0;
        let (mut k, mut ta) = (m.kappa, m.alpha.tan());
        let (s, c) = match self.kind {
            ScalingKind::LoadSensitivity => (
                (-a * dfz * dfz).exp() * (1.0 - a * dfz),
                1.0 - 0.5 * a * dfz,
            ),
            ScalingKind::Pressure => (1.0 - a * dp, 1.0 + a * dp),
            ScalingKind::SpeedFriction => {
                let vs = m.vx.abs() * (k * k + ta * ta).sqrt();
                (1.0 / (1.0 + a * vs), 1.0)
            }
            ScalingKind::RollingRadius => {
                k = (1.0 + k) * (1.0 + a * dfz) - 1.0;
                (1.0, 1.0)
            }
            ScalingKind::Camber => {
                ta += a * 0.1 * m.gamma;
                (1.0 - 2.0 * a * m.gamma * m.gamma, 1.0)
            }
            ScalingKind::SpeedFrictionExp => {
                let vs = m.vx.abs() * (k * k + ta * ta).sqrt();
                (1.0 - a * (1.0 - (-vs / 3.0).exp()), 1.0)
            }
            ScalingKind::LoadPowerLaw => ((1.0 + dfz).max(0.05).powf(-a), 1.0),
            ScalingKind::LoadLinear => (1.0 - a * dfz, 1.0),
            ScalingKind::LoadSaturating => {
                let t = (2.0 * dfz).tanh();
                (1.0 - a * t, 1.0 + a * t)
            }
        };
        let f = scaled(&self.inner, m, k, ta, s, c);
        output(&self.inner, inp, f, f64::NAN)
    }
    fn describe(&self) -> String {
        format!(
            "{} + {:?} strength {}",
            self.inner.describe(),
            self.kind,
            self.strength
        )
    }
}

/// A concealed-effect truth by name (see [`EFFECTS`]) at a strength level:
/// `level` 1 is the "concealed" default (a few % of peak force), 2 twice as
/// strong. `none` gives the plain steady MF (the control). None: unknown name.
pub fn concealed(name: &str, tyre: Tyre, level: f64) -> Option<Box<dyn TruthModel>> {
    let l = level;
    Some(match name {
        "none" => Box::new(SteadyMf::new(tyre)),
        "relaxation" => Box::new(Relaxation::new(tyre, 0.2 * l, 0.35 * l)),
        "lugre" => Box::new(LuGre::new(tyre, l)),
        "thermal" => Box::new(Thermal::new(tyre, 0.15 * l)),
        "load_sensitivity" => Box::new(Scaling::new(tyre, ScalingKind::LoadSensitivity, 0.08 * l)),
        "pressure" => Box::new(Scaling::new(tyre, ScalingKind::Pressure, 0.25 * l)),
        "speed_friction" => Box::new(Scaling::new(tyre, ScalingKind::SpeedFriction, 0.02 * l)),
        "rolling_radius" => Box::new(Scaling::new(tyre, ScalingKind::RollingRadius, 0.01 * l)),
        "camber" => Box::new(Scaling::new(tyre, ScalingKind::Camber, 1.0 * l)),
        _ => return None,
    })
}

/// Second formulations of some effects (other curves for the same physics),
/// to show that the diagnosis keys on the physical signature, not on
/// [`concealed`]'s formulas: `thermal` (a softening compound: friction
/// falls monotonically with temperature, tanh curve, other heat balance),
/// `speed_friction` (exponential decay with sliding speed),
/// `load_sensitivity` (power law of peak friction in load). None otherwise.
pub fn concealed_alt(name: &str, tyre: Tyre, level: f64) -> Option<Box<dyn TruthModel>> {
    let l = level;
    Some(match name {
        "thermal" => {
            let mut t = Thermal::new(tyre, 0.06 * l);
            t.curve = ThermalCurve::Softening;
            t.capacity = 6000.0;
            t.cooling = 50.0;
            t.share = 0.6;
            Box::new(t)
        }
        "speed_friction" => Box::new(Scaling::new(tyre, ScalingKind::SpeedFrictionExp, 0.08 * l)),
        "load_sensitivity" => Box::new(Scaling::new(tyre, ScalingKind::LoadPowerLaw, 0.08 * l)),
        _ => return None,
    })
}
