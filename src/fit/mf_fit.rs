//! mf_fit — the staged Magic Formula fit of recordings: nominal values from
//! the data, pure Fx → pure Fy → Mz → combined ([`super::mf_stages`]), each
//! stage starting from the values of the stages before it, then the quality
//! metrics on the fitted and the held-out samples. Data without cornering
//! sweeps (a drive/brake run) give the pure Fy stage the drive/brake rows
//! near free rolling, and the combined stage fits Mz only where a stage
//! fitted its pure-slip shape.
//!
//! Must never: change a parameter no stage fitted (the start tyre's values
//! pass through untouched, scaling factors included), print, or panic on
//! user data.

use super::holdout::Holdout;
use super::metrics::{self, ChannelMetric};
use super::mf_stages::{
    conditions_of, fit_stage, gather, neutral_start, stage_params, Channel, StageData, StageKind,
    CAMBER_SPREAD, PRESSURE_SPREAD,
};
use super::report::FitReport;
use super::solve::{FitOptions, ProgressFn};
use super::validity::Grid;
use crate::data::{Recording, SegmentKind};
use crate::mf::{form_of, Model};
use crate::stats::median;
use crate::tir::TyreParams;
use std::ops::Range;

mod gate;

/// Settings of [`fit_mf`].
#[derive(Clone, Debug)]
pub struct MfFitOptions {
    /// Stages to run (in the fixed order Fx, Fy, Mz, combined, Mx, My; a
    /// stage whose channel the data lack is skipped and reported).
    pub only: Vec<StageKind>,
    /// Then fit the relaxation lengths ([`super::transient`]; replays, so
    /// off by default).
    pub transient: bool,
    /// Which samples to hold out of the fit and judge it on (`--holdout`).
    pub holdout: Holdout,
    /// Per recording (same order): the time its first row was recorded,
    /// before a warm-up cut — the origin of `--holdout tail:F`'s time
    /// fraction. Empty or `None`: the first kept sample's time.
    pub t_origins: Vec<Option<f64>>,
    /// Take FNOMIN, NOMPRES (and INFLPRES), LONGVL from the data.
    pub nominal_from_data: bool,
    /// The start tyre is a generic one (the built-in), not a file of the
    /// tyre under test: coefficients the data cannot determine and that
    /// have a neutral value are held at it rather than at another tyre's
    /// (`NEUTRAL_SLIP_ANGLE_SHAPE`). `tyrekit fit --start` turns it off.
    pub generic_start: bool,
    /// Fit the radii and vertical stiffness keys to the recorded Re and Rl
    /// before the force stages ([`super::geometry`]; R0 enters the Mz, Mx,
    /// My equations). Off by default (the diagnosis baseline holds Re terms
    /// for its rolling-radius candidate); `tyrekit fit` turns it on.
    pub geometry: bool,
    /// Recordings the geometry step reads instead of the fitted ones (the
    /// same samples with other force values). The diagnosis fits its
    /// baseline again without the sensor zeros
    /// ([`crate::diagnose::sensor_zero`]) and keeps the geometry of the
    /// recording as measured: the free-rolling selection reads Fx, so a
    /// shifted Fx would pick other samples and another Re(Fz). `None`: the
    /// fitted ones.
    pub geometry_recordings: Option<std::sync::Arc<Vec<Recording>>>,
    /// Threads the residuals and Jacobians are evaluated on (results do not
    /// depend on it); default: the available parallelism.
    pub threads: usize,
    /// Settings of every stage's fit (LM, swarm, identifiability, holds);
    /// the default uses the staged tolerances [`STAGED_FTOL`],
    /// [`STAGED_DCHI2`], [`STAGED_STALL`] and a coarse-first polish.
    pub fit: FitOptions,
    /// Minimum samples for a stage to run.
    pub min_samples: usize,
    /// Hold the pressure terms (PPX*, PPY*, PPZ*, PPMX1) at the start's
    /// values whatever pressures the data hold. Off: they are fitted when
    /// the data span more than [`PRESSURE_SPREAD`]. The diagnosis fits its
    /// baseline beneath a named pressure law with them held
    /// ([`crate::diagnose::reestimate`]).
    pub hold_pressure: bool,
}

impl Default for MfFitOptions {
    fn default() -> Self {
        MfFitOptions {
            only: StageKind::ALL.to_vec(),
            transient: false,
            holdout: Holdout::None,
            t_origins: Vec::new(),
            nominal_from_data: true,
            generic_start: true,
            geometry: false,
            geometry_recordings: None,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            fit: FitOptions {
                coarse_first: true,
                lm: crate::fit::LmOptions {
                    ftol: STAGED_FTOL,
                    dchi2: STAGED_DCHI2,
                    stall: Some(STAGED_STALL),
                    ..Default::default()
                },
                ..Default::default()
            },
            min_samples: 50,
            hold_pressure: false,
        }
    }
}

/// The LM's relative cost tolerance of the staged fit (`ftol`, see
/// [`crate::fit::LmOptions`]): a nearly undamped step that predicts less
/// than 1e-9 of the cost ends the polish. Measured on the dev set (r05,
/// combined stage, 167 232 residuals): the last 12 of 30 full-data
/// iterations at the library default 1e-12 lowered the cost by 1.2e-8 of
/// it (the fitted and held-out figures agree to 6 significant digits) and took 40 % of the stage's
/// time; SciPy's `least_squares` stops at ftol = 1e-8.
pub const STAGED_FTOL: f64 = 1e-9;

