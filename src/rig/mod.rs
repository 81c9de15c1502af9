//! rig — a flat-belt tyre test-rig simulator (Calspan TIRF / FSAE TTC style)
//! that runs a test programme on a *truth model* and writes what the rig
//! would record: the TTC `.mat` and `.dat` layouts, SAE signs, TTC units
//! (kph, deg, N, N-m, kPa, cm, °C — or the US-customary export), with sensor
//! noise and offsets, a warm-up before the programme, and the standard
//! programme (slip angle swept at 4°/s through −4 → +12 → −12 → +3° (SAE),
//! five loads, inclinations 0/2/4°, three pressures; drive/brake runs sweeping
//! the slip ratio ±0.2 at SAE slip angles 0, −3, −6°).
//!
//! The truth model is a trait ([`TruthModel`]) so that concealed physics
//! (relaxation lag, thermal friction, load/pressure/speed effects, rolling
//! radius …) can be layered over the plain steady Magic Formula
//! ([`SteadyMf`]) by the diagnosis work. The noise-free ISO-W truth of every
//! recorded row is returned alongside ([`RigRun::truth`]) so tests can check
//! what a reader recovers.
//!
//! Must never: use an unseeded random source (runs are reproducible from
//! [`RigConfig::seed`]), or allocate per sample inside the truth model call.

use crate::data::conventions::{from_iso, AxisSample, AxisSystem};
use crate::data::{RawColumn, RawTable, Sample, Segment, SegmentKind};
use crate::error::{Error, Result};
use crate::mf::{Forces, MfInput, Tyre, UseMode};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// What the rig imposes at one instant (ISO-W, SI), handed to the truth model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RigInput {
    /// Time since the start of the recording (s).
    pub time: f64,
    /// Magic Formula inputs: Fz, κ, α, γ, φt, Vx (= V·cos α), P, Ω.
    pub mf: MfInput,
    /// Belt (road) speed V (m/s).
    pub v_belt: f64,
    /// Index of the programme step (segment or transition) being run.
    pub step: usize,
}

/// What the truth model returns (ISO-W, SI).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TruthOutput {
    /// Forces and moments at the contact point (ISO-W; N, N·m). The normal
    /// load is imposed by the rig ([`RigInput::mf`]), so it is not returned.
    pub forces: Forces,
    /// Effective rolling radius (m) — sets Ω for a given κ.
    pub re: f64,
    /// Loaded radius (m).
    pub rl: f64,
    /// Tread surface temperature (°C), NaN when the model has none.
    pub tread_temp: f64,
}

/// A truth model: the physics the rig "measures". Implementations may hold
/// states (lags, temperatures); `dt` is the time since the previous call
/// (0 on the first call after [`TruthModel::reset`]). The rig calls
/// [`TruthModel::sample`] exactly once per simulated sample, in time order,
/// also while the tyre is unloaded between runs (Fz = 0).
///
/// A concealed effect is a wrapper around another model, e.g. a first-order
/// slip-angle lag with relaxation length σ (Pacejka 3rd ed. eq. 7.11):
///
/// ```
/// use tyrekit::rig::{RigInput, SteadyMf, TruthModel, TruthOutput};
/// struct Lagged<M: TruthModel> { inner: M, sigma: f64, alpha: f64 }
/// impl<M: TruthModel> TruthModel for Lagged<M> {
///     fn sample(&mut self, inp: &RigInput, dt: f64) -> TruthOutput {
///         let travel = inp.mf.vx.abs() * dt;
///         self.alpha += (inp.mf.alpha - self.alpha) * (1.0 - (-travel / self.sigma).exp());
///         let mut lagged = *inp;
///         lagged.mf.alpha = self.alpha;
///         self.inner.sample(&lagged, dt)
///     }
///     fn reset(&mut self) { self.alpha = 0.0; self.inner.reset() }
///     fn describe(&self) -> String { format!("{} + relaxation σ = {} m", self.inner.describe(), self.sigma) }
/// }
/// let mut m = Lagged { inner: SteadyMf::new(tyrekit::mf::Tyre::builtin()), sigma: 0.3, alpha: 0.0 };
/// let mut cfg = tyrekit::rig::RigConfig::standard(&tyrekit::mf::Tyre::builtin(), 1);
/// cfg.programme.pressures.truncate(1);
/// let run = tyrekit::rig::simulate(&cfg, &mut m);
/// assert_eq!(run.plan.len(), 30);
/// ```
pub trait TruthModel {
    /// Forces and radii for the imposed inputs.
    fn sample(&mut self, inp: &RigInput, dt: f64) -> TruthOutput;
    /// Reset internal states (called once before a programme runs).
    fn reset(&mut self) {}
    /// A short description (written into the recording's `source`).
    fn describe(&self) -> String;
}

