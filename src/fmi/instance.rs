//! instance — one FMU instance: the FMI 2.0 co-simulation state machine, the
//! parameters (tyre file, input mode, transient model, use mode, side), the
//! input checks, the vehicle-side mirror, and the step, which is
//! [`TransientModel::step`] and nothing else.
//!
//! State machine (FMI 2.0, section 4.2.4): `Instantiated` → (fmi2EnterInitializationMode)
//! `InitializationMode` → (fmi2ExitInitializationMode) `StepComplete` ⟲ fmi2DoStep →
//! (fmi2Terminate) `Terminated`; fmi2Reset from any state but `Fatal` goes back to
//! `Instantiated`. `Error` is entered when initialisation fails (the instance has no
//! consistent configuration; only reset, free, FMU-state calls and getters remain);
//! `Fatal` when a panic was caught (only fmi2FreeInstance remains useful).
//! Refused calls (bad input, wrong state, unknown value reference, a model error)
//! return fmi2Error and leave the instance exactly as it was, so a later valid
//! call works.
//!
//! Side mirroring: the `.tir` describes the tyre as measured (its TYRESIDE). When
//! `side` names the other side, the tyre is its mirror image about the wheel's
//! x-z plane: the inputs vy, gamma, phit and alpha_in are negated on the way in
//! and the outputs Fy, Mx, Mz, alpha and Vsy on the way out (Fx, My, kappa, Re,
//! mux, muy, Vsx and the relaxation lengths are unchanged). A SYMMETRIC file is
//! never mirrored; an unknown TYRESIDE counts as LEFT (MF-Tyre's default).
//!
//! Must never: compute slips or forces itself, allocate in [`Instance::do_step`]
//! or the value getters/setters of Real/Integer/Boolean, or change anything on a
//! refused call.

use super::logging::{Category, Logger};
use super::types::Fmi2Status;
use super::vars::{
    self, boolean, integer, real, string, Causality, Values, VarInfo, VarType, Variability,
};
use crate::brush::{BrushParams, ForceModelKind};
use crate::mf::{Tyre, UseMode};
use crate::tir::TyreSide;
use crate::transient::{
    InputMode, LuGreParams, TransientConfig, TransientKind, TransientModel, TransientOptions,
    WheelInput, WheelOutput,
};
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Tag stored in every live instance (a cheap check against stray pointers).
pub const INSTANCE_TAG: u64 = 0x5459_5245_4b49_5431; // "TYREKIT1"

/// Name of the packaged tyre property file inside `resources/`.
pub const RESOURCE_TIR: &str = "tyre.tir";

/// FMI 2.0 co-simulation states (§4.2.4). The standard's `stepInProgress`,
/// `stepFailed` and `stepCanceled` never occur: steps are synchronous and a
/// refused step changes nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// After fmi2Instantiate or fmi2Reset: parameters and start values may be
    /// set, fmi2SetupExperiment called.
    Instantiated,
    /// Between fmi2EnterInitializationMode and fmi2ExitInitializationMode.
    InitializationMode,
    /// Initialized and ready for fmi2DoStep (also after every successful step).
    StepComplete,
    /// After fmi2Terminate: values stay readable, no more steps.
    Terminated,
    /// fmi2ExitInitializationMode failed: no consistent configuration; values
    /// stay readable, fmi2Reset or fmi2SetFMUstate starts over.
    Error,
    /// A panic was caught: only fmi2FreeInstance remains useful.
    Fatal,
}

impl Phase {
    /// Bit of this state in an "allowed states" mask.
    pub fn bit(self) -> u8 {
        1 << (self as u8)
    }
    /// The state's name as the standard writes it.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Instantiated => "instantiated",
            Phase::InitializationMode => "initializationMode",
            Phase::StepComplete => "stepComplete",
            Phase::Terminated => "terminated",
            Phase::Error => "error",
            Phase::Fatal => "fatal",
        }
    }
    /// Inverse of `as u8` (for the serialized state).
    pub fn from_u8(x: u8) -> Option<Phase> {
        [
            Phase::Instantiated,
            Phase::InitializationMode,
            Phase::StepComplete,
            Phase::Terminated,
            Phase::Error,
            Phase::Fatal,
        ]
        .get(x as usize)
        .copied()
    }
}

