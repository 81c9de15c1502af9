//! solve — one fit of one [`Problem`]: optional swarm start, identifiability
//! check, bounded LM polish, standard errors; and a sequence of such fits
//! (stages) passing the solution on by parameter name.
//!
//! Must never: move a parameter the data cannot determine (it is held at its
//! start value and reported as not identified), or talk to a terminal
//! (progress goes through the optional callback only).

use super::identify::{correlated_pairs, identify, standard_errors, IdentifyOptions, Verdict};
use super::lm::{self, linearise, LmOptions, Termination, Workspace};
use super::problem::{validate, Problem};
use super::pso::{self, PsoOptions};

/// Settings of one fit.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FitOptions {
    /// Levenberg–Marquardt polish: iteration limit, tolerances, initial
    /// damping, robust loss and stop rules.
    pub lm: LmOptions,
    /// Global start by particle swarm (needs finite bounds on the free parameters).
    pub pso: Option<PsoOptions>,
    /// Thresholds of the identifiability test that decides which free
    /// parameters are held at their start values.
    pub identify: IdentifyOptions,
    /// With a subsampled problem given to [`fit_global`]: converge the LM on
    /// it first (to a loose tolerance, 1e-6), then polish on all samples.
    /// The subsample's optimum is within sampling error of the full one, so
    /// the full-data polish needs few of the expensive iterations; the result
    /// (final cost, held set, standard errors) is always the full problem's.
    #[serde(default)]
    pub coarse_first: bool,
    /// Parameters (by name, case-insensitive) held at their start values
    /// whatever their `free` flag: the user's hold list (`tyrekit fit
    /// --hold`). Names the problem does not have are ignored here (a staged
    /// fit checks them against all its stages, see `mf_fit::fit_mf`).
    #[serde(default)]
    pub hold: Vec<String>,
    /// With `coarse_first`: after the subsample has converged, polish on all
    /// samples the quick way — at the final tolerance at once when the
    /// subsample's held set stands, and stopping at the first step below
    /// the stall rule's rate ([`POLISH_STALL_STEPS`]). For stages whose
    /// every full-data Jacobian is expensive (num-dual over 10⁵ residuals);
    /// where it costs milliseconds the path is left as it was, since in a
    /// flat valley the end point depends on it.
    #[serde(default)]
    pub quick_polish: bool,
}

impl FitOptions {
    /// Whether the hold list names parameter `name`.
    pub fn holds(&self, name: &str) -> bool {
        self.hold
            .iter()
            .any(|h| h.trim().eq_ignore_ascii_case(name))
    }
}

/// What is happening, for a progress display.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Global search by particle swarm ([`pso::minimize`]).
    Swarm,
    /// Bounded Levenberg–Marquardt polish of one start ([`lm`]).
    Polish,
}

/// One progress report.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a> {
    /// Name of the stage being fitted (e.g. `"pure Fy"`).
    pub stage: &'a str,
    /// Swarm or polish.
    pub phase: Phase,
    /// Iteration within the phase.
    pub iteration: usize,
    /// Upper limit of `iteration`: [`PsoOptions::iterations`] or
    /// [`LmOptions::max_iter`].
    pub max_iterations: usize,
    /// Which start is being polished (0-based).
    pub candidate: usize,
    /// Number of starts polished (1 without a swarm).
    pub candidates: usize,
    /// Best cost so far (within this phase and candidate).
    pub cost: f64,
}

/// Progress callback type.
pub type ProgressFn<'a> = dyn FnMut(&Progress) + 'a;

/// How a parameter came out of the fit.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ParamStatus {
    /// Not free in this fit.
    Fixed,
    /// Fitted, inside its bounds.
    Fitted,
    /// Fitted, but ended on a bound (its standard error is only indicative).
    AtBound,
    /// Free, but the data cannot determine it: held at its start value.
    NotIdentified {
        /// Why: no effect on the residuals, or collinear with named parameters.
        reason: Verdict,
    },
}