/// The plain steady-state Magic Formula as a truth model.
#[derive(Clone, Debug)]
pub struct SteadyMf {
    /// The Magic Formula tyre evaluated at every sample.
    pub tyre: Tyre,
    /// Use mode passed to `Tyre::evaluate` ([`SteadyMf::new`]: no limits, α* off, no turn slip).
    pub mode: UseMode,
}

impl SteadyMf {
    /// Wrap a tyre (use mode 121: no limits, α* off — a rig sample is never clipped).
    pub fn new(tyre: Tyre) -> SteadyMf {
        SteadyMf {
            tyre,
            mode: UseMode {
                limits: false,
                alpha_star: false,
                turn_slip: false,
            },
        }
    }
}

/// Radii with fallbacks when the model reports none (see [`crate::data::slip::model_radii`]).
pub use crate::data::slip::model_radii as radii;

pub mod effects;

impl TruthModel for SteadyMf {
    fn sample(&mut self, inp: &RigInput, _dt: f64) -> TruthOutput {
        let o = self.tyre.evaluate(&inp.mf, self.mode);
        let (re, rl) = radii(&self.tyre, inp.mf.fz, o.re, o.rl);
        TruthOutput {
            forces: Forces {
                fx: o.fx,
                fy: o.fy,
                mx: o.mx,
                my: o.my,
                mz: o.mz,
            },
            re,
            rl,
            tread_temp: f64::NAN,
        }
    }
    fn describe(&self) -> String {
        format!("steady MF ({})", self.tyre.params().source)
    }
}

/// The warm-up run before the programme: slip-angle sweeps (ISO, rad) through
/// `points` at `rate` (rad/s), at the programme's first set point.
#[derive(Clone, Debug)]
pub struct Warmup {
    /// Turning points of the slip-angle sweep (ISO-W α, rad), run from and back to 0.
    pub points: Vec<f64>,
    /// Slip-angle sweep rate (rad/s).
    pub rate: f64,
    /// Load of the warm-up (N); None: the programme's first load (the
    /// warm-up then runs straight into the first segment at the same set point).
    pub fz: Option<f64>,
}

/// A test programme (ISO-W, SI). [`Programme::standard`] gives the TTC-like one.
#[derive(Clone, Debug)]
pub struct Programme {
    /// Inflation pressures (Pa), outer loop.
    pub pressures: Vec<f64>,
    /// Inclinations of the cornering runs (rad).
    pub inclinations: Vec<f64>,
    /// Loads (N), inner loop.
    pub loads: Vec<f64>,
    /// Belt speed (m/s) of the cornering runs, and of the drive/brake runs
    /// when `db_speeds` is empty.
    pub speed: f64,
    /// Cornering sweep turning points (ISO α, rad), from and back to 0.
    pub lateral_points: Vec<f64>,
    /// Slip-angle sweep rate (rad/s).
    pub alpha_rate: f64,
    /// Drive/brake slip-angle set points (ISO α, rad); empty: no drive/brake runs.
    pub db_alphas: Vec<f64>,
    /// Inclinations of the drive/brake runs (rad).
    pub db_inclinations: Vec<f64>,
    /// Belt speeds of the drive/brake runs (m/s), a loop inside each slip
    /// angle (the loads inside it), so the speeds come round again with
    /// every slip angle instead of rising once through the run, as tyre
    /// tests run their speed programmes; empty: `speed` alone.
    pub db_speeds: Vec<f64>,
    /// Slip-ratio sweep amplitude A (–): 0 → +A → −A → 0.
    pub db_kappa: f64,
    /// Slip-ratio sweep rate (1/s).
    pub kappa_rate: f64,
    /// Time to move between set points (s), at zero slip.
    pub transition: f64,
    /// Warm-up before the programme (None: no warm-up).
    pub warmup: Option<Warmup>,
}

