//! transient — tyre dynamics between the wheel's motion and the steady Magic
//! Formula: wheel kinematics (slip from velocities, in one place: [`kinematics`]),
//! and the transient models (`Steady`, first-order `Relaxation` in deflection
//! form with a linear and a non-linear variant, `LuGre` dynamic friction).
//! This is exactly what the FMU steps and what `replay` steps.
//!
//! Must never: divide by the speed without a guard, allocate in `step`, or
//! leave the state changed when a step is refused (bad input).
//!
//! # Numerics
//! Every model is, over one step with the inputs held constant, a set of
//! scalar linear ODEs `ẋ = d − r·x` with `r ≥ 0`; they are solved exactly
//! (`x(h) = x·e^{−rh} + d·h·φ₁(rh)`, φ₁(z) = (1 − e^{−z})/z), so they are
//! unconditionally stable and free of step-size error for any `dt > 0`,
//! including the stiff limit (300 km/h, small relaxation length) and the
//! singular one (`|Vx| = 0`, where the rate vanishes and the deflection
//! integrates the slip speed: a spring). State-dependent rates — the
//! non-linear relaxation variant, and LuGre's elasto-plastic factor below
//! VXLOW — are sub-stepped deterministically (the number of sub-steps is a
//! function of the state and inputs only). Below VXLOW the relaxation
//! deflections are also clamped to what friction can hold (`saturate`).
//!
//! Verified (tests/transient_*.rs): with inputs held over 10 ms, outputs at
//! dt = 1e-4, 1e-3, 1e-2 s equal those at 1e-5 s to 1e-6 of the peak force
//! (linear relaxation), 1 % (LuGre), 2 % (non-linear relaxation), over
//! 0–300 km/h and standstill sliding.
//!
//! # Magic Formula calls (per step)
//! 1. [`Tyre::slip_properties_terms`] at zero slip and the actual speed (the
//!    "probe", the pure-slip equations only): Re, μx, μy, Cx, Cy, Kxκ, Kyα,
//!    σκ, σα (slip-independent); Fx, Fy at zero slip only where they are used
//!    (below VXLOW, LuGre), and My (rolling resistance with the MF's own
//!    low-speed/direction handling) only for the transient models. The
//!    steady model without turn slip probes Re only: its force evaluation
//!    ([`Tyre::forces_and_props`]) gives the slip-independent rest, the same
//!    bits, so one Magic Formula evaluation per step.
//! 2. [`Tyre::forces`] at the slips the model uses. For the transient models
//!    the MF sees the speed sgn(Vx)·max(|Vx|, VXLOW) — they do low speed
//!    themselves (MFeval's steady low-speed slip reduction would remove the
//!    standstill hold) — and the MF's own slip convention κ_MF = −Vsx/Vx
//!    (`StepCtx::forces`), so that braking backwards uses the braking branch
//!    of an asymmetric curve and a settled transient tyre equals the steady
//!    one in reverse. `Steady` calls the MF as is.
//! 3. Below VXLOW only: Fx, Fy at zero slip at the raised speed (the moment-free
//!    [`Tyre::forces_xy`], as LuGre's cross terms and the non-linear slopes), so that
//!    the MF's force at zero slip (shifts, camber thrust) keeps the MF's own
//!    low-speed reduction (`StepCtx::offset_correction`).
//!
//! The evaluations after the probe reuse its slip-independent terms (μx,
//! Kxκ, the load shape of Kyα: [`LoadTerms`], same bits), and the transient
//! models' force evaluation skips My (taken from the probe).
//!
//! `mu_scale` is applied by the similarity method ([`mf_at`]) until the MF
//! takes a friction scale itself.
//!
//! # State slot layout (`TransientState::x`, for FMU serialisation)
//! | slot | Relaxation                               | LuGre                         |
//! |------|------------------------------------------|-------------------------------|
//! | 0    | `u`: longitudinal deflection (m), κ' = u/σκ | `zx`: longitudinal bristle (m) |
//! | 1    | `v`: lateral deflection (m), tan α' = v/σα | `zy`: lateral bristle (m)      |
//! | 2    | `φ'`: lagged turn slip (1/m)            | –                             |
//! | 3    | tread temperature rise ΔT (K), any model with a `[THERMAL]` extension ([`extension`]) |
//! | 4–7  | reserved (0)                             | reserved (0)                  |
//!
//! The `Steady` model has no state (all slots stay 0). The all-zero state is
//! the state at rest (what [`TransientModel::reset`] restores).