/// One parameter's result.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ParamResult {
    /// Parameter name (the `.tir` key in lower case for Magic Formula fits,
    /// e.g. `pdy1`).
    pub name: String,
    /// Value the fit started from (given start, or carried from an earlier
    /// stage), in the parameter's own unit.
    pub start: f64,
    /// Fitted value; equal to `start` unless fitted.
    pub value: f64,
    /// Standard error (identified parameters only).
    pub stderr: Option<f64>,
    /// How the parameter came out (fixed, fitted, at a bound, not identified).
    #[serde(flatten)]
    pub status: ParamStatus,
}

/// Result of one fit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct FitOutcome {
    /// Name of the stage (the `stage` argument of [`fit`]).
    pub stage: String,
    /// All parameter values (θ order of the problem).
    pub theta: Vec<f64>,
    /// Per-parameter results, θ order.
    pub params: Vec<ParamResult>,
    /// Cost ½Σ c²ρ(w r²/c²) ([`super::loss::Loss::cost`]) at the start,
    /// on all residuals.
    pub initial_cost: f64,
    /// Best swarm cost, if a swarm ran.
    pub swarm_cost: Option<f64>,
    /// Cost at the solution, on all residuals (same definition as
    /// `initial_cost`).
    pub cost: f64,
    /// Residual variance s² = Σωr²/(m − n_identified).
    pub residual_variance: f64,
    /// Pairs of fitted parameters whose estimates correlate beyond ±0.95
    /// (name, name, correlation): the data mainly determine a combination.
    pub correlated: Vec<(String, String, f64)>,
    /// Number of residuals m of the full problem.
    pub n_residuals: usize,
    /// LM outer iterations of the chosen start's final (full-data) polish.
    pub iterations: usize,
    /// Why that polish stopped.
    pub termination: Termination,
}

impl FitOutcome {
    /// Value of a parameter by name.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.params.iter().find(|p| p.name == name).map(|p| p.value)
    }
    /// Result of a parameter by name.
    pub fn param(&self, name: &str) -> Option<&ParamResult> {
        self.params.iter().find(|p| p.name == name)
    }
}

/// Fit `problem` from `start` (None: the problem's start values) over the
/// parameters marked in `free` (None: the problem's `free` flags).
/// The swarm (if `opts.pso` is set) runs on `problem` itself; see
/// [`fit_global`] to run it on a cheaper subsample.
pub fn fit(
    problem: &dyn Problem,
    start: Option<&[f64]>,
    free: Option<&[bool]>,
    opts: &FitOptions,
    stage: &str,
    progress: Option<&mut ProgressFn>,
) -> crate::Result<FitOutcome> {
    fit_global(problem, None, start, free, opts, stage, progress)
}

/// The stall window ([`LmOptions::stall`]) of a full-data polish
/// that starts from a converged subsample solution: the rule's rate per
/// step is kept, its window shortened to this many accepted steps.
pub const POLISH_STALL_STEPS: usize = 1;

