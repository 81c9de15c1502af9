//! strategy — how one stage is solved ([`fit_stage`]): the channels
//! stacked with weights, a coarse subsample first, several starts raced
//! on a smaller one ([`RACE_SAMPLES`], [`neutral_start`]), the validity
//! rows softened and restored (the penalty continuation, [`CONTINUATION`]),
//! then the crate's one Levenberg–Marquardt ([`crate::fit::solve`]).
//!
//! Must never: judge a start on the subsample it was fitted on alone, or
//! return a start's point without the full-data polish.

use super::Channel;
use super::{MfStage, StageData, StageKind};
use crate::fit::problem::{Param, Problem, Stack};
use crate::fit::solve::{fit_global, FitOptions, FitOutcome, ProgressFn};
use crate::fit::validity::Validity;
use crate::mf::Form;
use crate::tir::MfParams;

/// Size of the subsample a large stage first converges on
/// ([`crate::fit::FitOptions::coarse_first`]): stages with more than twice
/// this many samples use every k-th sample with k = m / `COARSE_SAMPLES`.
/// 10 000 samples determine ≈ 30 parameters to well within the sampling
/// error of the full data's solution, so the full-data polish that follows
/// takes two or three iterations.
pub const COARSE_SAMPLES: usize = 10_000;

/// Size of the subsample the starts of a multi-start stage race on
/// (`best_start`; stages with more than twice this many samples use every
/// k-th sample with k = m / `RACE_SAMPLES`). The race only decides which
/// basin the winner comes from — it is judged on the full data and then
/// converged on the [`COARSE_SAMPLES`] subsample and the full data — so it
/// needs the curve shapes, not the last digit: 3 000 samples are still
/// ≈ 100 per parameter of the largest stage (combined, ≈ 30), and every
/// sweep of a 100 Hz recording keeps a point each ≈ 0.1 s. On the dev set's
/// 84 000-line recordings the two Mz starts took 5 of a fit's 14 s
/// racing on 11 500 samples. Only stages evaluated through num-dual race
/// on it (Mz, combined, Mx, My); the closed-form pure-slip stages race on
/// the coarse subsample (on dev-set r03, whose pure-Fy valley of collinear
/// PKY2/PKY4/PKY5 makes the end point depend on the path, the small race
/// had moved held-out pure Fy 0.91 → 0.96× the answer's baseline).
pub const RACE_SAMPLES: usize = 3_000;