pub mod extension;
mod kinematics;
pub mod lugre;
mod props;
mod relaxation;
pub mod scenario;
mod similarity;

pub use kinematics::{kinematics, Kinematics};
pub use lugre::{LuGreFriction, LuGreParams};
pub use props::{low_speed_weight, tyre_props, TyreProps};
pub use relaxation::{NL_MAX_SLIP_CHANGE, NL_MAX_SUBSTEPS, NL_SIGMA_MIN_FRACTION};
pub use similarity::{mf_at, mf_at_xy, Slip};

use crate::mf::{Forces, LoadTerms, MfInput, SlipProps, Tyre, UseMode};
use props::rolling_radius;
use relaxation::{relax_linear, relax_nonlinear};
use similarity::{mf_at_no_my, mf_at_props, stiff_slip};

/// The speed (m/s) at which the Magic Formula is evaluated for vx = 0 with
/// turn slip on: the limit vx → 0+ (see [`TransientModel::step`]).
pub const TURN_SLIP_VX0: f64 = 1e-9;

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
    /// The value `file` of the FMU's `transient` parameter and of
    /// `replay --transient`: the model the tyre file names
    /// ([`extension::file_transient`]), `steady` when it names none.
    pub const FROM_FILE: &'static str = "file";

    /// Resolve a `transient` setting for `tyre`: `file` (see
    /// [`TransientKind::FROM_FILE`]) or an explicit `steady` | `relaxation`
    /// | `lugre`. The error names the value and what is accepted.
    pub fn resolve(setting: &str, tyre: &crate::tir::TyreParams) -> crate::Result<Self> {
        if setting.trim().eq_ignore_ascii_case(Self::FROM_FILE) {
            return Ok(extension::file_transient(tyre)?.unwrap_or_default());
        }
        Self::parse(setting).ok_or_else(|| {
            crate::Error::Input(format!(
                "transient = \"{setting}\": expected \"file\" (as the tyre file says), \"steady\", \"relaxation\" or \"lugre\""
            ))
        })
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
    /// `0` means "not given" and is read as 1 (like `p = 0` means INFLPRES);
    /// negative or non-finite values are refused.
    pub mu_scale: f64,
    /// Prescribed longitudinal slip (used in [`InputMode::Slips`]).
    pub kappa_in: f64,
    /// Prescribed slip angle (rad, used in [`InputMode::Slips`]).
    pub alpha_in: f64,
}

/// One step's outputs, ISO-W, SI (the FMU's output variables).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelOutput {
    /// Longitudinal force Fx (N), positive forward (driving).
    pub fx: f64,
    /// Lateral force Fy (N), positive towards +y (left).
    pub fy: f64,
    /// Overturning moment Mx (N·m).
    pub mx: f64,
    /// Rolling-resistance moment My (N·m); for the transient models the MF's
    /// My at zero slip and the actual speed.
    pub my: f64,
    /// Self-aligning moment Mz (N·m).
    pub mz: f64,
    /// Longitudinal slip the force model used.
    pub kappa: f64,
    /// Slip angle the force model used (rad).
    pub alpha: f64,
    /// Effective rolling radius (m).
    pub re: f64,
    /// Longitudinal friction coefficient μx (–) at zero slip (Pacejka 3rd ed.
    /// eq. 4.E13), times the friction scale `s`.
    pub mux: f64,
    /// Lateral friction coefficient μy (–) at zero slip (Pacejka 3rd ed.
    /// eq. 4.E23), times the friction scale `s`.
    pub muy: f64,
    /// Longitudinal slip speed of the contact point (m/s).
    pub vsx: f64,
    /// Lateral slip speed of the contact point (m/s).
    pub vsy: f64,
    /// Longitudinal relaxation length in use (m).
    pub sigma_x: f64,
    /// Lateral relaxation length in use (m).
    pub sigma_y: f64,
    /// Friction scale `s` of the similarity method this step used (the
    /// `mu_scale` input times the tyre file's extension, see
    /// [`extension`]; 1 for a plain MF): the forces are s·F(c·κ/s, …).
    pub friction_scale: f64,
    /// Slip-stiffness scale `c` of the same step (1 for a plain MF).
    pub stiffness_scale: f64,
}