/// The staged fit's χ² tolerance ([`crate::fit::LmOptions::dchi2`]): a
/// step that changes χ² by less than 0.001 moves the parameters by less
/// than 3 % of a standard error. Measured on the dev set (`tests/devset_fit`):
/// on r05 the Mx stage's valley crawl (187 full-data iterations, 5.0 of the
/// fit's 11 s) ends after 2.6 s; with 0.01 it ended after 0.8 s, but along
/// the collinear valleys of pure Fy (PKY2/PKY4/PKY5) those last small steps
/// still moved the held-out figures: r03, r08, r21 pure Fy 3 % worse. At
/// 0.001 every figure of those recordings is as without the rule.
pub const STAGED_DCHI2: f64 = 1e-3;

/// The staged fit's stall rule ([`crate::fit::LmOptions::stall`]): stop
/// when 10 accepted steps together lowered the cost by less than 1e-4 of
/// it — at that rate a further 100 steps would lower the RMS residual by
/// under 0.05 %, below the last digit of every printed figure. What it
/// stops: the full-data polishes that creep after a converged subsample
/// (benchmark rig recording, combined stage: 53 iterations for 1.2e-4 of
/// the cost, 147 of 170 s; dev-set r16 combined: 36 for 1.6e-5) and the
/// Mx valley walks (dev-set r09: 865 linearisations, 39 s).
pub const STAGED_STALL: (usize, f64) = (10, 1e-4);

/// Sample ranges of one recording: (fitted, held out).
pub type TrainTest = (Vec<Range<usize>>, Vec<Range<usize>>);

/// Result of [`fit_mf`].
pub struct MfFit {
    /// The fitted tyre property file (start file with the fitted keys set).
    pub tyre: TyreParams,
    /// Per-stage outcomes and figures, as written to `fit.json`.
    pub report: FitReport,
    /// Stages skipped and why.
    pub skipped: Vec<String>,
    /// Which candidate of a gated stage was kept and the figures that decided
    /// it (`gate`).
    pub decisions: Vec<String>,
    /// Per recording: the (train, held-out) sample ranges.
    pub splits: Vec<TrainTest>,
    /// The geometry fit, when [`MfFitOptions::geometry`] asked for it.
    pub geometry: Option<super::geometry::Geometry>,
}

/// Nominal values from the data: FNOMIN = median of the segments' load set
/// points, NOMPRES = INFLPRES = median pressure, LONGVL = median speed.
pub fn nominal_from_data(tyre: &mut TyreParams, recs: &[Recording]) -> crate::Result<()> {
    let loads: Vec<f64> = recs
        .iter()
        .flat_map(|r| r.segments.iter().map(|s| s.fz))
        .filter(|f| *f > 0.0)
        .collect();
    let all = |f: fn(&crate::data::Sample) -> f64| -> Vec<f64> {
        recs.iter()
            .flat_map(|r| r.samples.iter().step_by(10).map(f))
            .collect()
    };
    if let Some(f) = median(loads).or_else(|| median(all(|s| s.fz))) {
        tyre.set("FNOMIN", f)?;
    }
    if let Some(p) = median(all(|s| s.p)).filter(|p| *p > 10_000.0) {
        tyre.set("NOMPRES", p)?;
        tyre.set("INFLPRES", p)?;
    }
    if let Some(v) = median(all(|s| s.vx.abs())).filter(|v| *v > 0.5) {
        tyre.set("LONGVL", v)?;
    }
    Ok(())
}

/// Widen the range limits of the file (FZMIN/FZMAX, ALPMIN/ALPMAX,
/// KPUMIN/KPUMAX, CAMMIN/CAMMAX, PRESMIN/PRESMAX) so they contain the data
/// with a margin of 20 % of the limit's magnitude: a fitted tyre must not
/// clip the conditions it was fitted on (the FMU's use modes 1xx clip
/// inputs to these ranges). FZMIN is never lowered: below it the moment
/// equations reduce the load (Fz·(Fz/FZMIN)², `Model::mx`), so it is a
/// model parameter rather than a validity limit. A limit the data lie
/// inside stays as it was.
pub fn widen_ranges(tyre: &mut TyreParams, recs: &[Recording]) -> crate::Result<()> {
    type Get = fn(&crate::data::Sample) -> f64;
    const PAD: f64 = 0.2;
    for (lo_k, hi_k, f) in [
        ("FZMIN", "FZMAX", (|s| s.fz) as Get),
        ("ALPMIN", "ALPMAX", |s| s.alpha),
        ("KPUMIN", "KPUMAX", |s| s.kappa),
        ("CAMMIN", "CAMMAX", |s| s.gamma),
        // A pressure of 0 means "not measured" (as NaN does).
        (
            "PRESMIN",
            "PRESMAX",
            |s| if s.p > 0.0 { s.p } else { f64::NAN },
        ),
    ] {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in recs.iter().flat_map(|r| &r.samples).map(f) {
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            continue;
        }
        if let (Some(a), Some(b)) = (tyre.get(lo_k), tyre.get(hi_k)) {
            if lo_k != "FZMIN" && lo < a {
                tyre.set(lo_k, lo - PAD * lo.abs())?;
            }
            if hi > b {
                tyre.set(hi_k, hi + PAD * hi.abs())?;
            }
        }
    }
    Ok(())
}