impl Programme {
    /// The standard programme for a tyre of nominal load `fnom` (N) and
    /// nominal pressure `pnom` (Pa): loads 0.5/0.75/1/1.25/1.5·Fnom (in the
    /// order 1, 0.5, 1.5, 0.75, 1.25 like TTC runs, so neighbours differ),
    /// pressures 0.85/1/1.15·Pnom, cornering at 0/2/4°, 40 kph; cornering
    /// sweep 0 → −4 → +12 → −12 → +3 → 0° SAE (= 0 → +4 → −12 → +12 → −3 → 0°
    /// ISO) at 4°/s; drive/brake at SAE 0, −3, −6° (ISO 0, +3, +6°), γ = 0,
    /// κ 0 → +0.2 → −0.2 → 0 at 0.1/s; 1.5 s transitions; a warm-up of
    /// irregular ±6…8° sweeps at 3°/s.
    pub fn standard(fnom: f64, pnom: f64) -> Programme {
        let d = |x: f64| x.to_radians();
        Programme {
            pressures: vec![pnom * 0.85, pnom, pnom * 1.15],
            inclinations: vec![0.0, d(2.0), d(4.0)],
            loads: [1.0, 0.5, 1.5, 0.75, 1.25]
                .iter()
                .map(|k| k * fnom)
                .collect(),
            speed: 40.0 / 3.6,
            lateral_points: [4.0, -12.0, 12.0, -3.0].iter().map(|x| d(*x)).collect(),
            alpha_rate: d(4.0),
            db_alphas: vec![0.0, d(3.0), d(6.0)],
            db_inclinations: vec![0.0],
            db_speeds: Vec::new(),
            db_kappa: 0.2,
            kappa_rate: 0.1,
            transition: 1.5,
            warmup: Some(Warmup {
                points: [6.0, -6.0, 8.0, -5.0, 7.0, -8.0]
                    .iter()
                    .map(|x| d(*x))
                    .collect(),
                rate: d(3.0),
                fz: None,
            }),
        }
    }
}

/// Sensor noise (1σ) and constant offsets, in ISO-W SI.
#[derive(Clone, Debug)]
pub struct Noise {
    /// Fx noise (N, 1σ).
    pub fx: f64,
    /// Fy noise (N, 1σ).
    pub fy: f64,
    /// Fz noise on the recorded load (N, 1σ); see `fz_wander` for the true load.
    pub fz: f64,
    /// Mx noise (N·m, 1σ).
    pub mx: f64,
    /// Mz noise (N·m, 1σ).
    pub mz: f64,
    /// Slip-angle noise (rad, 1σ).
    pub alpha: f64,
    /// Inclination noise (rad, 1σ).
    pub gamma: f64,
    /// Inflation-pressure noise (Pa, 1σ).
    pub p: f64,
    /// Belt-speed noise (m/s, 1σ).
    pub v: f64,
    /// Wheel-spin noise (rad/s, 1σ); also enters the recorded RE = V/Ω.
    pub omega: f64,
    /// Loaded-radius (RL) noise (m, 1σ).
    pub radius: f64,
    /// Load-control wander of the true load (N, 1σ, slowly varying).
    pub fz_wander: f64,
    /// Constant Fy offset (N) added to the recorded values (offsets never
    /// reach the truth).
    pub fy_offset: f64,
    /// Constant Fx offset (N) added to the recorded values.
    pub fx_offset: f64,
    /// Constant Mz offset (N·m) added to the recorded values.
    pub mz_offset: f64,
    /// Constant slip-angle offset (ISO-W, rad) added to the recorded values.
    pub alpha_offset: f64,
}

impl Default for Noise {
    fn default() -> Self {
        Noise {
            fx: 12.0,
            fy: 12.0,
            fz: 10.0,
            mx: 0.5,
            mz: 0.4,
            alpha: 0.02f64.to_radians(),
            gamma: 0.01f64.to_radians(),
            p: 300.0,
            v: 0.02,
            omega: 0.02,
            radius: 2e-4,
            fz_wander: 15.0,
            fy_offset: 8.0,
            fx_offset: -5.0,
            mz_offset: 0.3,
            alpha_offset: 0.03f64.to_radians(),
        }
    }
}