/// Number of `f64` state slots of any transient model (fixed so FMU states serialise simply).
pub const N_STATES: usize = 8;

/// Slot of the longitudinal deflection `u` (Relaxation) / bristle `zx` (LuGre).
pub const SLOT_X: usize = 0;
/// Slot of the lateral deflection `v` (Relaxation) / bristle `zy` (LuGre).
pub const SLOT_Y: usize = 1;
/// Slot of the lagged turn slip φ' (Relaxation with turn slip on).
pub const SLOT_PHI: usize = 2;

/// The complete dynamic state, plain data (copied by fmi2GetFMUstate, serialised as bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransientState {
    /// State slots; their meaning depends on the model (see the module docs).
    pub x: [f64; N_STATES],
}

/// Settings of a transient model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransientConfig {
    /// Which dynamics: steady, relaxation or LuGre.
    pub kind: TransientKind,
    /// Whether slips come from the velocities or are prescribed.
    pub input_mode: InputMode,
    /// Magic Formula use mode (`.tir` range limits, α*, turn slip) of every force
    /// evaluation.
    pub use_mode: UseMode,
}

/// Options beyond [`TransientConfig`] (kept apart so that code building a
/// `TransientConfig` literal keeps compiling): the relaxation variant and the
/// LuGre parameters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransientOptions {
    /// Relaxation: relaxation lengths from the instantaneous slip stiffness
    /// (local slope of the force curve) instead of the slip stiffness at zero slip.
    pub nonlinear: bool,
    /// LuGre parameters (default: friction function derived from the Magic Formula).
    pub lugre: LuGreParams,
    /// The steady-state force model: `None` = the Magic Formula; `Some` = the
    /// brush model (`crate::brush`), whose forces every transient model then
    /// uses, with the relaxation lengths and stiffnesses of the brush
    /// (`crate::brush::transient`). The MF still gives Re and My.
    pub brush: Option<crate::brush::BrushParams>,
}

/// A tyre's dynamics: configuration plus state. One per FMU instance / replay.
#[derive(Clone, Debug, Default)]
pub struct TransientModel {
    /// Model kind, input mode and MF use mode.
    pub config: TransientConfig,
    /// The dynamic state (deflections or bristles, see the module docs); all
    /// zero at rest.
    pub state: TransientState,
    /// Variant and LuGre parameters (not part of the state: set once at instantiation).
    pub options: TransientOptions,
}

/// Speed (m/s) below which a slip ratio is computed with this floor on `|Vx|`
/// (a wheel at rest is "fully sliding" for the steady model; the transient
/// models never divide by it).
pub const V_EPS: f64 = 1e-6;

/// Lower bound of the relaxation lengths in use (m): guards a zero slip
/// stiffness (e.g. a placeholder Magic Formula, or Fz → 0).
pub const SIGMA_MIN: f64 = 1e-3;
/// Upper bound of the relaxation lengths in use (m).
pub const SIGMA_MAX: f64 = 10.0;
/// Normal load (N) below which the tyre is off the ground: no force, state at rest.
pub const FZ_OFF: f64 = 1e-3;

/// Exact solution of `ẋ = d − r·x` (r ≥ 0, d constant) after `h` seconds:
/// `x·e^{−z} + d·h·φ₁(z)`, z = r·h, with one exponential (Taylor series
/// below z = 1e-3, where they are exact to round-off).
#[inline]
pub fn relax_exact(x: f64, r: f64, d: f64, h: f64) -> f64 {
    let z = r * h;
    let (e, p1) = if z < 1e-3 {
        (
            1.0 - z * (1.0 - z * (0.5 - z * (1.0 / 6.0 - z / 24.0))),
            1.0 - z * (0.5 - z * (1.0 / 6.0 - z * (1.0 / 24.0 - z / 120.0))),
        )
    } else {
        let e = (-z).exp();
        (e, (1.0 - e) / z)
    };
    x * e + d * h * p1
}