/// [`fit`] with the swarm run on `swarm_problem` (same parameter table, e.g.
/// every 20th sample: the swarm needs thousands of cost evaluations, the
/// polish a dozen). `FitOutcome::swarm_cost` is then that problem's cost.
/// With [`FitOptions::coarse_first`] the LM also converges on it first.
pub fn fit_global(
    problem: &dyn Problem,
    swarm_problem: Option<&dyn Problem>,
    start: Option<&[f64]>,
    free: Option<&[bool]>,
    opts: &FitOptions,
    stage: &str,
    mut progress: Option<&mut ProgressFn>,
) -> crate::Result<FitOutcome> {
    let params = problem.params();
    let swarm_problem = swarm_problem.unwrap_or(problem);
    let same_table = swarm_problem.params().len() == params.len()
        && swarm_problem
            .params()
            .iter()
            .zip(params)
            .all(|(a, b)| a.name == b.name);
    if !same_table {
        return Err(crate::Error::Input(format!(
            "fit stage '{stage}': the swarm problem's parameters differ from the problem's"
        )));
    }
    let theta0: Vec<f64> = match start {
        Some(s) => s.to_vec(),
        None => params.iter().map(|p| p.start).collect(),
    };
    validate(problem, &theta0)?;
    let free_in: Vec<bool> = match free {
        Some(f) if f.len() == params.len() => f.to_vec(),
        Some(f) => {
            return Err(crate::Error::Input(format!(
                "fit: free mask of length {} for {} parameters",
                f.len(),
                params.len()
            )))
        }
        None => params.iter().map(|p| p.free).collect(),
    };
    let free_in: Vec<bool> = free_in
        .iter()
        .zip(params)
        .map(|(&f, p)| f && !opts.holds(&p.name))
        .collect();
    let n_all = params.len();
    let m = problem.n_residuals();
    let loss = opts.lm.loss;
    if loss.kind != super::loss::LossKind::Linear && !(loss.scale.is_finite() && loss.scale > 0.0) {
        return Err(crate::Error::Input(format!(
            "fit stage '{stage}': robust loss scale {} (must be a positive residual size)",
            loss.scale
        )));
    }
    let mut r = vec![0.0; m];
    problem.residuals(&theta0, &mut r);
    let initial_cost = loss.cost(&r, problem.weights());

    // 1. Global start: the swarm's best distinct points, then the given start.
    let mut starts: Vec<Vec<f64>> = Vec::new();
    let mut swarm_cost = None;
    if let Some(po) = &opts.pso {
        let _t = super::timing::span(|| format!("    {stage}: swarm"));
        let cols: Vec<usize> = (0..n_all).filter(|&i| free_in[i]).collect();
        if !cols.is_empty() {
            let lo: Vec<f64> = cols.iter().map(|&c| params[c].lower).collect();
            let hi: Vec<f64> = cols.iter().map(|&c| params[c].upper).collect();
            let x0: Vec<f64> = cols.iter().map(|&c| theta0[c]).collect();
            let mut th = theta0.clone();
            let mut rs = vec![0.0; swarm_problem.n_residuals()];
            let mut cb = |it: usize, c: f64| {
                if let Some(p) = progress.as_mut() {
                    p(&Progress {
                        stage,
                        phase: Phase::Swarm,
                        iteration: it,
                        max_iterations: po.iterations,
                        candidate: 0,
                        candidates: 1,
                        cost: c,
                    })
                }
            };
            let res = pso::minimize(
                &lo,
                &hi,
                Some(&x0),
                |x| {
                    for (k, &c) in cols.iter().enumerate() {
                        th[c] = x[k];
                    }
                    swarm_problem.residuals(&th, &mut rs);
                    loss.cost(&rs, swarm_problem.weights())
                },
                po,
                Some(&mut cb),
            )?;
            for x in res.candidates.iter().take(po.polish.max(1)) {
                let mut t = theta0.clone();
                for (k, &c) in cols.iter().enumerate() {
                    t[c] = x[k];
                }
                starts.push(t);
            }
            swarm_cost = Some(res.cost);
        }
    }

    // 2–4. Polish every candidate start; keep the lowest final cost (ties: the
    // earlier candidate, so the swarm's best wins over the user's start).
    if !starts.contains(&theta0) {
        starts.push(theta0.clone());
    }
    let mut ws = Workspace::new(m, 0);
    let mut best: Option<Polished> = None;
    let n_starts = starts.len();
    // A candidate whose polish fails (e.g. the model is undefined there) is
    // skipped; the fit fails only if every candidate does.
    let mut first_err = None;
    // After a coarse solution the polish starts close to the optimum: small
    // initial damping (Madsen, Nielsen & Tingleff 2004, §3.2: τ = 1e-6 for a
    // start believed to be good), so it takes Gauss–Newton steps at once.
    let mut near = opts.clone();
    near.lm.lambda0 = near.lm.lambda0.min(1e-6);
    // With `quick_polish`, a shorter stall window at the same rate per
    // step: from a converged subsample the first Gauss–Newton steps take up the sampling
    // difference, and what follows is the valley creep the stall rule
    // exists for; no later acceleration is to wait for (dev-set r19,
    // combined stage: 11 full-data steps, 6.5 of the fit's 17 s, lowered
    // the cost by 1.0e-5 of it).
    if opts.quick_polish {
        near.lm.stall = opts.lm.stall.map(|(n, f)| {
            let w = n.clamp(1, POLISH_STALL_STEPS);
            (w, f * w as f64 / n.max(1) as f64)
        });
    }
    for (which, mut cand) in starts.into_iter().enumerate() {
        let mut polish_opts = None;
        let mut prior = None;
        if opts.coarse_first && !std::ptr::addr_eq(swarm_problem, problem) {
            let mut loose = opts.clone();
            loose.lm.ftol = loose.lm.ftol.max(1e-6);
            loose.lm.xtol = loose.lm.xtol.max(1e-6);
            loose.lm.gtol = loose.lm.gtol.max(1e-6);
            let mut cws = Workspace::new(swarm_problem.n_residuals(), 0);
            let _t = super::timing::span(|| {
                format!(
                    "    {stage}: coarse polish ({})",
                    swarm_problem.n_residuals()
                )
            });
            // A failing coarse polish leaves the candidate as it was.
            if let Ok(c) = polish(
                swarm_problem,
                cand.clone(),
                (which, n_starts),
                &theta0,
                &free_in,
                None,
                &loose,
                stage,
                progress.as_deref_mut(),
                &mut cws,
            ) {
                cand = c.theta;
                prior = opts.quick_polish.then_some(c.verdict);
                polish_opts = Some(&near);
            }
        }
        let _t =
            super::timing::span(|| format!("    {stage}: full polish ({})", problem.n_residuals()));
        let p = match polish(
            problem,
            cand,
            (which, n_starts),
            &theta0,
            &free_in,
            prior.as_deref(),
            polish_opts.unwrap_or(opts),
            stage,
            progress.as_deref_mut(),
            &mut ws,
        ) {
            Ok(p) => p,
            Err(e) => {
                first_err.get_or_insert(e);
                continue;
            }
        };
        if best.as_ref().is_none_or(|b| p.cost < b.cost) {
            best = Some(p);
        }
    }
    let best = match (best, first_err) {
        (Some(b), _) => b,
        (None, Some(e)) => return Err(e),
        (None, None) => return Err(crate::Error::Numeric("fit: no start to polish".into())),
    };
    let Polished {
        theta,
        free,
        verdict,
        current,
        iterations,
        termination,
        mut cost,
    } = best;
    let cols0: Vec<usize> = (0..n_all).filter(|&i| free_in[i]).collect();

    // 5. Standard errors over the identified free set.
    let _t = super::timing::span(|| format!("    {stage}: standard errors"));
    let mut stderr = vec![None; n_all];
    let mut correlated = Vec::new();
    let n_free = (0..n_all).filter(|&i| free[i]).count();
    let mut residual_variance = 2.0 * cost / (m.saturating_sub(n_free).max(1)) as f64;
    if !cols0.is_empty() {
        let lin = match current {
            Some(l) => l,
            None => linearise(problem, &theta, &cols0, &loss, &mut ws)?,
        };
        // The linearisation may be one final step of negligible gain before
        // θ (see `LmResult::linearisation`): the cost is θ's own, and Σωr²
        // is scaled to it (exact for plain least squares, where it is 2·cost).
        let wrss = if lin.cost > 0.0 && cost.is_finite() {
            lin.wrss * (cost / lin.cost)
        } else {
            lin.wrss
        };
        residual_variance = wrss / (m.saturating_sub(n_free).max(1)) as f64;
        let keep: Vec<bool> = cols0.iter().map(|&c| free[c]).collect();
        let se = standard_errors(&lin, &keep);
        for (k, &c) in cols0.iter().enumerate() {
            stderr[c] = se[k];
        }
        for (i, j, rho) in correlated_pairs(&lin, &keep, 0.95) {
            let (a, b) = (&params[cols0[i]].name, &params[cols0[j]].name);
            correlated.push((a.clone(), b.clone(), rho));
        }
    } else {
        problem.residuals(&theta, &mut r);
        cost = loss.cost(&r, problem.weights());
    }
    let out_params = params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let status = if let Some(v) = &verdict[i] {
                ParamStatus::NotIdentified { reason: v.clone() }
            } else if !free[i] {
                ParamStatus::Fixed
            } else if theta[i] <= p.lower || theta[i] >= p.upper {
                ParamStatus::AtBound
            } else {
                ParamStatus::Fitted
            };
            ParamResult {
                name: p.name.clone(),
                start: theta0[i],
                value: theta[i],
                stderr: stderr[i],
                status,
            }
        })
        .collect();
    Ok(FitOutcome {
        stage: stage.to_string(),
        theta,
        params: out_params,
        initial_cost,
        swarm_cost,
        cost,
        residual_variance,
        correlated,
        n_residuals: m,
        iterations,
        termination,
    })
}