/// The range of load, inclination and pressure of every loaded sample of
/// `recs`: where a fitted tyre must be valid ([`super::validity`]).
pub fn data_grid(recs: &[Recording]) -> Grid {
    let span = |f: &dyn Fn(&crate::data::Sample) -> f64| {
        recs.iter()
            .flat_map(|r| &r.samples)
            .filter(|s| s.fz > 0.0)
            .map(f)
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    Grid::spanning(
        span(&|s| s.fz),
        span(&|s| s.gamma),
        span(&|s| if s.p > 0.0 { s.p } else { f64::NAN }),
    )
}

/// Check the hold list of `opts` against the coefficients the stages fit:
/// an unknown name is an error naming it (a typo must not silently fit
/// the coefficient it meant to hold).
fn check_hold(hold: &[String]) -> crate::Result<()> {
    for h in hold {
        let known = StageKind::ALL
            .iter()
            .any(|k| k.table().iter().any(|e| e.0.eq_ignore_ascii_case(h.trim())));
        if !known {
            let why = if crate::tir::keys::key_index(h.trim()).is_some() {
                "a .tir key that no fit stage fits"
            } else {
                "not a .tir key"
            };
            return Err(crate::Error::Input(format!(
                "fit --hold '{h}': {why} (expected coefficients of the Fx, Fy, Mz, combined, Mx or My stages, e.g. PDY1)"
            )));
        }
    }
    Ok(())
}

/// Sample ranges of `kinds` segments intersected with `keep`.
fn segment_ranges(
    rec: &Recording,
    kinds: &[crate::data::SegmentKind],
    keep: &[Range<usize>],
) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    for seg in rec.segments.iter().filter(|s| kinds.contains(&s.kind)) {
        for k in keep {
            let (a, b) = (seg.start.max(k.start), seg.end.min(k.end));
            if a < b {
                out.push(a..b);
            }
        }
    }
    out
}

/// What every stage of one [`fit_mf`] call shares.
pub(crate) struct StageCtx<'a> {
    pub recs: &'a [Recording],
    /// Per recording: the fitted sample ranges.
    pub train: &'a [Vec<Range<usize>>],
    pub grid: &'a Grid,
    pub opts: &'a MfFitOptions,
    pub form: crate::mf::Form,
}

/// A stage's outcome: skipped (why), or fitted with the channels it fitted
/// and the kind of segment whose rows it fitted them on (the pure Fy stage
/// of data without cornering sweeps fits the drive/brake rows near free
/// rolling, [`near_free_rolling`]), with a line saying so when it did.
pub(crate) enum StageRun {
    Skipped(String),
    Done {
        out: super::solve::FitOutcome,
        channels: Vec<Channel>,
        rows: SegmentKind,
        note: Option<String>,
    },
}

/// |κ| below which a drive/brake sample stands in for free rolling when the
/// data hold no cornering sweeps (the pure Fy stage's rows then). At
/// κ = 0.02 the combined weight Gyκ = cos(Cyκ·atan(Byκ·κ)) of a typical tyre (Byκ ≈ 10,
/// Cyκ ≈ 1, Pacejka, *Tyre and Vehicle Dynamics*, eq. 4.E62) is 0.98, and
/// the model evaluates it anyway: the rows read Fy0(α) to within what the
/// combined stage then fits.
pub const FREE_ROLLING_KAPPA: f64 = 0.02;

/// Whether the cornering sweeps hold enough Mz samples (`min_samples`) for
/// the Mz stage to fit its pure-slip shape: only then does Mz join the
/// combined stage. Without them the trail is the start tyre's, evaluated
/// under braking at an equivalent slip √(α² + (Kx/Ky·κ)²) (Pacejka, *Tyre
/// and Vehicle Dynamics*, eq. 4.E78) far beyond what the data show; fitted
/// together with Fy, the combined weights then bent Fy to take up the
/// moment's misfit (the dev set's r04 cut to its drive/brake rows: the
/// fitted Fy at α = 3°, κ = −0.19 fell to 3 % of its free-rolling value
/// where the measured one keeps 89 %; with the generating file's
/// combined-slip coefficients the same tyre fits Fy to 29 N RMS, the
/// noise, against the fit's 218 N).
fn mz_shape_fitted(ctx: &StageCtx, tyre: &TyreParams) -> bool {
    let (seg, chans) = StageKind::Mz.segments_and_channels();
    gather(&tyre.p, ctx.recs, Some(ctx.train), seg, chans)
        .conds
        .len()
        >= ctx.opts.min_samples
}

/// Pure Fy coefficients held when the stage fits the rows
/// [`near_free_rolling`]: the shape factor PCY1 and the curvature PEY1–3
/// (eqs. 4.E21, 4.E24) act where Fy bends towards its peak, which slip
/// angles of 3–6° barely reach; PKY4 bends the cornering stiffness over
/// load (4.E25), which a few loads on one slip-angle level cannot tell from
/// PKY1–2; PVY1–2 (4.E29) trade with the horizontal shift PHY1–2 when the
/// slip angles have one sign (a TTC drive/brake run's 0, −3, −6°): fitted
/// freely, the first such fit moved PVY1 to its bound −0.5 and PKY1 to 2–9×
/// the generating file's, a curve that fits three slip angles and nothing
/// else. The peak and stiffness levels and their load trends (PDY1–2,
/// PKY1–2) and the offsets PHY1–2 stay fitted.
const FREE_ROLLING_HELD: [&str; 7] = ["pcy1", "pey1", "pey2", "pey3", "pky4", "pvy1", "pvy2"];