/// Checks the inputs a step uses; returns the friction scale in use.
fn validate(mode: InputMode, inp: &WheelInput, dt: f64) -> crate::Result<f64> {
    // dt = 0 is allowed: it returns the outputs of the current state without
    // advancing it (the FMU asks for outputs in initialization mode that way).
    if !(dt.is_finite() && dt >= 0.0) {
        return Err(crate::Error::Input(format!(
            "transient step: dt = {dt} s, expected a finite step >= 0"
        )));
    }
    let named = [
        ("vx", inp.vx),
        ("vy", inp.vy),
        ("omega", inp.omega),
        ("fz", inp.fz),
        ("gamma", inp.gamma),
        ("p", inp.p),
        ("phit", inp.phit),
        ("mu_scale", inp.mu_scale),
    ];
    for (n, x) in named {
        if !x.is_finite() {
            return Err(crate::Error::Input(format!(
                "transient step: input {n} = {x}, expected a finite number"
            )));
        }
    }
    if mode == InputMode::Slips {
        if !inp.kappa_in.is_finite() {
            return Err(crate::Error::Input(format!(
                "transient step: input kappa_in = {}, expected a finite number",
                inp.kappa_in
            )));
        }
        if !(inp.alpha_in.is_finite() && inp.alpha_in.abs() < 0.5 * std::f64::consts::PI) {
            return Err(crate::Error::Input(format!(
                "transient step: input alpha_in = {} rad, expected |alpha_in| < pi/2",
                inp.alpha_in
            )));
        }
    }
    if inp.mu_scale < 0.0 {
        return Err(crate::Error::Input(format!(
            "transient step: input mu_scale = {}, expected >= 0 (0 means 1)",
            inp.mu_scale
        )));
    }
    Ok(if inp.mu_scale == 0.0 {
        1.0
    } else {
        inp.mu_scale.max(1e-3)
    })
}

/// Everything a model's step needs, computed once per step.
pub(crate) struct StepCtx<'a> {
    pub tyre: &'a Tyre,
    pub mode: UseMode,
    pub base: MfInput,
    pub kin: Kinematics,
    pub props: TyreProps,
    pub s: f64,
    /// Slip-stiffness scale of the extension (1 without one).
    pub c: f64,
    pub fz: f64,
    pub omega_re: f64,
    /// Whether the force evaluation runs at a raised speed (|Vx| < VXLOW).
    pub floored: bool,
    /// The probe's slip-independent MF terms, for the step's later
    /// evaluations at the same load ([`LoadTerms`]; None: computed afresh).
    pub terms: Option<LoadTerms<f64>>,
    /// −1 reversing from velocities, else +1: maps the transient models'
    /// κ = −Vsx/|Vx| to the MF's κ = −Vsx/Vx (see [`StepCtx::forces`]).
    pub dir: f64,
    /// The brush force model, when chosen ([`TransientOptions::brush`]).
    pub brush: Option<&'a crate::brush::BrushParams>,
}

