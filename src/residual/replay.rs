//! replay — a recording's measured inputs (ISO-W, SI) stepped through
//! [`TransientModel::step`], the code the FMU runs, on the recording's own
//! time base.
//!
//! # Time base and resets
//! * The step of sample `i` is `dt = t[i] − t[i−1]`; the inputs of sample
//!   `i` are held over that step (zero-order hold towards the sample, the
//!   FMU's co-simulation convention) and the outputs at its end are compared
//!   with sample `i`.
//! * The model state is reset to rest at the first sample and at every
//!   **gap**: a non-finite or non-positive time step, or one longer than
//!   [`ReplayOptions::gap_factor`] times the median sample spacing (the
//!   warm-up cut, concatenated files, dropped rows). A continuous recording
//!   is *not* reset at segment starts: the rig runs through its transitions
//!   without stopping, so the tyre's state carries over physically. At a
//!   gap whose time runs forward (or stands: a repeated time stamp) the
//!   tread temperature of a `[THERMAL]` tyre carries over, cooled over the gap
//!   ([`TransientModel::reset_after_gap`]): a logger drop-out of a fraction
//!   of a second does not cool a tyre whose time constant is minutes, and
//!   a reset to ambient at each one would make a thermal model fail on any
//!   recording with drop-outs.
//! * After a reset, the state is **settled** on the first sample of the run:
//!   one step of [`ReplayOptions::settle_time`] with that sample's inputs
//!   held (the transient models integrate exactly, so this is the steady
//!   state of those inputs). A run that starts mid-sweep thus starts at
//!   equilibrium, not at an artificial zero deflection.
//! * A sample whose core inputs (Vx, Fz, α) are missing or refused by the
//!   model gets NaN outputs and ends its run (the next good sample starts a
//!   new one). Missing optional inputs as in [`super::input`].
//!
//! By default slips are prescribed ([`InputMode::Slips`]): rigs impose κ
//! and α and record them (the diagnosis scores its candidates so).
//! With [`ReplayOptions::wheel_speed`] and a recording that has the wheel
//! speed Ω, the model runs as the FMU is used by default
//! ([`InputMode::Velocities`]): κ = (Ω·Re(Fz) − Vx)/|Vx| with the tyre's
//! own effective rolling radius (so a rolling-radius finding changes the
//! replay), α from Vy = tan α·|Vx|; without Ω the slips stay prescribed.
//! Where the loader took κ from the rig's slip ratio SR, Ω is the wheel
//! speed that slip implies with the rig's radius, Vx·(1 + SR)/R_SR
//! ([`crate::data::slip::SLIP_RADIUS_CHANNEL`]), so the replay's κ is
//! (1 + SR)·Re(Fz)/R_SR − 1: SR where the file's radius is the rig's.
//!
//! Must never: allocate per sample beyond the output vectors, or carry a
//! slip, turn-slip or bristle state across a gap.

use super::input::wheel_input;
use crate::data::Recording;
use crate::error::Result;
use crate::mf::{Forces, Tyre, UseMode};
use crate::transient::{
    InputMode, TransientConfig, TransientKind, TransientModel, TransientOptions, WheelOutput,
};
use std::io::Write;

/// How to replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReplayOptions {
    /// Transient model stepped through the recording (default: steady-state MF).
    pub kind: TransientKind,
    /// MFeval-style use mode: limit checks, α* definition, turn slip.
    pub use_mode: UseMode,
    /// Relaxation variant and LuGre parameters of the transient model.
    pub options: TransientOptions,
    /// A step longer than this many median spacings is a gap (reset).
    pub gap_factor: f64,
    /// Duration (s) of the settling step after a reset (0: start at rest).
    pub settle_time: f64,
    /// Take κ from the recorded wheel speed and the tyre's Re(Fz) (the
    /// FMU's velocities input) when the recording has Ω (see the module docs).
    pub wheel_speed: bool,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            kind: TransientKind::Steady,
            use_mode: UseMode::default(),
            options: TransientOptions::default(),
            gap_factor: 5.0,
            settle_time: 5.0,
            wheel_speed: false,
        }
    }
}

/// The replay of one recording: one output per sample (NaN where the sample
/// could not be replayed) and the runs between resets.
#[derive(Clone, Debug, Default)]
pub struct Replay {
    /// Simulated forces and moments (ISO-W; N, N·m), one per sample.
    pub sim: Vec<Forces>,
    /// Full step outputs (slips used, μ, slip speeds …), one per sample.
    pub out: Vec<WheelOutput>,
    /// Half-open sample ranges replayed without a reset.
    pub runs: Vec<(usize, usize)>,
    /// Samples that could not be replayed.
    pub skipped: usize,
}

/// Median of the positive finite time steps (NaN when there are none).
pub fn median_spacing(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    if d.is_empty() {
        return f64::NAN;
    }
    let m = d.len() / 2;
    *d.select_nth_unstable_by(m, f64::total_cmp).1
}