/// Fit one Magic Formula stage: the `channels` of `data` (channel k ↔
/// `data.meas[k]`; several channels are stacked with weights 1/mean(y²), so
/// newtons and newton-metres compare) over `params`, from `base`, on
/// `threads` threads; a stage with more than 2·[`COARSE_SAMPLES`] samples
/// first converges on a subsample unless `opts.coarse_first` is off. With
/// `extra_starts` (θ vectors over `params`) the parameters' start and each
/// of them are raced, and the candidate with the least full-data cost after
/// converging on the subsample is polished (`best_start`).
#[allow(clippy::too_many_arguments)]
pub fn fit_stage(
    form: Form,
    base: &MfParams<f64>,
    params: &[Param],
    data: &StageData,
    channels: &[Channel],
    threads: usize,
    opts: &FitOptions,
    name: &str,
    progress: Option<&mut ProgressFn>,
    extra_starts: &[Vec<f64>],
) -> crate::Result<FitOutcome> {
    let m = data.conds.len();
    let t_build = crate::fit::timing::span(|| format!("  {name}: build ({m} samples)"));
    let coarse =
        (opts.coarse_first && m > 2 * COARSE_SAMPLES).then(|| data.every(m / COARSE_SAMPLES));
    let weights: Vec<f64> = data
        .meas
        .iter()
        .map(|y| {
            let ms = y.iter().map(|v| v * v).sum::<f64>() / y.len().max(1) as f64;
            if channels.len() > 1 && ms > 0.0 {
                1.0 / ms
            } else {
                1.0
            }
        })
        .collect();
    fn parts_of<'d>(
        form: Form,
        base: &MfParams<f64>,
        params: &[Param],
        d: &'d StageData,
        channels: &[Channel],
        weights: &[f64],
        threads: usize,
    ) -> crate::Result<Vec<MfStage<'d>>> {
        channels
            .iter()
            .enumerate()
            .map(|(k, &c)| {
                Ok(MfStage::new(form, base, params.to_vec(), d, k, c)?
                    .with_weight(weights[k])
                    .with_threads(threads))
            })
            .collect()
    }
    let parts = parts_of(form, base, params, data, channels, &weights, threads)?;
    let coarse_parts = match &coarse {
        Some(d) => parts_of(form, base, params, d, channels, &weights, threads)?,
        None => Vec::new(),
    };
    // Stages with closed-form Jacobians (pure Fx, pure Fy) race on the
    // coarse subsample: there the race costs little (≈ 0.1–0.4 s), and the
    // smaller subsample would trade start choice for nothing worth having.
    let dual = parts.iter().any(|p| p.analytic.is_none());
    let race = (opts.coarse_first && !extra_starts.is_empty() && m > 2 * RACE_SAMPLES && dual)
        .then(|| data.every(m / RACE_SAMPLES));
    // The same for the quick full-data polish (`FitOptions::quick_polish`).
    let mut opts = opts.clone();
    opts.quick_polish |= dual;
    let opts = &opts;
    let race_parts = match &race {
        Some(d) => parts_of(form, base, params, d, channels, &weights, threads)?,
        None => Vec::new(),
    };
    // The validity rows, scaled to the weighted energy of the data they join.
    let validity = |d: &StageData| -> crate::Result<Option<Validity>> {
        let Some(grid) = &d.grid else { return Ok(None) };
        let energy: f64 = d
            .meas
            .iter()
            .zip(&weights)
            .map(|(y, w)| w * y.iter().map(|v| v * v).sum::<f64>())
            .sum();
        Ok(Some(Validity::new(form, base, params, grid, energy)?))
    };
    let valid = validity(data)?;
    let coarse_valid = match &coarse {
        Some(d) => validity(d)?,
        None => None,
    };
    let race_valid = match &race {
        Some(d) => validity(d)?,
        None => None,
    };
    // `soft` scales the validity rows' weight (the penalty continuation).
    fn stacked<'p>(
        parts: &'p [MfStage<'_>],
        valid: &'p Option<Validity>,
        soft: f64,
    ) -> crate::Result<Option<Stack<'p>>> {
        if parts.is_empty() || (parts.len() == 1 && valid.is_none()) {
            return Ok(None);
        }
        let mut v: Vec<(&dyn Problem, f64)> =
            parts.iter().map(|p| (p as &dyn Problem, 1.0)).collect();
        if let Some(val) = valid {
            v.push((val as &dyn Problem, soft));
        }
        Ok(Some(Stack::new(v)?))
    }
    let stack = stacked(&parts, &valid, 1.0)?;
    let coarse_stack = stacked(&coarse_parts, &coarse_valid, 1.0)?;
    let race_stack = stacked(&race_parts, &race_valid, 1.0)?;
    let problem: &dyn Problem = match &stack {
        Some(s) => s,
        None => &parts[0],
    };
    fn one_of<'p>(
        stack: &'p Option<Stack<'_>>,
        parts: &'p [MfStage<'_>],
    ) -> Option<&'p dyn Problem> {
        match (stack, parts.first()) {
            (Some(s), _) => Some(s),
            (None, Some(p)) => Some(p),
            (None, None) => None,
        }
    }
    let coarse_problem = one_of(&coarse_stack, &coarse_parts);
    let race_problem = one_of(&race_stack, &race_parts);
    // The penalty continuation's ladder on the level the starts race on.
    let (on_parts, on_valid) = if race.is_some() {
        (&race_parts, &race_valid)
    } else if coarse.is_some() {
        (&coarse_parts, &coarse_valid)
    } else {
        (&parts, &valid)
    };
    let bound = !extra_starts.is_empty() && on_valid.as_ref().is_some_and(|v| v.n_residuals() > 0);
    let ladder: Vec<Stack> = if bound {
        CONTINUATION
            .iter()
            .filter_map(|&f| stacked(on_parts, on_valid, f).transpose())
            .collect::<crate::Result<_>>()?
    } else {
        Vec::new()
    };
    drop(t_build);
    let mut start = None;
    if !extra_starts.is_empty() {
        let _t = crate::fit::timing::span(|| {
            format!("  {name}: best_start ({})", extra_starts.len() + 1)
        });
        start = Some(best_start(
            problem,
            race_problem.or(coarse_problem),
            extra_starts,
            &ladder,
            opts,
            name,
        )?);
    }
    fit_global(
        problem,
        coarse_problem,
        start.as_deref(),
        None,
        opts,
        name,
        progress,
    )
}

/// Most LM iterations per round of one start in `best_start`: the starts
/// race, and the winner is polished to convergence afterwards, so the limit
/// decides only which start wins when one of them crawls: a start still
/// descending after 50 steps on the subsample is then judged where it
/// stands (rig recording of `tyrekit bench diagnose`, combined stage: the
/// own start took 200 iterations, 40 s, to reach a cost of 90.6; the
/// neutral start 82.7 in 22).
pub const START_ITERATIONS: usize = 50;