impl Noise {
    /// No noise and no offsets.
    pub fn none() -> Noise {
        Noise {
            fx: 0.0,
            fy: 0.0,
            fz: 0.0,
            mx: 0.0,
            mz: 0.0,
            alpha: 0.0,
            gamma: 0.0,
            p: 0.0,
            v: 0.0,
            omega: 0.0,
            radius: 0.0,
            fz_wander: 0.0,
            fy_offset: 0.0,
            fx_offset: 0.0,
            mz_offset: 0.0,
            alpha_offset: 0.0,
        }
    }
}

/// Which TTC export layout to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TtcUnits {
    /// The SI export: s, kph, rpm, deg, N, N-m, kPa, cm, degC.
    Si,
    /// The US-customary export: s, mph, rpm, deg, lb, ft-lb, psi, in, degF.
    UsCustomary,
}

/// Rig configuration.
#[derive(Clone, Debug)]
pub struct RigConfig {
    /// The test programme to run.
    pub programme: Programme,
    /// Simulation rate (Hz).
    pub sample_rate: f64,
    /// Record every n-th simulated sample (1 = all).
    pub decimate: usize,
    /// Sensor noise and offsets of the recorded channels.
    pub noise: Noise,
    /// Seed of the ChaCha8 random source of the noise: equal seeds give identical runs.
    pub seed: u64,
    /// Which TTC export layout (SI or US customary) the table is written in.
    pub units: TtcUnits,
    /// Ambient temperature (°C).
    pub ambient: f64,
}

impl RigConfig {
    /// Standard programme for `tyre` at 100 Hz, default noise, SI export.
    pub fn standard(tyre: &Tyre, seed: u64) -> RigConfig {
        let p = &tyre.params().p;
        let fnom = if p.fnomin > 0.0 { p.fnomin } else { 4000.0 };
        let pnom = if p.nompres > 0.0 { p.nompres } else { 2e5 };
        RigConfig {
            programme: Programme::standard(fnom, pnom),
            sample_rate: 100.0,
            decimate: 1,
            noise: Noise::default(),
            seed,
            units: TtcUnits::Si,
            ambient: 25.0,
        }
    }
}