/// Allowed-state masks of the FMI 2.0 co-simulation calling sequence table.
pub mod allowed {
    use super::Phase::*;
    const fn m(p: super::Phase) -> u8 {
        1 << (p as u8)
    }
    /// Every state but `Fatal` (fmi2Reset and the FMU-state functions).
    pub const ALL_LIVE: u8 =
        m(Instantiated) | m(InitializationMode) | m(StepComplete) | m(Terminated) | m(Error);
    /// Every state, `Fatal` included (fmi2SetDebugLogging).
    pub const ANY: u8 = ALL_LIVE | m(Fatal);
    /// `Instantiated` only (fmi2SetupExperiment, fmi2EnterInitializationMode).
    pub const INSTANTIATED: u8 = m(Instantiated);
    /// `InitializationMode` only (fmi2ExitInitializationMode).
    pub const INIT: u8 = m(InitializationMode);
    /// `StepComplete` only (fmi2DoStep, fmi2Terminate).
    pub const STEP: u8 = m(StepComplete);
    /// Where values can be read (fmi2GetReal & co., fmi2GetDirectionalDerivative).
    pub const GET: u8 = m(InitializationMode) | m(StepComplete) | m(Terminated) | m(Error);
    /// Where values can be written (fmi2SetReal & co.,
    /// fmi2SetRealInputDerivatives); which variables, per state, is checked
    /// per variable.
    pub const SET: u8 = m(Instantiated) | m(InitializationMode) | m(StepComplete);
    /// Where the slave's status can be inquired (fmi2GetStatus & co., §4.2.3).
    pub const STATUS: u8 = m(StepComplete) | m(Terminated) | m(Error);
    /// Where fmi2GetRealOutputDerivatives may be called.
    pub const OUTPUT_DERIVATIVES: u8 = m(StepComplete) | m(Terminated) | m(Error);
    /// No state (fmi2CancelStep: there is never a step in progress to cancel).
    pub const NONE: u8 = 0;
}