/// The rows the pure Fy stage fits when the data hold no cornering sweeps:
/// the drive/brake rows at a slip angle (combined segments) with
/// |κ| < [`FREE_ROLLING_KAPPA`], and the upright ones at α ≈ 0 (pure
/// longitudinal segments) for the offsets. A TTC drive/brake run holds
/// blocks at SA 0, −3 and −6° and no sweep of α: without these rows the
/// stage was skipped and Fy0 stayed the start tyre's (the dev set cut to
/// its drive/brake rows: Fy at 17× the noise floor, a force scale error of
/// +32–37 % that the combined weights could not take up), with
/// [`FREE_ROLLING_HELD`] held. Mz gets no such stand-in: its trail is
/// evaluated at the equivalent slip √(α² + (Kx/Ky·κ)²) (eq. 4.E78), far
/// beyond 6° under braking, so a shape read at two slip angles would be
/// extrapolated — see [`mz_shape_fitted`]. `None`: another stage, or
/// fewer than `min_samples` such rows at a slip angle.
fn near_free_rolling(
    kind: StageKind,
    ctx: &StageCtx,
    tyre: &TyreParams,
    channels: &[Channel],
) -> Option<StageData> {
    if kind != StageKind::PureFy {
        return None;
    }
    let free = |d: &mut StageData| d.retain(|c| c.kappa.abs() < FREE_ROLLING_KAPPA);
    let mut data = gather(
        &tyre.p,
        ctx.recs,
        Some(ctx.train),
        SegmentKind::Combined,
        channels,
    );
    free(&mut data);
    if data.conds.len() < ctx.opts.min_samples {
        return None;
    }
    let mut upright = gather(
        &tyre.p,
        ctx.recs,
        Some(ctx.train),
        SegmentKind::PureLongitudinal,
        channels,
    );
    free(&mut upright);
    data.append(upright);
    Some(data)
}

/// Combined-slip coefficients that shape the weights' dependence on the
/// slip angle (Pacejka, *Tyre and Vehicle Dynamics*, eqs. 4.E54–4.E57 for
/// Gxα: Cxα, Exα; 4.E62–4.E67 for Gyκ and SVyκ: the α terms of Byκ and
/// DVyκ). Drive/brake runs at one non-zero slip angle fix each weight at that
/// angle only — the shape is then a free extrapolation (collinear with RBX1,
/// RBY1, RVY1, and driven to its bounds by noise) — so these are held at
/// their start values unless the combined runs cover two slip angles or more.
/// Exα's load trend REX2 is not among them: see [`SLIP_ANGLE_LOAD_TREND`].
const SLIP_ANGLE_SHAPE: [&str; 5] = ["rcx1", "rex1", "rby2", "rby3", "rvy4"];

/// Neutral values of the held Gxα shape terms (eqs. 4.E55–4.E56): Cxα = 1,
/// Exα = 0 make the weight cos(atan(Bxα·α)), a curve with no curvature term
/// the data did not show. They replace the start file's values when the
/// start is a generic tyre ([`MfFitOptions::generic_start`]): its values
/// belong to another tyre, and borrowed ones set the extrapolation to slip
/// angles the data do not hold (dev set, runs at −3° scored at −6°: the
/// built-in car tyre's Exα −0.44 made the fitted FSAE tyres' Fx 10–20 % low
/// at −6°; with the neutral shape and REX2 fitted their all-row Fx went
/// from 2.0–2.6 to 1.1–1.4 × the peer's, while the car tyres, whose own
/// shape is nearer the built-in one, lost 0.1–0.2 × (r15 1.08 → 1.26 ×)).
const NEUTRAL_SLIP_ANGLE_SHAPE: [(&str, f64); 2] = [("rcx1", 1.0), ("rex1", 0.0)];

/// Exα's load trend (REX2, eq. 4.E56), the one load-dependent term of Gxα in
/// MF 6.1. At a single slip angle the weight curves G(κ) of several loads
/// differ only through it, so drive/brake runs at two loads or more
/// determine it even where they hold one angle (its level REX1 trades with
/// RBX1 there and stays held). Held when the runs' loads span less than
/// [`LOAD_SPREAD_FOR_TREND`] of FNOMIN.
const SLIP_ANGLE_LOAD_TREND: &str = "rex2";

/// Spread of the drive/brake samples' normalised load change dfz (5th to
/// 95th percentile) from which they count as runs at several loads: test
/// plans step the load by ≥ 25 % of FNOMIN, while a regulated single load
/// scatters by a few per cent.
const LOAD_SPREAD_FOR_TREND: f64 = 0.25;

/// The slip-angle offset of Gxα (SHxα = RHX1, eq. 4.E57): an asymmetry of
/// the weight between positive and negative slip angles, seen only when the
/// drive/brake runs cover both signs of α. At slip angles of one sign it is
/// collinear with RBX1 and RBX2 (one weight curve G(κ) at that angle, three
/// parameters): the dev set's runs at α = −3° fitted RHX1 ≈ −1.1° and an
/// RBX1 twice the generating file's, which extrapolated to −6° underpredicts
/// Fx by 20 %. Held at its start value unless both signs are present.
const SLIP_ANGLE_ASYMMETRY: &str = "rhx1";