/// One step of the programme as run.
#[derive(Clone, Debug)]
enum Step {
    /// Move set points linearly, zero slip.
    Transition {
        from: SetPoint,
        to: SetPoint,
        dur: f64,
    },
    /// α through the turning points.
    Lateral {
        sp: SetPoint,
        points: Vec<f64>,
        rate: f64,
        warmup: bool,
    },
    /// κ sweep at a fixed α.
    DriveBrake { sp: SetPoint, amp: f64, rate: f64 },
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct SetPoint {
    fz: f64,
    gamma: f64,
    p: f64,
    alpha: f64,
    /// Belt speed (m/s).
    v: f64,
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Piecewise-linear path from 0 through `pts` back to 0 at `rate`: value at time t, total duration.
fn path(pts: &[f64], rate: f64, t: f64) -> (f64, f64) {
    let mut prev = 0.0;
    let mut t0 = 0.0;
    let mut total = 0.0;
    let mut val = None;
    for &p in pts.iter().chain(std::iter::once(&0.0)) {
        let d = (p - prev).abs() / rate;
        if val.is_none() && t <= t0 + d {
            val = Some(if d > 0.0 {
                lerp(prev, p, (t - t0) / d)
            } else {
                p
            });
        }
        t0 += d;
        total = t0;
        prev = p;
    }
    (val.unwrap_or(0.0), total)
}

/// The result of a simulated programme.
#[derive(Clone, Debug)]
pub struct RigRun {
    /// The recording in TTC layout (SAE signs, TTC units, noise and offsets).
    pub table: RawTable,
    /// Noise-free ISO-W SI truth of every recorded row (true inputs and forces).
    pub truth: Vec<Sample>,
    /// Loaded/effective radius truth per row (m).
    pub truth_re: Vec<f64>,
    /// The programme's segments (row indices into the recording as written),
    /// with their set points: what a reader should find.
    pub plan: Vec<Segment>,
    /// Rows recorded before the programme started (unloaded lead-in, load
    /// ramp and warm-up sweeps).
    pub warmup_rows: usize,
}

impl RigRun {
    /// Write the TTC `.mat` layout (zlib-compressed elements when `compress`).
    pub fn write_mat(&self, path: &Path, compress: bool) -> Result<()> {
        std::fs::write(path, crate::data::ttc::write_mat(&self.table, compress))
            .map_err(|e| Error::io(path, e))
    }
    /// Write the TTC `.dat` layout.
    pub fn write_dat(&self, path: &Path) -> Result<()> {
        std::fs::write(path, crate::data::ttc::write_dat(&self.table))
            .map_err(|e| Error::io(path, e))
    }
    /// Number of recorded rows.
    pub fn rows(&self) -> usize {
        self.truth.len()
    }
}

/// Standard normal deviate (Box–Muller).
fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.gen::<f64>().max(1e-300);
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Run the programme on the truth model.
pub fn simulate(cfg: &RigConfig, model: &mut dyn TruthModel) -> RigRun {
    let pr = &cfg.programme;
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    // Build the step list.
    let mut steps: Vec<Step> = Vec::new();
    let mut cur = SetPoint::default();
    let goto = |steps: &mut Vec<Step>, cur: &mut SetPoint, to: SetPoint, dur: f64| {
        steps.push(Step::Transition {
            from: *cur,
            to,
            dur,
        });
        *cur = to;
    };
    let first = SetPoint {
        fz: pr.loads.first().copied().unwrap_or(1000.0),
        gamma: pr.inclinations.first().copied().unwrap_or(0.0),
        p: pr.pressures.first().copied().unwrap_or(2e5),
        alpha: 0.0,
        v: pr.speed,
    };
    // Lead-in: tyre unloaded for 1 s, then loaded.
    cur.p = first.p;
    cur.gamma = first.gamma;
    cur.v = pr.speed;
    steps.push(Step::Transition {
        from: cur,
        to: cur,
        dur: 1.0,
    });
    let wsp = SetPoint {
        fz: pr.warmup.as_ref().and_then(|w| w.fz).unwrap_or(first.fz),
        ..first
    };
    goto(&mut steps, &mut cur, wsp, 2.0);
    if let Some(w) = &pr.warmup {
        steps.push(Step::Lateral {
            sp: wsp,
            points: w.points.clone(),
            rate: w.rate,
            warmup: true,
        });
    }
    let warmup_steps = steps.len();
    for &p in &pr.pressures {
        for &g in &pr.inclinations {
            for &fz in &pr.loads {
                let sp = SetPoint {
                    fz,
                    gamma: g,
                    p,
                    alpha: 0.0,
                    v: pr.speed,
                };
                if sp != cur {
                    goto(&mut steps, &mut cur, sp, pr.transition);
                }
                steps.push(Step::Lateral {
                    sp,
                    points: pr.lateral_points.clone(),
                    rate: pr.alpha_rate,
                    warmup: false,
                });
            }
        }
    }
    let db_speeds = if pr.db_speeds.is_empty() {
        std::slice::from_ref(&pr.speed)
    } else {
        &pr.db_speeds[..]
    };
    for &p in &pr.pressures {
        for &g in &pr.db_inclinations {
            for &a in &pr.db_alphas {
                for &v in db_speeds {
                    for &fz in &pr.loads {
                        let sp = SetPoint {
                            fz,
                            gamma: g,
                            p,
                            alpha: a,
                            v,
                        };
                        goto(&mut steps, &mut cur, sp, pr.transition);
                        steps.push(Step::DriveBrake {
                            sp,
                            amp: pr.db_kappa,
                            rate: pr.kappa_rate,
                        });
                    }
                }
            }
        }
    }
    let unload = SetPoint { fz: 0.0, ..cur };
    goto(&mut steps, &mut cur, unload, pr.transition);

    let dt = 1.0 / cfg.sample_rate.max(1e-3);
    let dec = cfg.decimate.max(1);
    let nz = &cfg.noise;
    let us = cfg.units == TtcUnits::UsCustomary;
    // Column buffers in TTC order.
    const NAMES: [&str; 23] = [
        "ET", "V", "N", "SA", "IA", "RL", "RE", "P", "FX", "FY", "FZ", "MX", "MZ", "NFX", "NFY",
        "RST", "TSTI", "TSTC", "TSTO", "AMBTMP", "SR", "SL", "RUN",
    ];
    let units: [&str; 23] = if us {
        [
            "s", "mph", "rpm", "deg", "deg", "in", "in", "psi", "lb", "lb", "lb", "ft-lb", "ft-lb",
            "-", "-", "degF", "degF", "degF", "degF", "degF", "-", "-", "-",
        ]
    } else {
        [
            "s", "kph", "rpm", "deg", "deg", "cm", "cm", "kPa", "N", "N", "N", "N-m", "N-m", "-",
            "-", "degC", "degC", "degC", "degC", "degC", "-", "-", "-",
        ]
    };
    let (k_v, k_len, k_p, k_f, k_m) = if us {
        (
            1.0 / 0.447_04,
            1.0 / 0.0254,
            1.0 / 6_894.757_293,
            1.0 / 4.448_221_615_260_5,
            1.0 / 1.355_817_948_331_4,
        )
    } else {
        (3.6, 100.0, 1e-3, 1.0, 1.0)
    };
    let temp = |c: f64| if us { c * 9.0 / 5.0 + 32.0 } else { c };
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); NAMES.len()];
    let mut truth = Vec::new();
    let mut truth_re = Vec::new();
    let mut plan: Vec<Segment> = Vec::new();
    let mut warmup_rows = 0usize;
    let mut t = 0.0;
    let mut k = 0usize;
    let mut wander = 0.0;
    let mut last_t = f64::NAN;
    model.reset();
    let mut last_re: f64 = 0.3;
    for (si, step) in steps.iter().enumerate() {
        let dur = match step {
            Step::Transition { dur, .. } => *dur,
            Step::Lateral { points, rate, .. } => path(points, *rate, 0.0).1,
            Step::DriveBrake { amp, rate, .. } => path(&[*amp, -*amp], *rate, 0.0).1,
        };
        let row0 = truth.len();
        let n = (dur / dt).round() as usize;
        for j in 0..n {
            let tl = j as f64 * dt;
            let (sp, alpha, kappa) = match step {
                Step::Transition { from, to, dur } => {
                    let s = if *dur > 0.0 { tl / dur } else { 1.0 };
                    (
                        SetPoint {
                            fz: lerp(from.fz, to.fz, s),
                            gamma: lerp(from.gamma, to.gamma, s),
                            p: lerp(from.p, to.p, s),
                            alpha: lerp(from.alpha, to.alpha, s),
                            v: lerp(from.v, to.v, s),
                        },
                        lerp(from.alpha, to.alpha, s),
                        0.0,
                    )
                }
                Step::Lateral {
                    sp, points, rate, ..
                } => (*sp, path(points, *rate, tl).0, 0.0),
                Step::DriveBrake { sp, amp, rate } => {
                    (*sp, sp.alpha, path(&[*amp, -*amp], *rate, tl).0)
                }
            };
            // Slow load-control wander (first-order filtered noise, τ ≈ 1 s).
            wander +=
                (gauss(&mut rng) * nz.fz_wander * (2.0 * dt).sqrt() - wander * dt).clamp(-1e3, 1e3);
            let fz = if sp.fz > 0.0 {
                (sp.fz + wander).max(0.0)
            } else {
                0.0
            };
            let v = sp.v;
            let vx = v * alpha.cos();
            let mut inp = RigInput {
                time: t,
                mf: MfInput {
                    fz,
                    kappa,
                    alpha,
                    gamma: sp.gamma,
                    phit: 0.0,
                    vx,
                    p: sp.p,
                    omega: 0.0,
                },
                v_belt: v,
                step: si,
            };
            // Ω = (1 + κ)·Vx/Re with the model's Re of the previous sample
            // (Re moves by micrometres per step), so the model is called once.
            inp.mf.omega = (1.0 + kappa) * vx / last_re.max(1e-3);
            let dtm = if last_t.is_nan() { 0.0 } else { t - last_t };
            let mut out = model.sample(&inp, dtm);
            if fz <= 0.0 {
                out.forces = Forces::default();
            }
            if out.re.is_finite() && out.re > 0.0 {
                last_re = out.re;
            }
            last_t = t;
            if k.is_multiple_of(dec) {
                let f = out.forces;
                let iso = AxisSample {
                    fx: f.fx + nz.fx_offset + nz.fx * gauss(&mut rng),
                    fy: f.fy + nz.fy_offset + nz.fy * gauss(&mut rng),
                    fz: fz + nz.fz * gauss(&mut rng),
                    mx: f.mx + nz.mx * gauss(&mut rng),
                    my: f.my,
                    mz: f.mz + nz.mz_offset + nz.mz * gauss(&mut rng),
                    alpha: alpha + nz.alpha_offset + nz.alpha * gauss(&mut rng),
                    gamma: sp.gamma + nz.gamma * gauss(&mut rng),
                    kappa,
                    phit: 0.0,
                    rl: out.rl,
                };
                let sae = from_iso(AxisSystem::Sae, &iso);
                let omega_m = inp.mf.omega + nz.omega * gauss(&mut rng);
                let v_m = v + nz.v * gauss(&mut rng);
                let rpm = omega_m * 60.0 / std::f64::consts::TAU;
                // Calspan reports RE as V/Ω: exact only while rolling freely.
                let re_rec = if omega_m.abs() > 1e-6 {
                    v_m / omega_m
                } else {
                    f64::NAN
                };
                let rl_rec = out.rl + nz.radius * gauss(&mut rng);
                let fzs = sae.fz.abs().max(1.0);
                let tt = if out.tread_temp.is_finite() {
                    out.tread_temp
                } else {
                    cfg.ambient + 5.0
                };
                let row = [
                    t,
                    v_m * k_v,
                    rpm,
                    sae.alpha.to_degrees(),
                    sae.gamma.to_degrees(),
                    rl_rec * k_len,
                    re_rec * k_len,
                    (sp.p + nz.p * gauss(&mut rng)) * k_p,
                    sae.fx * k_f,
                    sae.fy * k_f,
                    sae.fz * k_f,
                    sae.mx * k_m,
                    sae.mz * k_m,
                    sae.fx / fzs,
                    sae.fy / fzs,
                    temp(cfg.ambient + 3.0),
                    temp(tt + 0.3 * gauss(&mut rng)),
                    temp(tt + 0.3 * gauss(&mut rng)),
                    temp(tt + 0.3 * gauss(&mut rng)),
                    temp(cfg.ambient),
                    kappa,
                    omega_m * rl_rec / (v_m * alpha.cos()) - 1.0,
                    1.0,
                ];
                for (c, x) in cols.iter_mut().zip(row) {
                    c.push(x);
                }
                truth.push(Sample {
                    time: t,
                    vx,
                    omega: inp.mf.omega,
                    fz,
                    kappa,
                    alpha,
                    gamma: sp.gamma,
                    phit: 0.0,
                    p: sp.p,
                    fx: f.fx,
                    fy: f.fy,
                    mx: f.mx,
                    my: f.my,
                    mz: f.mz,
                });
                truth_re.push(out.re);
            }
            k += 1;
            t += dt;
        }
        let row1 = truth.len();
        if si + 1 == warmup_steps {
            warmup_rows = row1;
        }
        match step {
            Step::Lateral {
                sp, warmup: false, ..
            }
            | Step::DriveBrake { sp, .. }
                if row1 > row0 =>
            {
                let kind = match step {
                    Step::Lateral { .. } => SegmentKind::PureLateral,
                    _ if sp.alpha == 0.0 => SegmentKind::PureLongitudinal,
                    _ => SegmentKind::Combined,
                };
                plan.push(Segment {
                    start: row0,
                    end: row1,
                    kind,
                    fz: sp.fz,
                    gamma: sp.gamma,
                    p: sp.p,
                    vx: sp.v,
                    alpha: if kind == SegmentKind::PureLateral {
                        f64::NAN
                    } else {
                        sp.alpha
                    },
                });
            }
            _ => {}
        }
    }
    let mut table = RawTable {
        columns: NAMES
            .iter()
            .zip(units)
            .zip(cols)
            .map(|((n, u), data)| RawColumn {
                name: n.to_string(),
                unit: Some(u.to_string()),
                data,
            })
            .collect(),
        meta: vec![],
        axes: Some(AxisSystem::Sae),
    };
    table.meta.push((
        "source".into(),
        format!(
            "tyrekit rig simulator: {}, seed {}",
            model.describe(),
            cfg.seed
        ),
    ));
    table.meta.push(("testid".into(), "rig-standard".into()));
    table.meta.push(("tireid".into(), model.describe()));
    RigRun {
        table,
        truth,
        truth_re,
        plan,
        warmup_rows,
    }
}