/// Names of the states in a mask, for messages.
pub fn phases_in(mask: u8) -> String {
    (0..6u8)
        .filter_map(Phase::from_u8)
        .filter(|p| mask & p.bit() != 0)
        .map(Phase::name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// A loaded tyre and the `tyre_file` value it was loaded for.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The checked tyre model, shared with the FMU states that use it.
    pub tyre: Arc<Tyre>,
    /// The `tyre_file` parameter value ("" = the packaged resources/tyre.tir).
    pub key: String,
    /// The file actually read.
    pub path: PathBuf,
    /// FNV-1a of the file's bytes: an FMU state records it and is refused
    /// by an instance whose tyre differs (states never carry a path).
    pub hash: u64,
}

/// Everything an FMU state captures (fmi2GetFMUstate clones this).
#[derive(Clone, Debug)]
pub struct Sim {
    /// The FMI state.
    pub phase: Phase,
    /// Current communication point (s): the time the next fmi2DoStep must start at.
    pub time: f64,
    /// `startTime` of fmi2SetupExperiment (s; 0 until it is called).
    pub start_time: f64,
    /// `stopTime` of fmi2SetupExperiment (s), if the master defined one.
    pub stop_time: Option<f64>,
    /// Current value of every variable (inputs, outputs, parameters).
    pub values: Values,
    /// The transient tyre model: its configuration, options and dynamic state.
    pub model: TransientModel,
    /// Evaluate the mirror image of the file's tyre (see the module header).
    pub mirror: bool,
    /// The tyre in use (the current `tyre_file`).
    pub loaded: Loaded,
}

/// One FMU instance (what fmi2Component points to).
pub struct Instance {
    /// [`INSTANCE_TAG`] while the instance lives; 0 once fmi2FreeInstance ran.
    pub tag: u64,
    /// The master's logger with this instance's category filter.
    pub log: Logger,
    /// The FMU's resources folder (from fmuResourceLocation).
    pub resources: PathBuf,
    /// resources/tyre.tir, loaded at instantiation (what fmi2Reset returns to).
    pub default_tyre: Loaded,
    /// The simulation: state, values, model (what an FMU state copies).
    pub sim: Sim,
    /// The start values `tyrekit package` chose for this FMU (read from the
    /// packaged modelDescription.xml at instantiation; `fmi::start`).
    pub chosen: Vec<ChosenStart>,
    /// Addresses of the FMU states (`Box<Snapshot>`) this instance created
    /// and the master has not freed: fmi2FreeInstance frees them.
    pub states: Vec<usize>,
}

/// A parameter's start value chosen at packaging (`spec::CHOSEN_STARTS`): (name, value).
pub type ChosenStart = (&'static str, String);

/// The settings derived from the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derived {
    /// Transient model, input mode and use mode (parameters `transient`,
    /// `input_mode`, `use_mode`).
    pub config: TransientConfig,
    /// Non-linear relaxation (parameter `nonlinear`) and the LuGre parameters
    /// of the tyre file's `[LUGRE]` section (defaults without one).
    pub options: TransientOptions,
    /// Evaluate the mirror image of the file's tyre: parameter `side` names
    /// the side opposite the file's TYRESIDE (see the module header).
    pub mirror: bool,
}

/// Parse the parameter values into a transient configuration and the mirror flag.
pub fn derive(values: &Values, tyre: &Tyre) -> Result<Derived, String> {
    let mode = values.string(string::INPUT_MODE);
    let input_mode = match mode.trim().to_ascii_lowercase().as_str() {
        "velocities" => InputMode::Velocities,
        "slips" => InputMode::Slips,
        _ => {
            return Err(format!(
                "input_mode = \"{mode}\": expected \"velocities\" or \"slips\""
            ))
        }
    };
    let kind_s = values.string(string::TRANSIENT);
    // "file" (the default): the model the tyre file names, steady if none.
    let kind = TransientKind::resolve(kind_s, tyre.params()).map_err(|e| e.to_string())?;
    let code = values.integers[integer::USE_MODE];
    let use_mode = u32::try_from(code)
        .ok()
        .and_then(UseMode::from_code)
        .ok_or_else(|| {
            format!(
                "use_mode = {code}: expected three digits, each 1 or 2 (limits, alpha*, turn slip), e.g. 111"
            )
        })?;
    let side_s = values.string(string::SIDE);
    let wanted = match side_s.trim().to_ascii_lowercase().as_str() {
        "" => None,
        "left" => Some(TyreSide::Left),
        "right" => Some(TyreSide::Right),
        _ => {
            return Err(format!(
                "side = \"{side_s}\": expected \"\" (as the file's TYRESIDE), \"left\" or \"right\""
            ))
        }
    };
    let file_side = match tyre.params().side {
        TyreSide::Unknown => TyreSide::Left,
        s => s,
    };
    let mirror = match wanted {
        None => false,
        Some(_) if file_side == TyreSide::Symmetric => false,
        Some(w) => w != file_side,
    };
    let lugre = LuGreParams::from_tyre_params(tyre.params())
        .map_err(|e| format!("transient = \"{kind_s}\": [LUGRE] section: {e}"))?;
    let force_s = values.string(string::FORCE_MODEL);
    let brush = match ForceModelKind::parse(force_s) {
        Some(ForceModelKind::Mf) => None,
        Some(ForceModelKind::Brush) => Some(
            BrushParams::from_tyre(tyre)
                .map_err(|e| format!("force_model = \"brush\": [BRUSH] section: {e}"))?
                .0,
        ),
        None => {
            return Err(format!(
                "force_model = \"{force_s}\": expected \"mf\" or \"brush\""
            ))
        }
    };
    Ok(Derived {
        config: TransientConfig {
            kind,
            input_mode,
            use_mode,
        },
        options: TransientOptions {
            nonlinear: values.booleans[boolean::NONLINEAR],
            lugre,
            brush,
        },
        mirror,
    })
}

/// Load a tyre property file for the `tyre_file` value `key` ("" = packaged default).
pub fn load_tyre(resources: &Path, key: &str) -> Result<Loaded, String> {
    let path = if key.trim().is_empty() {
        resources.join(RESOURCE_TIR)
    } else {
        let p = PathBuf::from(key.trim());
        if p.is_absolute() {
            p
        } else {
            resources.join(p)
        }
    };
    // Bounded, non-blocking read of a regular file only (a FIFO or a device
    // as tyre_file is refused at once), then the one validation of a tyre.
    let fail = |e: crate::Error| format!("cannot load tyre property file {}: {e}", path.display());
    let bytes = crate::tir::read_file(&path).map_err(fail)?;
    let params =
        crate::tir::TyreParams::from_bytes(&bytes, &path.display().to_string()).map_err(fail)?;
    let tyre = Tyre::checked(params).map_err(fail)?;
    Ok(Loaded {
        tyre: Arc::new(tyre),
        key: key.to_string(),
        hash: super::snapshot::fnv1a(&bytes),
        path,
    })
}

/// The input slots checked before every step, with their names.
const INPUTS: [(usize, &str); 10] = [
    (real::VX, "vx"),
    (real::VY, "vy"),
    (real::OMEGA, "omega"),
    (real::FZ, "Fz"),
    (real::GAMMA, "gamma"),
    (real::P, "p"),
    (real::PHIT, "phit"),
    (real::MU_SCALE, "mu_scale"),
    (real::KAPPA_IN, "kappa_in"),
    (real::ALPHA_IN, "alpha_in"),
];

/// The hard limits (min, max) of a Real slot, from the modelDescription's
/// `min`/`max` attributes (the generated table: one source of truth).
const fn limits_of(slot: usize) -> (f64, f64) {
    let mut i = 0;
    while i < vars::VARIABLES.len() {
        let v = &vars::VARIABLES[i];
        if matches!(v.ty, VarType::Real) && v.slot == slot {
            return (v.min, v.max);
        }
        i += 1;
    }
    (f64::NEG_INFINITY, f64::INFINITY)
}

/// (min, max) of every Real slot, built at compile time (the setters' check).
const REAL_LIMITS: [(f64, f64); real::N] = {
    let mut out = [(0.0, 0.0); real::N];
    let mut i = 0;
    while i < real::N {
        out[i] = limits_of(i);
        i += 1;
    }
    out
};

/// (slot, min, max) of every checked input, built at compile time.
const LIMITS: [(usize, f64, f64); INPUTS.len()] = {
    let mut out = [(0, 0.0, 0.0); INPUTS.len()];
    let mut i = 0;
    while i < INPUTS.len() {
        let (lo, hi) = limits_of(INPUTS[i].0);
        out[i] = (INPUTS[i].0, lo, hi);
        i += 1;
    }
    out
};

/// The load above which a step is refused for this tyre: FZ_LIMIT_FACTOR ×
/// max(FNOMIN, FZMAX) (the Magic Formula's load terms are polynomials in
/// dfz = Fz/Fz0 − 1 that turn over far outside the measured range).
pub const FZ_LIMIT_FACTOR: f64 = 10.0;

/// The tyre-relative load limit (N) of [`FZ_LIMIT_FACTOR`].
pub fn fz_limit(tyre: &Tyre) -> f64 {
    let p = &tyre.params().p;
    FZ_LIMIT_FACTOR
        * p.fnomin
            .max(if p.fzmax.is_finite() { p.fzmax } else { 0.0 })
}

/// The lowest inflation pressure (Pa) accepted besides the sentinel 0 (=
/// the file's INFLPRES): below 0.1 bar a tyre is flat, and the Magic
/// Formula's pressure terms ((p/NOMPRES)^QSY7 …) diverge (p = 1e-300 Pa gave
/// My = −7e125 N·m with the limit checks off).
pub const P_MIN: f64 = 1e4;

/// Why an input value is refused (`None` = acceptable).
fn input_problem(slot: usize, x: f64) -> Option<String> {
    if !x.is_finite() {
        return Some("is not finite (NaN or infinite)".into());
    }
    if slot == real::P && x > 0.0 && x < P_MIN {
        return Some(format!(
            "is below {P_MIN} Pa (0.1 bar, a flat tyre) and not 0 (= the file's INFLPRES)"
        ));
    }
    let (lo, hi) = REAL_LIMITS
        .get(slot)
        .copied()
        .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    if !(lo..=hi).contains(&x) {
        return Some(format!(
            "is outside its physical range [{lo}, {hi}] (min/max in modelDescription.xml)"
        ));
    }
    None
}

impl Sim {
    /// The state right after instantiation / reset.
    fn initial(loaded: Loaded, chosen: &[ChosenStart]) -> Result<Sim, String> {
        let mut values = Values::start();
        super::start::apply(&mut values, &loaded.tyre);
        for (name, value) in chosen {
            // start::read_chosen only returns String parameters of spec::CHOSEN_STARTS.
            if let Some(v) = super::vars::by_name(name) {
                values.strings[v.slot] = std::ffi::CString::new(value.as_str()).unwrap_or_default();
            }
        }
        let d = derive(&values, &loaded.tyre)?;
        let mut sim = Sim {
            phase: Phase::Instantiated,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            values,
            model: TransientModel::new(d.config),
            mirror: d.mirror,
            loaded,
        };
        sim.apply(d);
        Ok(sim)
    }

    /// Install derived settings and the calculated parameters.
    pub fn apply(&mut self, d: Derived) {
        self.model.config = d.config;
        self.model.options = d.options;
        self.mirror = d.mirror;
        let p = &self.loaded.tyre.params().p;
        self.values.reals[real::R0] = p.unloaded_radius;
        self.values.reals[real::FZ0] = p.fnomin;
        self.values.reals[real::P0] = p.inflpres;
        self.values.booleans[boolean::MIRRORED] = d.mirror;
    }

    /// Step `model` by `dt` with the current inputs and write the outputs.
    /// On error nothing (model state, outputs) is changed. Allocation-free
    /// unless it fails.
    pub fn compute(&mut self, dt: f64, model: &mut TransientModel) -> Result<(), String> {
        advance(&mut self.values, &self.loaded.tyre, self.mirror, model, dt)
    }

    /// [`Sim::compute`] on the instance's own model (fmi2DoStep: no copy of
    /// the model; a refused step leaves it as it was all the same).
    pub fn step_own(&mut self, dt: f64) -> Result<(), String> {
        advance(
            &mut self.values,
            &self.loaded.tyre,
            self.mirror,
            &mut self.model,
            dt,
        )
    }
}

/// The work of [`Sim::compute`]: check the inputs, step `model`, check and
/// store the outputs. On error neither `model` nor `values` has changed.
fn advance(
    values: &mut Values,
    tyre: &Tyre,
    m: bool,
    model: &mut TransientModel,
    dt: f64,
) -> Result<(), String> {
    let r = &values.reals;
    // Fast check first (no branch per input; NaN fails every comparison);
    // the message only on failure.
    let mut ok = r[real::FZ] <= fz_limit(tyre);
    for (slot, lo, hi) in LIMITS {
        ok &= r[slot] >= lo && r[slot] <= hi;
    }
    ok &= r[real::P] == 0.0 || r[real::P] >= P_MIN;
    if !ok {
        return Err(input_error(r, tyre));
    }
    let inp = WheelInput {
        vx: r[real::VX],
        vy: flip(m, r[real::VY]),
        omega: r[real::OMEGA],
        fz: r[real::FZ],
        gamma: flip(m, r[real::GAMMA]),
        p: r[real::P],
        phit: flip(m, r[real::PHIT]),
        mu_scale: r[real::MU_SCALE],
        kappa_in: r[real::KAPPA_IN],
        alpha_in: flip(m, r[real::ALPHA_IN]),
    };
    let saved = model.state;
    let mut out = match model.step(tyre, &inp, dt) {
        Ok(o) => o,
        Err(e) => {
            model.state = saved;
            return Err(format!(
                "tyre model (transient = {}) refused the step: {e}",
                model.config.kind.name()
            ));
        }
    };
    let contact = inp.fz > 0.0;
    if contact {
        if !all_finite(&out) {
            model.state = saved;
            return Err(output_error(&mut out, &inp));
        }
    } else {
        // Off the ground: no force, no moment; nothing undefined leaks out.
        for (_, v) in output_fields(&mut out) {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
        out.fx = 0.0;
        out.fy = 0.0;
        out.mx = 0.0;
        out.my = 0.0;
        out.mz = 0.0;
    }
    let r = &mut values.reals;
    r[real::FX] = out.fx;
    r[real::FY] = flip(m, out.fy);
    r[real::MX] = flip(m, out.mx);
    r[real::MY] = out.my;
    r[real::MZ] = flip(m, out.mz);
    r[real::KAPPA] = out.kappa;
    r[real::ALPHA] = flip(m, out.alpha);
    r[real::RE] = out.re;
    r[real::MUX] = out.mux;
    r[real::MUY] = out.muy;
    r[real::VSX] = out.vsx;
    r[real::VSY] = flip(m, out.vsy);
    r[real::SIGMA_X] = out.sigma_x;
    r[real::SIGMA_Y] = out.sigma_y;
    values.booleans[boolean::CONTACT] = contact;
    Ok(())
}

/// Whether every output of a step is finite (one pass, no branch per field).
#[inline]
fn all_finite(o: &WheelOutput) -> bool {
    [
        o.fx, o.fy, o.mx, o.my, o.mz, o.kappa, o.alpha, o.re, o.mux, o.muy, o.vsx, o.vsy,
        o.sigma_x, o.sigma_y,
    ]
    .iter()
    .fold(true, |ok, x| ok & x.is_finite())
}

/// The message for refused inputs (cold path).
#[cold]
fn input_error(r: &[f64], tyre: &Tyre) -> String {
    for (slot, name) in INPUTS {
        if let Some(why) = input_problem(slot, r[slot]) {
            return format!(
                "input {name} = {} {why}; step refused, nothing changed",
                r[slot]
            );
        }
    }
    let lim = fz_limit(tyre);
    if r[real::FZ] > lim {
        return format!(
            "input Fz = {} N is above {FZ_LIMIT_FACTOR} x max(FNOMIN, FZMAX) = {lim} N of the \
             loaded tyre, where the Magic Formula has no meaning; step refused, nothing changed",
            r[real::FZ]
        );
    }
    "inputs refused".into()
}

/// The message for a non-finite model output (cold path).
#[cold]
fn output_error(out: &mut WheelOutput, inp: &WheelInput) -> String {
    let bad = output_fields(out)
        .into_iter()
        .find(|(_, v)| !v.is_finite())
        .map(|(n, v)| format!("{n} = {v}"))
        .unwrap_or_default();
    format!(
        "tyre model returned {bad} for vx={} vy={} omega={} Fz={} gamma={} (nothing changed)",
        inp.vx, inp.vy, inp.omega, inp.fz, inp.gamma
    )
}

/// Mirror a lateral quantity when `mirror` (as `0 - x`, so that a zero stays +0).
#[inline]
fn flip(mirror: bool, x: f64) -> f64 {
    if mirror {
        0.0 - x
    } else {
        x
    }
}

/// The outputs of a step by name (for the finiteness check).
fn output_fields(o: &mut WheelOutput) -> [(&'static str, &mut f64); 14] {
    [
        ("Fx", &mut o.fx),
        ("Fy", &mut o.fy),
        ("Mx", &mut o.mx),
        ("My", &mut o.my),
        ("Mz", &mut o.mz),
        ("kappa", &mut o.kappa),
        ("alpha", &mut o.alpha),
        ("Re", &mut o.re),
        ("mux", &mut o.mux),
        ("muy", &mut o.muy),
        ("Vsx", &mut o.vsx),
        ("Vsy", &mut o.vsy),
        ("sigma_x", &mut o.sigma_x),
        ("sigma_y", &mut o.sigma_y),
    ]
}

/// Look up a value reference of the expected type.
#[inline]
fn var(vr: u32, ty: VarType) -> Result<&'static VarInfo, String> {
    match vars::lookup(vr) {
        Some(v) if v.ty == ty => Ok(v),
        other => Err(var_error(vr, ty, other)),
    }
}

/// "No slot" in the compact value-reference tables below.
const NO_SLOT: u8 = u8::MAX;

/// valueReference → Real storage slot for the hot getters/setters, built at
/// compile time from the generated variable table (so it cannot disagree
/// with it): with `inputs_only`, only the Real *inputs* (the only Real
/// variables fmi2SetReal accepts; the caller's state mask already limits
/// when); otherwise every Real. [`NO_SLOT`] for anything else. A value
/// reference that is not in the table (or not of the kind) takes the full
/// checked path, which names the problem.
const fn real_slots(inputs_only: bool) -> [u8; vars::VR_TABLE.len()] {
    let mut t = [NO_SLOT; vars::VR_TABLE.len()];
    let mut vr = 0;
    while vr < t.len() {
        let i = vars::VR_TABLE[vr] as usize;
        if i < vars::VARIABLES.len() {
            let v = &vars::VARIABLES[i];
            let real = matches!(v.ty, VarType::Real);
            let input = matches!(v.causality, Causality::Input);
            if real && (input || !inputs_only) && v.slot < NO_SLOT as usize {
                t[vr] = v.slot as u8;
            }
        }
        vr += 1;
    }
    t
}

/// Real slot of each value reference (see [`real_slots`]).
const REAL_SLOT: [u8; vars::VR_TABLE.len()] = real_slots(false);
/// Real slot of each Real input's value reference (see [`real_slots`]).
const REAL_INPUT_SLOT: [u8; vars::VR_TABLE.len()] = real_slots(true);

/// The slot of `vr` in `table`, or [`NO_SLOT`].
#[inline(always)]
fn slot_in(table: &[u8], vr: u32) -> usize {
    table.get(vr as usize).copied().unwrap_or(NO_SLOT) as usize
}

#[cold]
fn var_error(vr: u32, ty: VarType, found: Option<&VarInfo>) -> String {
    match found {
        None => format!("unknown valueReference {vr}"),
        Some(v) => format!(
            "valueReference {vr} is {} ({}), not a {}",
            v.name,
            v.ty.name(),
            ty.name()
        ),
    }
}

impl Instance {
    /// fmi2Instantiate's work after the C arguments are checked: find the
    /// resources folder and load `resources/tyre.tir`.
    pub fn new(
        log: Logger,
        resource_location: Option<&str>,
    ) -> Result<Box<Instance>, (Logger, String)> {
        let Some(loc) = resource_location else {
            return Err((
                log,
                "no fmuResourceLocation given: cannot find resources/tyre.tir".into(),
            ));
        };
        let resources = match super::resources::resource_dir(loc) {
            Ok(r) => r,
            Err(e) => return Err((log, e)),
        };
        if !resources.is_dir() {
            return Err((
                log,
                format!(
                    "resources folder {} (from fmuResourceLocation \"{loc}\") does not exist",
                    resources.display()
                ),
            ));
        }
        let default_tyre = match load_tyre(&resources, "") {
            Ok(t) => t,
            Err(e) => return Err((log, e)),
        };
        // The packaged XML beside resources/ holds the chosen start values
        // (e.g. force_model = brush); none there = the built-in XML's.
        let chosen = match super::start::read_chosen(&resources) {
            Ok(c) => c,
            Err(e) => return Err((log, e)),
        };
        let sim = match Sim::initial(default_tyre.clone(), &chosen) {
            Ok(s) => s,
            Err(e) => return Err((log, e)),
        };
        let inst = Box::new(Instance {
            tag: INSTANCE_TAG,
            log,
            resources,
            default_tyre,
            sim,
            chosen,
            states: Vec::new(),
        });
        for w in &inst.default_tyre.tyre.params().warnings {
            inst.log.status(Fmi2Status::Warning, w);
        }
        inst.event(&format!(
            "instantiated; tyre {} ({:?}, TYRESIDE {:?})",
            inst.default_tyre.path.display(),
            inst.default_tyre.tyre.version(),
            inst.default_tyre.tyre.params().side
        ));
        Ok(inst)
    }

    /// Log a logEvents message (only formatted when it will be sent).
    pub fn event(&self, msg: &str) {
        self.log.log(Fmi2Status::Ok, Category::Events, msg);
    }

    /// fmi2Reset: back to the state right after fmi2Instantiate.
    pub fn reset(&mut self) -> Result<(), String> {
        self.sim = Sim::initial(self.default_tyre.clone(), &self.chosen)?;
        self.event("reset to the instantiated state");
        Ok(())
    }

    /// fmi2SetupExperiment.
    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), String> {
        if !start.is_finite() {
            return Err(format!("startTime {start} is not finite"));
        }
        if let Some(s) = stop {
            if !s.is_finite() || s < start {
                return Err(format!(
                    "stopTime {s} must be finite and >= startTime {start}"
                ));
            }
        }
        self.sim.start_time = start;
        self.sim.time = start;
        self.sim.stop_time = stop;
        Ok(())
    }

    /// Outputs for the current inputs without advancing the dynamics (used in
    /// initialization mode and at fmi2ExitInitializationMode).
    pub fn refresh_initial_outputs(&mut self) -> Result<(), String> {
        let mut probe = self.sim.model.clone();
        self.sim.compute(0.0, &mut probe)
    }

    /// fmi2ExitInitializationMode: the first outputs must be computable,
    /// otherwise the instance goes to the error state.
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        if let Err(e) = self.refresh_initial_outputs() {
            self.sim.phase = Phase::Error;
            return Err(format!("initialization failed: {e}"));
        }
        self.sim.phase = Phase::StepComplete;
        self.event(&format!(
            "initialized: tyre {}, transient {}, input_mode {}, use_mode {}, mirrored {}",
            self.sim.loaded.path.display(),
            self.sim.model.config.kind.name(),
            self.sim.values.string(string::INPUT_MODE),
            self.sim.values.integers[integer::USE_MODE],
            self.sim.mirror
        ));
        Ok(())
    }

    /// fmi2DoStep. Refused steps change nothing.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        if !(h.is_finite() && h > 0.0) {
            return Err(format!("communicationStepSize {h} must be finite and > 0"));
        }
        let tol = 1e-9 * self.sim.time.abs().max(1.0);
        if !t.is_finite() || (t - self.sim.time).abs() > tol {
            return Err(format!(
                "currentCommunicationPoint {t} differs from the FMU's time {} (steps must follow each other)",
                self.sim.time
            ));
        }
        // stopTime is not enforced: the tyre has no end of validity in time, and
        // common masters (fmi-sim) take a last step past stopTime when the step
        // does not divide the interval.
        self.sim.step_own(h)?;
        // Adopt the master's clock so that long runs do not drift.
        self.sim.time = t + h;
        Ok(())
    }

    /// Is a variable settable in the current state? (FMI 2.0, section 4.2.4)
    fn check_settable(&self, v: &VarInfo) -> Result<(), String> {
        match v.causality {
            Causality::Output | Causality::CalculatedParameter => Err(format!(
                "{} is {}: it cannot be set",
                v.name,
                if v.causality == Causality::Output {
                    "an output"
                } else {
                    "a calculated parameter"
                }
            )),
            Causality::Parameter
                if v.variability != Variability::Tunable
                    && !matches!(
                        self.sim.phase,
                        Phase::Instantiated | Phase::InitializationMode
                    ) =>
            {
                Err(format!(
                    "{} is a fixed parameter: set it before fmi2ExitInitializationMode (now in state {})",
                    v.name,
                    self.sim.phase.name()
                ))
            }
            _ => Ok(()),
        }
    }

    /// fmi2GetReal (one compact table look-up per value; an unknown or
    /// non-Real reference falls back to the checked look-up for its message).
    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Result<(), String> {
        if self.sim.phase == Phase::InitializationMode {
            self.refresh_initial_outputs()?;
        }
        let reals = &self.sim.values.reals;
        for (vr, o) in vrs.iter().zip(out.iter_mut()) {
            *o = match reals.get(slot_in(&REAL_SLOT, *vr)) {
                Some(x) => *x,
                None => reals[var(*vr, VarType::Real)?.slot],
            };
        }
        Ok(())
    }

    /// fmi2SetReal: every value is checked before any is stored. The usual
    /// call (Real inputs, acceptable values) is checked in one branch-free
    /// pass over a compact table; anything else takes the full checks, which
    /// name the first problem.
    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Result<(), String> {
        let mut ok = true;
        for (vr, x) in vrs.iter().zip(vals) {
            let s = slot_in(&REAL_INPUT_SLOT, *vr);
            ok &= s != NO_SLOT as usize && input_problem(s, *x).is_none();
        }
        if ok {
            let reals = &mut self.sim.values.reals;
            for (vr, x) in vrs.iter().zip(vals) {
                if let Some(r) = reals.get_mut(slot_in(&REAL_INPUT_SLOT, *vr)) {
                    *r = *x;
                }
            }
            return Ok(());
        }
        for (vr, x) in vrs.iter().zip(vals) {
            let v = var(*vr, VarType::Real)?;
            self.check_settable(v)?;
            if let Some(why) = input_problem(v.slot, *x) {
                return Err(format!("{} = {x} {why}; value not taken", v.name));
            }
        }
        for (vr, x) in vrs.iter().zip(vals) {
            if let Some(v) = vars::lookup(*vr) {
                self.sim.values.reals[v.slot] = *x;
            }
        }
        Ok(())
    }

    /// fmi2GetInteger.
    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Result<(), String> {
        for (vr, o) in vrs.iter().zip(out.iter_mut()) {
            *o = self.sim.values.integers[var(*vr, VarType::Integer)?.slot];
        }
        Ok(())
    }

    /// fmi2SetInteger (parameters are validated when set).
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> Result<(), String> {
        for (vr, x) in vrs.iter().zip(vals) {
            let v = var(*vr, VarType::Integer)?;
            self.check_settable(v)?;
            let old = self.sim.values.integers[v.slot];
            self.sim.values.integers[v.slot] = *x;
            if let Err(e) = self.reconfigure() {
                self.sim.values.integers[v.slot] = old;
                return Err(format!("{e}; value not taken"));
            }
        }
        Ok(())
    }

    /// fmi2GetBoolean.
    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [i32]) -> Result<(), String> {
        if self.sim.phase == Phase::InitializationMode {
            self.refresh_initial_outputs()?;
        }
        for (vr, o) in vrs.iter().zip(out.iter_mut()) {
            *o = i32::from(self.sim.values.booleans[var(*vr, VarType::Boolean)?.slot]);
        }
        Ok(())
    }

    /// fmi2SetBoolean: every reference is checked before any value is stored,
    /// and the values are taken back if the configuration they give is refused
    /// (as fmi2SetInteger and fmi2SetString do).
    pub fn set_boolean(&mut self, vrs: &[u32], vals: &[i32]) -> Result<(), String> {
        for vr in vrs {
            let v = var(*vr, VarType::Boolean)?;
            self.check_settable(v)?;
        }
        let old = self.sim.values.booleans;
        for (vr, x) in vrs.iter().zip(vals) {
            if let Some(v) = vars::lookup(*vr) {
                self.sim.values.booleans[v.slot] = *x != 0;
            }
        }
        // A Boolean parameter (nonlinear) changes the derived options.
        self.reconfigure().map_err(|e| {
            self.sim.values.booleans = old;
            format!("{e}; values not taken")
        })
    }

    /// fmi2GetString: pointers into the instance, valid until the next call.
    pub fn get_string(
        &self,
        vrs: &[u32],
        out: &mut [*const std::os::raw::c_char],
    ) -> Result<(), String> {
        for (vr, o) in vrs.iter().zip(out.iter_mut()) {
            *o = self.sim.values.strings[var(*vr, VarType::String)?.slot].as_ptr();
        }
        Ok(())
    }

    /// fmi2SetString for one variable (parameters are validated, the tyre file
    /// loaded, when set).
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<(), String> {
        let v = var(vr, VarType::String)?;
        self.check_settable(v)?;
        let new = CString::new(value).map_err(|_| format!("{}: text contains NUL", v.name))?;
        let old_loaded = self.sim.loaded.clone();
        if v.slot == string::TYRE_FILE && value != self.sim.loaded.key {
            self.sim.loaded = if value.trim().is_empty() {
                self.default_tyre.clone()
            } else {
                load_tyre(&self.resources, value)?
            };
            for w in &self.sim.loaded.tyre.params().warnings {
                self.log.status(Fmi2Status::Warning, w);
            }
        }
        let old = std::mem::replace(&mut self.sim.values.strings[v.slot], new);
        if let Err(e) = self.reconfigure() {
            self.sim.values.strings[v.slot] = old;
            self.sim.loaded = old_loaded;
            return Err(format!("{e}; value not taken"));
        }
        if v.slot == string::TYRE_FILE {
            self.event(&format!(
                "tyre_file: loaded {}",
                self.sim.loaded.path.display()
            ));
        }
        Ok(())
    }

    /// Re-derive the configuration from the parameters.
    fn reconfigure(&mut self) -> Result<(), String> {
        let d = derive(&self.sim.values, &self.sim.loaded.tyre)?;
        self.sim.apply(d);
        Ok(())
    }

    /// Install a complete state (fmi2SetFMUstate); checked before anything changes.
    pub fn restore(&mut self, sim: &Sim) -> Result<(), String> {
        let d = derive(&sim.values, &sim.loaded.tyre)?;
        if d.config != sim.model.config || d.options != sim.model.options || d.mirror != sim.mirror
        {
            return Err("FMU state is inconsistent with its own parameters".into());
        }
        self.sim.clone_from(sim);
        Ok(())
    }
}