/// Whether the drive/brake samples (|κ| > 0.01) of `conds` hold slip angles
/// of both signs (each sign ≥ 5 % of them, beyond ±0.5°).
fn slip_angle_both_signs(conds: &[crate::mf::Conditions]) -> bool {
    let edge = 0.5f64.to_radians();
    let (mut n, mut pos, mut neg) = (0usize, 0usize, 0usize);
    for c in conds.iter().filter(|c| c.kappa.abs() > 0.01) {
        n += 1;
        pos += usize::from(c.alpha > edge);
        neg += usize::from(c.alpha < -edge);
    }
    pos * 20 >= n && neg * 20 >= n && n > 0
}

/// The line `fit` prints (and stamps into the file) when [`run_stage`] held
/// combined-slip terms of the weights' dependence on α ([`SLIP_ANGLE_SHAPE`],
/// [`SLIP_ANGLE_ASYMMETRY`]): the combined forces at slip angles the data do
/// not hold are then the start file's shape, not a fit.
fn held_shape_note(out: &super::solve::FitOutcome) -> Option<String> {
    let held: Vec<String> = out
        .params
        .iter()
        .filter(|p| matches!(p.status, super::solve::ParamStatus::Fixed))
        .filter(|p| {
            let n = p.name.to_ascii_lowercase();
            SLIP_ANGLE_SHAPE.contains(&n.as_str())
                || n == SLIP_ANGLE_ASYMMETRY
                || n == SLIP_ANGLE_LOAD_TREND
        })
        .map(|p| format!("{} = {}", p.name.to_ascii_uppercase(), p.value))
        .collect();
    (!held.is_empty()).then(|| {
        format!(
            "combined stage: the drive/brake runs cover one slip-angle level or one sign of the slip angle, which does not determine how the combined-slip weights change with it; {} held (the start file's values, or the neutral Gxα shape RCX1 = 1, REX1 = 0 when the start is the built-in tyre), so combined forces at slip angles the data do not hold are that shape extrapolated, not fitted",
            held.join(", ")
        )
    })
}

/// Number of distinct non-zero |α| levels of the drive/brake samples
/// (|κ| > 0.01) in `conds`: |α| in 0.5° bins, a bin counted when it holds
/// ≥ 5 % of those samples (a test plan's slip-angle steps are ≥ 1°; the
/// transitions between blocks fall below 5 %).
fn slip_angle_levels(conds: &[crate::mf::Conditions]) -> usize {
    let step = 0.5f64.to_radians();
    let mut bins = std::collections::BTreeMap::<i64, usize>::new();
    let mut n = 0usize;
    for c in conds.iter().filter(|c| c.kappa.abs() > 0.01) {
        n += 1;
        *bins
            .entry((c.alpha.abs() / step).round() as i64)
            .or_default() += 1;
    }
    bins.iter().filter(|(&b, &k)| b != 0 && k * 20 >= n).count()
}

/// The 5th-to-95th-percentile spread of the normalised load change dfz of
/// the drive/brake samples (|κ| > 0.01) of `conds` ([`LOAD_SPREAD_FOR_TREND`]);
/// 0 without such samples.
fn drive_brake_load_spread(conds: &[crate::mf::Conditions], fz0: f64) -> f64 {
    let mut dfz: Vec<f64> = conds
        .iter()
        .filter(|c| c.kappa.abs() > 0.01 && c.fz.is_finite())
        .map(|c| (c.fz - fz0) / fz0)
        .collect();
    if dfz.len() < 2 || !fz0.is_finite() || fz0 <= 0.0 {
        return 0.0;
    }
    dfz.sort_by(f64::total_cmp);
    let at = |q: f64| dfz[((dfz.len() - 1) as f64 * q).round() as usize];
    at(0.95) - at(0.05)
}

/// Why the samples of `seg` segments could not be used, when they exist but
/// lack a model input ("" otherwise): the slip or speed the loader could not
/// derive says more than a count of zero.
fn unusable_inputs(recs: &[Recording], seg: SegmentKind) -> String {
    let (mut n, mut kappa, mut vx) = (0usize, 0usize, 0usize);
    for rec in recs {
        for g in rec.segments.iter().filter(|g| g.kind == seg) {
            for s in &rec.samples[g.start.min(rec.samples.len())..g.end.min(rec.samples.len())] {
                n += 1;
                kappa += usize::from(!s.kappa.is_finite());
                vx += usize::from(!s.vx.is_finite());
            }
        }
    }
    let mut why = Vec::new();
    if n > 0 && kappa * 2 > n {
        why.push("no slip ratio κ (no usable wheel speed, no slip channel, and the run does not roll freely: see `tyrekit data summary`)");
    }
    if n > 0 && vx * 2 > n {
        why.push("no speed channel (Vx or the belt speed)");
    }
    if why.is_empty() {
        String::new()
    } else {
        format!(": {n} samples there, but {}", why.join("; "))
    }
}