/// The penalty continuation (a homotopy on the validity rows' weight):
/// factors on the weight of [`Validity`]'s rows, in the order they are
/// solved, before the full weight (1). A minimum of the fit that sits on a
/// validity bound (E = 1 at some load) is where the hinge penalty stops LM:
/// a step along the bound leaves it on one side and is rejected on the
/// other. Solved first with the bound softened (violations cost 10⁴ and
/// 10² times less), the fit moves towards the unconstrained minimum and
/// comes back to the bound where the data put it, which may lie in another
/// basin (Nocedal & Wright, *Numerical Optimization*, 2nd ed., §17.1, the
/// quadratic penalty method with an increasing weight). TyreData's pure Fy
/// (28 Nov 2026): from the race's winner (σ_Fy 4.47 %, Ey = 1 at the top
/// load) to σ_Fy 4.13 %, the best of a 62-start global search with the
/// bounds imposed exactly (SLSQP), with Ey falling with load instead.
pub const CONTINUATION: [f64; 2] = [1e-4, 1e-2];

/// Several starts (issue #14 item 3): the problem's own and `extra`, each
/// converged on the subsample `coarse` (to 1e-6; the [`RACE_SAMPLES`] or
/// the [`COARSE_SAMPLES`] subsample when the stage is large, the problem
/// itself when it is not), judged by the full problem's cost — with a
/// subsample that is the error on the (k − 1)/k samples the candidate was
/// not fitted on, a held-out figure. Then, when the stage has validity
/// rows, the best is carried through the penalty continuation (`ladder`:
/// the subsample's problem with the rows' weight at each factor of
/// [`CONTINUATION`], then at full weight) and replaced by the result when
/// that costs less by more than one part in 10⁶ (a minimum off the bounds
/// comes back to itself). Returns the best converged point.
fn best_start(
    problem: &dyn Problem,
    coarse: Option<&dyn Problem>,
    extra: &[Vec<f64>],
    ladder: &[Stack],
    opts: &FitOptions,
    name: &str,
) -> crate::Result<Vec<f64>> {
    let own: Vec<f64> = problem.params().iter().map(|p| p.start).collect();
    let mut loose = opts.clone();
    loose.lm.ftol = loose.lm.ftol.max(1e-6);
    loose.lm.xtol = loose.lm.xtol.max(1e-6);
    loose.lm.gtol = loose.lm.gtol.max(1e-6);
    loose.lm.max_iter = loose.lm.max_iter.min(START_ITERATIONS);
    loose.coarse_first = false;
    let on = coarse.unwrap_or(problem);
    let mut r = vec![0.0; problem.n_residuals()];
    let mut best: Option<(f64, Vec<f64>)> = None;
    for s in std::iter::once(&own).chain(extra) {
        // A start the model cannot evaluate is skipped.
        let Ok(o) = fit_global(on, None, Some(s), None, &loose, name, None) else {
            continue;
        };
        problem.residuals(&o.theta, &mut r);
        let c = opts.lm.loss.cost(&r, problem.weights());
        if c.is_finite() && best.as_ref().is_none_or(|b| c < b.0) {
            best = Some((c, o.theta));
        }
    }
    if let (Some((c0, theta0)), false) = (&best, ladder.is_empty()) {
        let mut cont = opts.clone();
        cont.coarse_first = false;
        let mut theta = theta0.clone();
        let mut ok = true;
        for step in ladder
            .iter()
            .map(|p| p as &dyn Problem)
            .chain(std::iter::once(on))
        {
            match fit_global(step, None, Some(&theta), None, &cont, name, None) {
                Ok(o) => theta = o.theta,
                Err(_) => {
                    ok = false;
                    break;
                }
            }
        }
        if ok {
            problem.residuals(&theta, &mut r);
            let c = opts.lm.loss.cost(&r, problem.weights());
            if c.is_finite() && c < c0 * (1.0 - 1e-6) {
                best = Some((c, theta));
            }
        }
    }
    Ok(best.map_or(own, |b| b.1))
}

/// The neutral start of a stage's free parameters: the shape, shift,
/// curvature and camber terms at 0, only the primary factors (C, D, K and
/// their load terms, Bt, Ct, Dt of the trail, the combined weights' B and C)
/// kept — a second start far from a poor minimum the first may sit in
/// (a curvature factor driven to a bound, a trail shape fitted by camber
/// terms). Fixed parameters keep their values.
pub fn neutral_start(kind: StageKind, params: &[Param]) -> Vec<f64> {
    const KEEP: &[&str] = &[
        "pcy1", "pdy1", "pdy2", "pky1", "pky2", "pky4", "pcx1", "pdx1", "pdx2", "pkx1", "pkx2",
        "qbz1", "qcz1", "qdz1", "qdz2", "rbx1", "rbx2", "rcx1", "rby1", "rby2", "rcy1",
    ];
    let _ = kind;
    params
        .iter()
        .map(|p| {
            if !p.free || KEEP.contains(&p.name.as_str()) {
                p.start
            } else {
                p.clamp(0.0)
            }
        })
        .collect()
}