impl StepCtx<'_> {
    /// The transient models' force evaluation at slips `sl` (κ = −Vsx/|Vx|):
    /// the MF at the signed (floored) speed with the MF's own slip convention
    /// κ_MF = −Vsx/Vx = dir·κ, exactly as the steady model evaluates it — so
    /// that braking while reversing uses the braking branch of the curve (the
    /// MF's brake/drive asymmetry, SHx, SVx) with Fx mirrored by the MF
    /// (Pacejka 3rd ed. eq. 4.E9 with MFeval's sign of Vx), and the backward
    /// conventions of Fy (α* modes) and Mz are the MF's own: a settled
    /// transient model equals the steady one in reverse too
    /// (tests/transient_reverse.rs). My is not evaluated here (NaN): the
    /// step takes it from the zero-slip probe (rolling resistance at the
    /// actual speed).
    #[inline]
    pub fn forces(&self, base: &MfInput, sl: Slip) -> Forces {
        if let Some(b) = self.brush {
            return crate::brush::transient::forces(b, self.fz, self.stiff(sl), self.s, base.vx);
        }
        let sl = Slip {
            kappa: self.dir * sl.kappa,
            ..sl
        };
        let pre = self.terms.as_ref();
        mf_at_no_my(self.tyre, base, self.mode, self.stiff(sl), self.s, pre)
    }

    /// The slips scaled by the extension's slip-stiffness scale `c`
    /// (similarity method: stiffness × c); unchanged when c = 1.
    #[inline]
    pub fn stiff(&self, sl: Slip) -> Slip {
        stiff_slip(self.c, sl)
    }

    /// Fx, Fy of [`StepCtx::forces`] only (bit-identical), without the moments.
    #[inline]
    pub fn forces_xy(&self, base: &MfInput, sl: Slip) -> (f64, f64) {
        if self.brush.is_some() {
            let f = self.forces(base, sl);
            return (f.fx, f.fy);
        }
        let sl = Slip {
            kappa: self.dir * sl.kappa,
            ..sl
        };
        let pre = self.terms.as_ref();
        mf_at_xy(self.tyre, base, self.mode, self.stiff(sl), self.s, pre)
    }

    /// Low-speed offset correction (N): the MF's force at zero slip at the
    /// actual speed (the probe, with the MF's own low-speed reduction of its
    /// shifts) minus that at the raised speed of the force evaluation. Zero
    /// from VXLOW up; below it one extra forces evaluation. Added to the
    /// force evaluation, it keeps the MF's low-speed treatment of the shifts
    /// (a parked car is not pushed by a camber thrust or SVx of rolling).
    pub fn offset_correction(&self) -> (f64, f64) {
        if !self.floored {
            return (0.0, 0.0);
        }
        let (fx, fy) = self.forces_xy(&self.base, Slip::default());
        let d = |p: f64, f: f64| {
            let x = self.s * p - f;
            if x.is_finite() {
                x
            } else {
                0.0
            }
        };
        (d(self.props.fx0, fx), d(self.props.fy0, fy))
    }
}

impl TransientModel {
    /// A model at rest (zero state), default options.
    pub fn new(config: TransientConfig) -> Self {
        TransientModel {
            config,
            state: TransientState::default(),
            options: TransientOptions::default(),
        }
    }

    /// A model at rest with explicit options (non-linear relaxation, LuGre parameters).
    pub fn with_options(config: TransientConfig, options: TransientOptions) -> Self {
        TransientModel {
            config,
            state: TransientState::default(),
            options,
        }
    }

    /// Back to the initial (zero) state.
    pub fn reset(&mut self) {
        self.state = TransientState::default();
    }

    /// Restart after `gap` seconds without inputs (a replay's dropped rows
    /// or refused samples): the slip, turn-slip and bristle states restart
    /// at rest as in [`TransientModel::reset`] — their history fades within
    /// a relaxation length, and nothing recorded says what the slips did
    /// during the gap —, while the
    /// tread temperature of a `[THERMAL]` extension (slot 3), whose time
    /// constant is minutes, carries over, cooled over the gap without
    /// frictional power: ΔT·exp(−gap·h/C), the heat balance of
    /// [`extension`] with P = 0 (a repeated time stamp, gap 0, keeps it as
    /// it is). A gap that is not a finite time ≥ 0 (time running backwards:
    /// concatenated files) resets everything.
    pub fn reset_after_gap(&mut self, tyre: &Tyre, gap: f64) {
        let warm = self.state.x[extension::SLOT_TEMP];
        self.reset();
        let thermal = tyre.extension().and_then(|e| e.thermal);
        if let Some(m) = thermal.filter(|_| gap.is_finite() && gap >= 0.0 && warm.is_finite()) {
            self.state.x[extension::SLOT_TEMP] = warm * (-gap / m.time_constant()).exp();
        }
    }