/// Run stage `kind` from the values of `tyre` on the fitted rows: its
/// channels where recorded, its samples (the combined stage: the combined
/// rows and the pure ones, see below), its parameter table. `multi_start`:
/// converge from the current values, the neutral start and the data-driven
/// one ([`super::initial`]) and polish the best; otherwise polish from the
/// current values only (a re-fit after a later stage).
pub(crate) fn run_stage(
    ctx: &StageCtx,
    kind: StageKind,
    tyre: &TyreParams,
    multi_start: bool,
    progress: Option<&mut ProgressFn>,
) -> crate::Result<StageRun> {
    let (recs, opts) = (ctx.recs, ctx.opts);
    let (seg, all_channels) = kind.segments_and_channels();
    let recorded = |c: &Channel| recs.iter().any(|r| r.has(c.name()));
    let mut channels: Vec<Channel> = all_channels
        .iter()
        .copied()
        .filter(|c| recorded(c) || !kind.optional(*c))
        .collect();
    let mut note = None;
    if kind == StageKind::Combined && channels.contains(&Channel::Mz) && !mz_shape_fitted(ctx, tyre)
    {
        channels.retain(|&c| c != Channel::Mz);
        note = Some(format!(
            "combined stage: Mz left out (fewer than {} Mz samples in lateral segments: its pure-slip shape is the start tyre's, and fitted with it the combined weights would bend Fy to take up the moment's misfit); Mz under combined slip is the start tyre's, not a fit",
            opts.min_samples
        ));
    }
    if !channels.iter().all(recorded) {
        return Ok(StageRun::Skipped(format!(
            "{}: the data have no {:?} channel",
            kind.name(),
            channels
        )));
    }
    let mut data = gather(&tyre.p, recs, Some(ctx.train), seg, &channels);
    let mut rows = seg;
    if data.conds.len() < opts.min_samples {
        match near_free_rolling(kind, ctx, tyre, &channels) {
            Some(d) => {
                note = Some(format!(
                    "{}: no cornering sweeps ({} samples in {} segments); fitted on the {} drive/brake samples near free rolling (|κ| < {FREE_ROLLING_KAPPA}) at their slip angles, the upright ones included; a few slip angles of one sign do not determine the shape, curvature and vertical shift, so PCY1, PEY1–3, PKY4, PVY1–2 are held at the start's values",
                    kind.name(),
                    data.conds.len(),
                    seg.label(),
                    d.conds.len()
                ));
                data = d;
                rows = SegmentKind::Combined;
            }
            None => {
                return Ok(StageRun::Skipped(format!(
                    "{}: {} samples in {} segments (need {}){}",
                    kind.name(),
                    data.conds.len(),
                    seg.label(),
                    opts.min_samples,
                    unusable_inputs(recs, seg)
                )))
            }
        }
    }
    data.grid = Some(ctx.grid.clone());
    // Slip-angle levels of the combined runs, counted before the pure rows
    // join them (see `SLIP_ANGLE_SHAPE`).
    let combined_alpha_levels = slip_angle_levels(&data.conds);
    let combined_both_signs = slip_angle_both_signs(&data.conds);
    let combined_load_spread = drive_brake_load_spread(&data.conds, tyre.p.fnomin);
    if kind == StageKind::Combined {
        // The combined weights act on the pure rows too (κ and α are
        // never exactly 0 there: Gyκ, SVyκ, Gxα and Mz's s·Fx apply), so
        // the stage fits them with the combined rows: fitted on the
        // combined runs alone they were free to spoil the pure ones
        // (dev set: pure Fy 1.01 → 2.03 × baseline on r04).
        for pure in [SegmentKind::PureLateral, SegmentKind::PureLongitudinal] {
            data.append(gather(&tyre.p, recs, Some(ctx.train), pure, &channels));
        }
    }
    let mut params = stage_params(
        kind,
        &tyre.p,
        data.gamma_spread < CAMBER_SPREAD,
        data.p_spread < PRESSURE_SPREAD || opts.hold_pressure,
    );
    if kind == StageKind::Combined {
        for p in params.iter_mut() {
            let name = p.name.to_ascii_lowercase();
            let shape = combined_alpha_levels < 2 && SLIP_ANGLE_SHAPE.contains(&name.as_str());
            let asym = !combined_both_signs && name == SLIP_ANGLE_ASYMMETRY;
            let trend = combined_alpha_levels < 2
                && combined_load_spread < LOAD_SPREAD_FOR_TREND
                && name == SLIP_ANGLE_LOAD_TREND;
            if shape || asym || trend {
                *p = p.clone().fixed();
                if shape && opts.generic_start {
                    if let Some(&(_, v)) = NEUTRAL_SLIP_ANGLE_SHAPE.iter().find(|(k, _)| *k == name)
                    {
                        p.start = v;
                    }
                }
            }
        }
    }
    if rows == SegmentKind::Combined && kind == StageKind::PureFy {
        for p in params.iter_mut() {
            if FREE_ROLLING_HELD.contains(&p.name.to_ascii_lowercase().as_str()) {
                *p = p.clone().fixed();
            }
        }
    }
    let mut extra = Vec::new();
    if multi_start && !matches!(kind, StageKind::Mx | StageKind::My) {
        extra.push(neutral_start(kind, &params));
        extra.extend(super::initial::estimate(kind, &tyre.p, &data, &params));
    }
    let out = fit_stage(
        ctx.form,
        &tyre.p,
        &params,
        &data,
        &channels,
        opts.threads,
        &opts.fit,
        kind.name(),
        progress,
        &extra,
    )?;
    Ok(StageRun::Done {
        out,
        channels,
        rows,
        note,
    })
}