/// The input mode a replay of `rec` runs with (see the module docs).
pub fn input_mode(rec: &Recording, opts: &ReplayOptions) -> InputMode {
    if opts.wheel_speed && rec.has("omega") {
        InputMode::Velocities
    } else {
        InputMode::Slips
    }
}

/// Replay `rec` through `tyre` (see the module docs for time base and resets).
pub fn replay(rec: &Recording, tyre: &Tyre, opts: &ReplayOptions) -> Result<Replay> {
    let n = rec.samples.len();
    let t: Vec<f64> = rec.samples.iter().map(|s| s.time).collect();
    let h = median_spacing(&t);
    let max_dt = if h.is_finite() {
        h * opts.gap_factor.max(1.0)
    } else {
        f64::INFINITY
    };
    let mut model = TransientModel::with_options(
        TransientConfig {
            kind: opts.kind,
            input_mode: input_mode(rec, opts),
            use_mode: opts.use_mode,
        },
        opts.options,
    );
    let nan = Forces {
        fx: f64::NAN,
        fy: f64::NAN,
        mx: f64::NAN,
        my: f64::NAN,
        mz: f64::NAN,
    };
    let mut r = Replay {
        sim: Vec::with_capacity(n),
        out: Vec::with_capacity(n),
        runs: Vec::new(),
        skipped: 0,
    };
    let slip_radius = rec
        .extra(crate::data::slip::SLIP_RADIUS_CHANNEL)
        .filter(|r| r.len() == n);
    let mut run_start: Option<usize> = None;
    // Time the model's state stands at (a restart cools from there).
    let mut state_time: Option<f64> = None;
    for (i, s) in rec.samples.iter().enumerate() {
        let dt = if i > 0 { t[i] - t[i - 1] } else { f64::NAN };
        let gap = !(dt.is_finite() && dt > 0.0 && dt <= max_dt);
        if gap || run_start.is_none() {
            if let Some(a) = run_start.take() {
                r.runs.push((a, i));
            }
        }
        let o = wheel_input(tyre, s, slip_radius.map(|r| r[i])).and_then(|inp| {
            if run_start.is_none() {
                match state_time {
                    Some(t0) => model.reset_after_gap(tyre, t[i] - t0),
                    None => model.reset(),
                }
                // The state now stands at this sample's time, taken or not.
                state_time = Some(t[i]);
                let settle = opts.settle_time.max(0.0);
                model.step(tyre, &inp, settle).ok()
            } else {
                model.step(tyre, &inp, dt).ok()
            }
        });
        match o {
            Some(o) => {
                if run_start.is_none() {
                    run_start = Some(i);
                }
                state_time = Some(t[i]);
                r.sim.push(Forces {
                    fx: o.fx,
                    fy: o.fy,
                    mx: o.mx,
                    my: o.my,
                    mz: o.mz,
                });
                r.out.push(o);
            }
            None => {
                if let Some(a) = run_start.take() {
                    r.runs.push((a, i));
                }
                r.skipped += 1;
                r.sim.push(nan);
                r.out.push(WheelOutput {
                    fx: f64::NAN,
                    fy: f64::NAN,
                    mx: f64::NAN,
                    my: f64::NAN,
                    mz: f64::NAN,
                    ..Default::default()
                });
            }
        }
    }
    if let Some(a) = run_start {
        r.runs.push((a, n));
    }
    Ok(r)
}

/// Write the replay CSV: `time,Fx,Fy,Mz,Fx_sim,Fy_sim,Mz_sim`, then
/// `Mx,My,Mx_sim,My_sim` when the recording has Mx / My (ISO-W, SI).
pub fn write_csv(rec: &Recording, rp: &Replay, w: impl std::io::Write) -> std::io::Result<()> {
    let has_mx = rec.has("Mx");
    let has_my = rec.has("My");
    let mut w = std::io::BufWriter::new(w);
    write!(w, "time,Fx,Fy,Mz,Fx_sim,Fy_sim,Mz_sim")?;
    if has_mx {
        write!(w, ",Mx")?;
    }
    if has_my {
        write!(w, ",My")?;
    }
    if has_mx {
        write!(w, ",Mx_sim")?;
    }
    if has_my {
        write!(w, ",My_sim")?;
    }
    writeln!(w)?;
    for (s, f) in rec.samples.iter().zip(&rp.sim) {
        write!(
            w,
            "{},{},{},{},{},{},{}",
            s.time, s.fx, s.fy, s.mz, f.fx, f.fy, f.mz
        )?;
        if has_mx {
            write!(w, ",{}", s.mx)?;
        }
        if has_my {
            write!(w, ",{}", s.my)?;
        }
        if has_mx {
            write!(w, ",{}", f.mx)?;
        }
        if has_my {
            write!(w, ",{}", f.my)?;
        }
        writeln!(w)?;
    }
    w.flush()
}