    /// Advance by `dt` seconds with inputs held constant over the step and
    /// return the outputs at the end of the step. On error the state is unchanged.
    ///
    /// Cost: the steady model without turn slip, one forces evaluation (and
    /// the radius); otherwise one zero-slip probe (pure-slip equations, for Re, μ, the
    /// stiffnesses and relaxation lengths; the zero-slip forces and My only
    /// where used) and one forces-only evaluation; below VXLOW one Fx/Fy-only
    /// one more (zero-slip offsets); LuGre two Fx/Fy-only ones (cross terms);
    /// the non-linear relaxation variant three Fx/Fy-only ones per slope
    /// evaluation (one per step when the slips change little, two per
    /// sub-step otherwise).
    pub fn step(&mut self, tyre: &Tyre, inp: &WheelInput, dt: f64) -> crate::Result<WheelOutput> {
        let s = validate(self.config.input_mode, inp, dt)?;
        let fz = inp.fz.max(0.0);
        let mode = self.config.use_mode;
        // Turn slip at exactly vx = 0: the MF's turn-slip shape (Pacejka 4.86,
        // D_Hyφ ∝ sgn Vx, and B_Hyφ ∝ 1/D_Hyφ) is 0/0 there, while its limit
        // for vx → 0+ is finite (and the low-speed reduction has already
        // faded φt and κ to 0): evaluate at that limit (issue 16).
        let vx_mf = if mode.turn_slip && inp.vx == 0.0 {
            TURN_SLIP_VX0
        } else {
            inp.vx
        };
        let base = MfInput {
            fz,
            kappa: 0.0,
            alpha: 0.0,
            gamma: inp.gamma,
            phit: inp.phit,
            vx: vx_mf,
            p: inp.p,
            omega: inp.omega,
        };
        let steady = self.config.kind == TransientKind::Steady;
        // The force evaluation. Transient models: speed of the sign of Vx
        // and magnitude ≥ VXLOW, so that the MF's steady-state low-speed slip
        // reduction stays out (the transient model handles low speed itself
        // — as MFeval's transient modes skip that reduction) while its
        // backward-running conventions stay in. Steady: the MF as it is.
        let fbase = if steady {
            base
        } else {
            let vl = tyre.params().p.vxlow;
            let vl = if vl.is_finite() && vl > 0.0 { vl } else { 1.0 };
            let v = inp.vx.abs().max(vl);
            MfInput {
                vx: if inp.vx < 0.0 { -v } else { v },
                ..base
            }
        };
        // The probe computes only what this step uses: Fx, Fy at zero slip for
        // the low-speed offset correction and LuGre's direct force, My for the
        // transient models' rolling resistance (the steady model takes the
        // force evaluation's). The rest of `SlipProps` is always computed.
        let floored = fbase.vx != base.vx;
        let want_forces = floored || self.config.kind == TransientKind::LuGre;
        // The steady model on the ground without turn slip needs from the
        // probe only Re (for the slips): its force evaluation gives μ, Kxκ,
        // Kyα, C and σ too, bit-identical to the probe's
        // ([`Tyre::forces_and_props`]), so the probe's Magic Formula is skipped.
        let brush = self.options.brush.as_ref();
        let fast = steady && !mode.turn_slip && fz > FZ_OFF && brush.is_none();
        let (mut probe, mut props, terms) = if fast {
            let probe = SlipProps {
                re: tyre.zero_slip_radius(&base, mode),
                ..Default::default()
            };
            let props = TyreProps {
                re: rolling_radius(tyre, probe.re),
                ..Default::default()
            };
            (probe, props, None)
        } else {
            let my = !steady || brush.is_some();
            let (probe, terms) = tyre.slip_properties_terms(&base, mode, 1.0, want_forces, my);
            let mut props = tyre_props(tyre, &probe, fz, inp.vx.abs());
            if let Some(b) = brush {
                crate::brush::transient::step_props(b, &mut props, fz);
            }
            (probe, props, Some(terms))
        };
        let kin = kinematics(self.config.input_mode, inp, props.re);
        // The extension hook (friction and slip-stiffness scales, see
        // `extension`); a tyre without one keeps s and c = 1 untouched.
        let ext = tyre.extension();
        let (s, c) = match ext {
            Some(e) => {
                let (es, ec) = e.scales(&self.state, fz, &kin);
                (s * es, ec)
            }
            None => (s, 1.0),
        };
        let dir = if self.config.input_mode == InputMode::Velocities && inp.vx < 0.0 {
            -1.0
        } else {
            1.0
        };
        // The steady model's slips: the MF convention κ = −Vsx/Vx with the
        // sign of Vx (MFeval flips Fx for Vx < 0 itself).
        let steady_slip = Slip {
            kappa: dir * kin.kappa,
            ..Slip::of(&kin)
        };
        let solved = if fast {
            let (f, zp) = mf_at_props(tyre, &fbase, mode, stiff_slip(c, steady_slip), s);
            probe = SlipProps { re: probe.re, ..zp };
            props = tyre_props(tyre, &probe, fz, inp.vx.abs());
            Some(f)
        } else {
            None
        };
        let ctx = StepCtx {
            tyre,
            mode,
            base: fbase,
            kin,
            props,
            s,
            c,
            fz,
            omega_re: inp.omega * props.re,
            floored,
            dir,
            terms,
            brush,
        };
        let mut next = self.state;
        let mut out = if fz <= FZ_OFF {
            // Off the ground: no force (whatever the MF makes of Fz = 0), the
            // tyre springs back to rest.
            next = TransientState::default();
            let fin = |x: f64| if x.is_finite() { x } else { 0.0 };
            WheelOutput {
                kappa: kin.kappa,
                alpha: kin.alpha,
                re: props.re,
                mux: fin(s * props.mux),
                muy: fin(s * props.muy),
                vsx: kin.vsx,
                vsy: kin.vsy,
                sigma_x: props.sigma_x,
                sigma_y: props.sigma_y,
                friction_scale: s,
                stiffness_scale: c,
                ..Default::default()
            }
        } else if steady {
            let f = match (solved, brush) {
                (Some(f), _) => f,
                // The brush's κ is −Vsx/|Vx| (its force opposes the slip speed
                // whichever way the wheel rolls).
                (None, Some(_)) => ctx.forces(&fbase, Slip::of(&kin)),
                (None, None) => mf_at(tyre, &fbase, mode, ctx.stiff(steady_slip), s),
            };
            self.output(&ctx, &f, steady_slip)
        } else {
            match self.config.kind {
                TransientKind::Relaxation => {
                    let (k, t) = if self.options.nonlinear {
                        relax_nonlinear(&ctx, &mut next, dt)
                    } else {
                        relax_linear(&ctx, &mut next, dt)
                    };
                    let mut b = fbase;
                    if mode.turn_slip {
                        b.phit = next.x[SLOT_PHI];
                    }
                    let sl = Slip::new(k, t);
                    let mut o = ctx.forces(&b, sl);
                    let (cx, cy) = ctx.offset_correction();
                    o.fx += cx;
                    o.fy += cy;
                    // Report the slip in the MF's convention (as the steady model).
                    let used = Slip {
                        kappa: ctx.dir * k,
                        ..sl
                    };
                    self.output(&ctx, &o, used)
                }
                _ => lugre::step(&ctx, &self.options.lugre, &mut next, dt),
            }
        };
        if let Some(e) = ext {
            // The load curve's aligning-moment scale (1 without one).
            out.mz *= e.moment_scale(fz);
            e.advance(&self.state, &mut next, &out, dt);
        }
        if (!steady || brush.is_some()) && fz > FZ_OFF {
            // Rolling resistance at the actual speed and direction (the MF's
            // own low-speed treatment), from the zero-slip probe.
            out.my = probe.my;
        }
        let all_finite = next.x.iter().all(|x| x.is_finite())
            && out.fx.is_finite()
            && out.fy.is_finite()
            && out.mx.is_finite()
            && out.my.is_finite()
            && out.mz.is_finite();
        if !all_finite {
            return Err(crate::Error::Numeric(format!(
                "transient step ({}): non-finite result for inputs {inp:?}, dt = {dt}",
                self.config.kind.name()
            )));
        }
        self.state = next;
        Ok(out)
    }

    fn output(&self, c: &StepCtx, o: &Forces, sl: Slip) -> WheelOutput {
        WheelOutput {
            fx: o.fx,
            fy: o.fy,
            mx: o.mx,
            my: o.my,
            mz: o.mz,
            kappa: sl.kappa,
            alpha: sl.alpha,
            re: c.props.re,
            mux: c.s * c.props.mux,
            muy: c.s * c.props.muy,
            vsx: c.kin.vsx,
            vsy: c.kin.vsy,
            sigma_x: c.props.sigma_x,
            sigma_y: c.props.sigma_y,
            friction_scale: c.s,
            stiffness_scale: c.c,
        }
    }
}