/// Fit the Magic Formula to `recs` from `start` (whose version decides the
/// equation set). See the module doc.
pub fn fit_mf(
    recs: &[Recording],
    start: TyreParams,
    opts: &MfFitOptions,
    mut progress: Option<&mut ProgressFn>,
) -> crate::Result<MfFit> {
    check_hold(&opts.fit.hold)?;
    let mut tyre = start;
    if opts.nominal_from_data {
        nominal_from_data(&mut tyre, recs)?;
    }
    widen_ranges(&mut tyre, recs)?;
    let geometry = if opts.geometry {
        let _t = super::timing::span(|| "geometry".into());
        let on = opts
            .geometry_recordings
            .as_deref()
            .map_or(recs, |v| v.as_slice());
        Some(super::geometry::fit_geometry(&mut tyre, on)?)
    } else {
        None
    };
    let grid = data_grid(recs);
    let form = form_of(tyre.version);
    let splits: Vec<TrainTest> = recs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let s = opts
                .holdout
                .split_from(r, opts.t_origins.get(i).copied().flatten());
            (s.train, s.test)
        })
        .collect();
    let train: Vec<Vec<Range<usize>>> = splits.iter().map(|s| s.0.clone()).collect();
    let mut report = FitReport {
        sources: recs.iter().map(|r| r.source.clone()).collect(),
        ..Default::default()
    };
    let mut skipped = Vec::new();
    let mut decisions = Vec::new();
    let mut fitted_channels: Vec<(Channel, crate::data::SegmentKind)> = Vec::new();
    let mut ran: Vec<StageKind> = Vec::new();
    let ctx = StageCtx {
        recs,
        train: &train,
        grid: &grid,
        opts,
        form,
    };
    // The rows a stage's acceptance is judged on: the held-out rows where
    // `--holdout` keeps some, else the fitted ones (issue #14 item 3: pick
    // by held-out error, not by in-sample cost).
    let test: Vec<Vec<Range<usize>>> = splits.iter().map(|s| s.1.clone()).collect();
    let judge_rows = if test.iter().any(|t| !t.is_empty()) {
        &test
    } else {
        &train
    };
    for kind in StageKind::ALL {
        if !opts.only.contains(&kind) {
            continue;
        }
        let _t = super::timing::span(|| format!("stage {}", kind.name()));
        let before = tyre.clone();
        let (out, channels, rows) =
            match run_stage(&ctx, kind, &tyre, true, progress.as_deref_mut())? {
                StageRun::Skipped(why) => {
                    skipped.push(why);
                    continue;
                }
                StageRun::Done {
                    out,
                    channels,
                    rows,
                    note,
                } => {
                    decisions.extend(note);
                    (out, channels, rows)
                }
            };
        for p in &out.params {
            tyre.set(&p.name, p.value)?;
        }
        if kind == StageKind::Combined {
            decisions.extend(held_shape_note(&out));
        }
        let mut outs = vec![out];
        if kind == StageKind::Combined {
            let pure: Vec<StageKind> = ran
                .iter()
                .copied()
                .filter(|k| matches!(k, StageKind::PureFx | StageKind::PureFy | StageKind::Mz))
                .collect();
            let (t, o, note) = gate::accept_combined(
                &ctx,
                &before,
                tyre,
                &outs[0],
                &pure,
                &channels,
                judge_rows,
                progress.as_deref_mut(),
            )?;
            tyre = t;
            outs.extend(o);
            decisions.push(note);
        }
        report.stages.extend(outs);
        ran.push(kind);
        for &c in &channels {
            fitted_channels.push((c, rows));
        }
    }
    report.fitted = fitted_channels
        .iter()
        .map(|(c, seg)| (c.name().to_string(), *seg))
        .collect();
    if opts.transient {
        let (fits, skip) =
            super::transient::fit_relaxation(recs, &mut tyre, Some(&train), opts.min_samples)?;
        report.relaxation = fits;
        skipped.extend(skip);
    }
    // Quality: every fitted channel over its segments, fitted and held out.
    let _t = super::timing::span(|| "metrics".into());
    let model = Model::new(tyre.p.clone(), form);
    for (c, seg) in &fitted_channels {
        if fitted_channels
            .iter()
            .position(|(c2, _)| c2 == c)
            .is_some_and(|first| fitted_channels[first].1 != *seg)
        {
            continue; // scored once, over the segments of its first stage
        }
        for (r, rec) in recs.iter().enumerate() {
            let sim: Vec<f64> = rec
                .samples
                .iter()
                .map(|s| c.of(&model.solve(&conditions_of(&tyre.p, s))))
                .collect();
            let kinds = [*seg];
            let on = segment_ranges(rec, &kinds, &splits[r].0);
            if !on.is_empty() {
                report
                    .metrics
                    .extend(metrics::evaluate(rec, c.name(), &sim, Some(&on))?);
            }
            let off = segment_ranges(rec, &kinds, &splits[r].1);
            if !off.is_empty() {
                report
                    .holdout_metrics
                    .extend(metrics::evaluate(rec, c.name(), &sim, Some(&off))?);
            }
        }
    }
    Ok(MfFit {
        tyre,
        report,
        skipped,
        decisions,
        splits,
        geometry,
    })
}

/// The overall (all-conditions) σ of `channel` in `m`, if present.
pub fn overall_sigma(m: &[ChannelMetric], channel: &str) -> Option<f64> {
    m.iter()
        .find(|x| x.channel == channel && x.condition.is_none())
        .map(|x| x.sigma)
}