/// A polished candidate.
struct Polished {
    theta: Vec<f64>,
    free: Vec<bool>,
    verdict: Vec<Option<Verdict>>,
    /// Linearisation over the originally free columns at `theta`, if current.
    current: Option<super::lm::Linearisation>,
    iterations: usize,
    termination: Termination,
    cost: f64,
}

/// Identify, polish by LM and re-judge from one start (see `fit_global`).
#[allow(clippy::too_many_arguments)]
fn polish(
    problem: &dyn Problem,
    theta_init: Vec<f64>,
    which: (usize, usize),
    theta0: &[f64],
    free0: &[bool],
    prior: Option<&[Option<Verdict>]>,
    opts: &FitOptions,
    stage: &str,
    mut progress: Option<&mut ProgressFn>,
    ws: &mut Workspace,
) -> crate::Result<Polished> {
    // 2. Identifiability at the LM start, 3. polish, 4. re-judge every
    // originally free parameter at the solution: one whose column was zero
    // only because of where the start was (e.g. a term multiplying a
    // parameter that started at 0) is released, one that lost its effect is
    // reset to its start; repeat until the held set is stable (≤ 5 rounds).
    // While some parameter is held for the first time the LM runs to a loose
    // tolerance (1e-6): its solution is only where the held set is re-judged,
    // and converging the reduced model fully would be wasted work. The last
    // run is always at the caller's tolerances. A `prior` held set (the
    // subsample polish's, from which this start comes) counts as judged
    // before: when the first judgement agrees with it the LM runs at the
    // caller's tolerances at once (one LM start instead of a loose and a
    // strict one, each re-growing its damping from `lambda0`).
    let params = problem.params();
    let n_all = params.len();
    let loss = opts.lm.loss;
    let mut theta = theta_init;
    let mut free = free0.to_vec();
    let mut verdict: Vec<Option<Verdict>> = match prior {
        Some(v) if v.len() == n_all => v.to_vec(),
        _ => vec![None; n_all],
    };
    let judged_before = prior.is_some_and(|v| v.len() == n_all);
    let mut iterations = 0;
    let mut termination = Termination::NoFreeParameters;
    let mut cost = f64::INFINITY;
    let cols0: Vec<usize> = (0..n_all).filter(|&i| free0[i]).collect();
    // Linearisation over cols0 valid at the current θ, if any.
    let mut current: Option<super::lm::Linearisation> = None;
    let mut last_loose = false;
    // The LM's own linearisation at its solution, when it ended on one over
    // all of cols0 (saves evaluating J there again).
    let mut carried: Option<super::lm::Linearisation> = None;
    for round in 0..5 {
        if cols0.is_empty() {
            break;
        }
        let lin = match carried.take() {
            Some(l) => l,
            None => linearise(problem, &theta, &cols0, &loss, ws)?,
        };
        let v = identify(params, &lin, &opts.identify);
        let mut held: Vec<Option<Verdict>> = vec![None; n_all];
        for (k, vk) in v.into_iter().enumerate() {
            if !vk.is_identified() {
                held[cols0[k]] = Some(vk);
            }
        }
        let same = (0..n_all).all(|i| held[i].is_some() == verdict[i].is_some());
        verdict = held;
        if round > 0 && same && !last_loose {
            current = Some(lin);
            break;
        }
        let loose = verdict.iter().any(|v| v.is_some())
            && !((round > 0 || judged_before) && same)
            && round < 4;
        let mut lm_opts = opts.lm.clone();
        if loose {
            lm_opts.ftol = lm_opts.ftol.max(1e-6);
            lm_opts.xtol = lm_opts.xtol.max(1e-6);
            lm_opts.gtol = lm_opts.gtol.max(1e-6);
        }
        last_loose = loose;
        let mut moved = false;
        for &c in &cols0 {
            free[c] = verdict[c].is_none();
            if verdict[c].is_some() && theta[c] != theta0[c] {
                theta[c] = theta0[c];
                moved = true;
            }
        }
        // Reuse the linearisation unless holding a parameter moved θ.
        let keep: Vec<bool> = cols0.iter().map(|&c| free[c]).collect();
        let start_lin = (!moved).then(|| lin.restrict(&keep));
        let max_iter = opts.lm.max_iter;
        let mut cb = |it: usize, c: f64| {
            if let Some(p) = progress.as_mut() {
                p(&Progress {
                    stage,
                    phase: Phase::Polish,
                    iteration: it,
                    max_iterations: max_iter,
                    candidate: which.0,
                    candidates: which.1,
                    cost: c,
                })
            }
        };
        let res = lm::minimize_from(
            problem,
            &theta,
            &free,
            &lm_opts,
            start_lin,
            ws,
            Some(&mut cb),
        )?;
        theta = res.theta;
        super::timing::note(|| {
            format!(
                "      {stage}: LM round {round} on {} rows: cost {:.6e} -> {:.6e}, {} linearisations, {} trial evaluations, {:?}{}",
                problem.n_residuals(),
                res.initial_cost,
                res.cost,
                res.iterations,
                res.residual_evals,
                res.termination,
                if loose { " (loose)" } else { "" }
            )
        });
        iterations += res.iterations;
        termination = res.termination;
        cost = res.cost;
        carried = res.linearisation.filter(|l| l.cols == cols0);
    }

    if cost == f64::INFINITY {
        let mut r = vec![0.0; problem.n_residuals()];
        problem.residuals(&theta, &mut r);
        cost = loss.cost(&r, problem.weights());
    }
    Ok(Polished {
        theta,
        free,
        verdict,
        current,
        iterations,
        termination,
        cost,
    })
}