#[cfg(test)]
mod tests {
    use super::{
        drive_brake_load_spread, slip_angle_both_signs, slip_angle_levels, LOAD_SPREAD_FOR_TREND,
    };
    use crate::mf::Conditions;

    fn runs(levels_deg: &[f64]) -> Vec<Conditions> {
        let mut v = Vec::new();
        for &a in levels_deg {
            for i in 0..200 {
                v.push(Conditions {
                    alpha: a.to_radians(),
                    kappa: -0.2 + 0.4 * i as f64 / 199.0,
                    ..Default::default()
                });
            }
        }
        v
    }

    #[test]
    fn slip_angle_levels_count_the_drive_brake_blocks() {
        // A test plan at SA 0 and −3°: one non-zero level; the shape of
        // the weights in α is then not determined.
        assert_eq!(slip_angle_levels(&runs(&[0.0, -3.0])), 1);
        // SA 0, −3, −6: two; ±3 counts once (|α| — the weights' shape
        // terms are even in α without a shift).
        assert_eq!(slip_angle_levels(&runs(&[0.0, -3.0, -6.0])), 2);
        assert_eq!(slip_angle_levels(&runs(&[3.0, -3.0])), 1);
        // A few samples of a transition between blocks do not count.
        let mut c = runs(&[0.0, -3.0]);
        c.extend(runs(&[-6.0]).into_iter().take(5));
        assert_eq!(slip_angle_levels(&c), 1);
        // Free-rolling samples (|κ| ≤ 0.01) are not drive/brake runs.
        let free: Vec<Conditions> = runs(&[-6.0, -9.0])
            .into_iter()
            .map(|c| Conditions { kappa: 0.0, ..c })
            .collect();
        assert_eq!(slip_angle_levels(&free), 0);
    }

    #[test]
    fn load_spread_tells_runs_at_several_loads_from_one() {
        // Drive/brake samples at a regulated load scattering by ±2 %.
        let at = |fz: f64, n: usize| {
            (0..n).map(move |i| Conditions {
                fz: fz * (1.0 + 0.02 * ((i % 7) as f64 - 3.0) / 3.0),
                kappa: 0.1,
                ..Default::default()
            })
        };
        // One load: its scatter is no load trend.
        let one: Vec<Conditions> = at(1000.0, 200).collect();
        assert!(drive_brake_load_spread(&one, 1000.0) < LOAD_SPREAD_FOR_TREND);
        // Loads of 0.2 … 1.4 × FNOMIN: dfz spans −0.8 … +0.4.
        let four: Vec<Conditions> = [200.0, 600.0, 1000.0, 1400.0]
            .iter()
            .flat_map(|&f| at(f, 100))
            .collect();
        let spread = drive_brake_load_spread(&four, 1000.0);
        assert!((spread - 1.2).abs() < 0.05, "spread {spread}");
        // Free-rolling samples (|κ| ≤ 0.01) are no drive/brake runs.
        let free: Vec<Conditions> = four
            .iter()
            .map(|c| Conditions { kappa: 0.0, ..*c })
            .collect();
        assert_eq!(drive_brake_load_spread(&free, 1000.0), 0.0);
    }

    #[test]
    fn held_slip_angle_terms_are_said() {
        use crate::fit::solve::{FitOutcome, ParamResult, ParamStatus};
        let r = |name: &str, status: ParamStatus| ParamResult {
            name: name.into(),
            start: 1.0,
            value: 1.0,
            stderr: None,
            status,
        };
        let mut out = FitOutcome {
            stage: "combined".into(),
            theta: vec![1.0; 3],
            params: vec![
                r("rbx1", ParamStatus::Fitted),
                r("rcx1", ParamStatus::Fixed),
                r("rhx1", ParamStatus::Fixed),
            ],
            initial_cost: 1.0,
            swarm_cost: None,
            cost: 1.0,
            residual_variance: 1.0,
            correlated: Vec::new(),
            n_residuals: 10,
            iterations: 1,
            termination: crate::fit::lm::Termination::Cost,
        };
        let note = super::held_shape_note(&out).expect("held terms are said");
        assert!(note.contains("RCX1 = 1, RHX1 = 1") && note.contains("extrapolated"));
        assert!(!note.contains("RBX1"));
        // Nothing held (two levels, both signs): nothing said.
        out.params.retain(|p| p.name == "rbx1");
        assert!(super::held_shape_note(&out).is_none());
    }

    #[test]
    fn slip_angle_signs_decide_whether_the_asymmetry_is_seen() {
        // SA 0 and −3° (the dev set's plan), or −3 and −6°: one sign, so
        // RHX1 is held; ±3°: both signs, so it is fitted.
        assert!(!slip_angle_both_signs(&runs(&[0.0, -3.0])));
        assert!(!slip_angle_both_signs(&runs(&[-3.0, -6.0])));
        assert!(slip_angle_both_signs(&runs(&[3.0, -3.0])));
        // A stray transition (< 5 % of the drive/brake samples) is no
        // second sign; no drive/brake samples at all is none.
        let mut c = runs(&[0.0, -3.0]);
        c.extend(runs(&[3.0]).into_iter().take(5));
        assert!(!slip_angle_both_signs(&c));
        assert!(!slip_angle_both_signs(&[]));
    }
}