/// One stage of a staged fit.
pub struct Stage<'a> {
    /// Stage name, for progress and the report.
    pub name: String,
    /// The stage's problem (its own data subset and residual channels).
    pub problem: &'a dyn Problem,
    /// Names of the parameters this stage fits; empty = the problem's `free` flags.
    pub free: Vec<String>,
    /// Settings of this stage's fit.
    pub options: FitOptions,
    /// Problem the swarm runs on (a subsample of `problem`); `None` = `problem`.
    pub swarm_problem: Option<&'a dyn Problem>,
}

/// Parameter values carried between stages, by name, in first-seen order.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ParamValues(pub Vec<(String, f64)>);

impl ParamValues {
    /// The value carried for `name` (exact match), if any.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }
    /// Set the value of `name`, appending it if it is new.
    pub fn set(&mut self, name: &str, value: f64) {
        match self.0.iter_mut().find(|(n, _)| n == name) {
            Some(e) => e.1 = value,
            None => self.0.push((name.to_string(), value)),
        }
    }
}

/// Run `stages` in order. Each stage starts from `values` where they name its
/// parameters (else from its problem's start), fits its free set, and writes
/// its solution back into `values` for the stages after it.
pub fn run_stages(
    stages: &[Stage],
    values: &mut ParamValues,
    mut progress: Option<&mut ProgressFn>,
) -> crate::Result<Vec<FitOutcome>> {
    let mut out = Vec::with_capacity(stages.len());
    for st in stages {
        let params = st.problem.params();
        let start: Vec<f64> = params
            .iter()
            .map(|p| values.get(&p.name).map_or(p.start, |v| p.clamp(v)))
            .collect();
        let free: Vec<bool> = if st.free.is_empty() {
            params.iter().map(|p| p.free).collect()
        } else {
            for n in &st.free {
                if !params.iter().any(|p| &p.name == n) {
                    return Err(crate::Error::Input(format!(
                        "fit stage '{}': unknown parameter '{n}'",
                        st.name
                    )));
                }
            }
            params.iter().map(|p| st.free.contains(&p.name)).collect()
        };
        let res = fit_global(
            st.problem,
            st.swarm_problem,
            Some(&start),
            Some(&free),
            &st.options,
            &st.name,
            progress.as_deref_mut(),
        )?;
        for (p, v) in params.iter().zip(&res.theta) {
            values.set(&p.name, *v);
        }
        out.push(res);
    }
    Ok(out)
}
