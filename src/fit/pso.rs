//! pso — particle swarm optimisation for a global start: a bounded,
//! derivative-free search whose best point the LM then polishes.
//!
//! Global-best swarm with Clerc–Kennedy constriction (inertia 0.7298,
//! acceleration 1.49618 each; Clerc & Kennedy 2002, IEEE Trans. Evol. Comput.
//! 6(1)), the variant used for tyre-model identification in the heavy-truck
//! literature (e.g. PSO-based MF identification from flat-track data).
//! Positions leaving the box are clamped to it and that velocity component
//! is zeroed (absorbing walls).
//!
//! Must never: draw from an unseeded generator (a fixed seed gives the same
//! result on every run and machine: ChaCha8 is platform independent), or
//! evaluate outside the bounds.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Swarm settings.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PsoOptions {
    /// Swarm size (at least 1 is used).
    pub particles: usize,
    /// Maximum number of swarm iterations (each evaluates every particle once).
    pub iterations: usize,
    /// Seed of the ChaCha8 generator: the same seed gives the same result
    /// on every run and machine.
    pub seed: u64,
    /// Velocity weight χ (Clerc–Kennedy constriction: 0.7298).
    pub inertia: f64,
    /// Acceleration towards the particle's own best (χ·c₁: 1.49618).
    pub cognitive: f64,
    /// Acceleration towards the swarm's best (χ·c₂: 1.49618).
    pub social: f64,
    /// Largest velocity component, as a fraction of the box width.
    pub vmax_fraction: f64,
    /// Stop after this many iterations without improving the best cost by
    /// more than `1e-12 × |best|` (0 = never stop early).
    pub patience: usize,
    /// How many of the swarm's best distinct points the fit polishes by LM
    /// (the given start is always polished too; the lowest final cost wins).
    pub polish: usize,
}

impl Default for PsoOptions {
    fn default() -> Self {
        PsoOptions {
            particles: 30,
            iterations: 150,
            seed: 0x7e5e_d00d,
            inertia: 0.7298,
            cognitive: 1.49618,
            social: 1.49618,
            vmax_fraction: 0.5,
            patience: 40,
            polish: 2,
        }
    }
}

/// Best point found.
#[derive(Clone, Debug, PartialEq)]
pub struct PsoResult {
    /// Best point (the swarm's global best), in the box.
    pub x: Vec<f64>,
    /// The particles' personal bests with a finite cost, best first, without
    /// duplicates (`candidates[0] == x` unless no point had a finite cost).
    pub candidates: Vec<Vec<f64>>,
    /// Cost at `x` (+∞ if no point had a finite cost).
    pub cost: f64,
    /// Number of cost evaluations, the initial swarm's included.
    pub evaluations: usize,
    /// Iterations run (fewer than [`PsoOptions::iterations`] when
    /// `patience` stopped the swarm).
    pub iterations: usize,
}

/// Minimise `cost` over the box [lower, upper] (finite, lower < upper or equal).
/// If `x0` is given it seeds particle 0, so the swarm never ends worse than
/// the start. Non-finite costs count as +∞. `progress(iteration, best)`
/// is called after every iteration.
pub fn minimize(
    lower: &[f64],
    upper: &[f64],
    x0: Option<&[f64]>,
    mut cost: impl FnMut(&[f64]) -> f64,
    opts: &PsoOptions,
    mut progress: Option<&mut dyn FnMut(usize, f64)>,
) -> crate::Result<PsoResult> {
    let n = lower.len();
    if upper.len() != n || x0.is_some_and(|x| x.len() != n) {
        return Err(crate::Error::Input(
            "pso: bounds and start differ in length".into(),
        ));
    }
    for k in 0..n {
        if !(lower[k].is_finite() && upper[k].is_finite() && lower[k] <= upper[k]) {
            return Err(crate::Error::Input(format!(
                "pso: the swarm needs finite bounds; dimension {k} has [{}, {}]",
                lower[k], upper[k]
            )));
        }
    }
    let np = opts.particles.max(1);
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let width: Vec<f64> = (0..n).map(|k| upper[k] - lower[k]).collect();
    let vmax: Vec<f64> = width.iter().map(|w| w * opts.vmax_fraction).collect();
    let mut x = vec![vec![0.0; n]; np];
    let mut v = vec![vec![0.0; n]; np];
    for p in 0..np {
        for k in 0..n {
            x[p][k] = lower[k] + width[k] * rng.gen::<f64>();
            v[p][k] = (2.0 * rng.gen::<f64>() - 1.0) * 0.1 * width[k];
        }
    }
    if let Some(x0) = x0 {
        for k in 0..n {
            x[0][k] = x0[k].max(lower[k]).min(upper[k]);
        }
    }
    let eval = |c: f64| if c.is_finite() { c } else { f64::INFINITY };
    let mut pbest = x.clone();
    let mut pcost: Vec<f64> = x.iter().map(|xi| eval(cost(xi))).collect();
    let mut evaluations = np;
    let mut g = 0;
    for p in 1..np {
        if pcost[p] < pcost[g] {
            g = p;
        }
    }
    let mut gbest = pbest[g].clone();
    let mut gcost = pcost[g];
    let mut stale = 0;
    let mut iterations = 0;
    for it in 0..opts.iterations {
        iterations = it + 1;
        let before = gcost;
        for p in 0..np {
            for k in 0..n {
                let (r1, r2): (f64, f64) = (rng.gen(), rng.gen());
                let vk = opts.inertia * v[p][k]
                    + opts.cognitive * r1 * (pbest[p][k] - x[p][k])
                    + opts.social * r2 * (gbest[k] - x[p][k]);
                let vk = vk.max(-vmax[k]).min(vmax[k]);
                let mut xk = x[p][k] + vk;
                let mut vk2 = vk;
                if xk < lower[k] {
                    xk = lower[k];
                    vk2 = 0.0;
                } else if xk > upper[k] {
                    xk = upper[k];
                    vk2 = 0.0;
                }
                x[p][k] = xk;
                v[p][k] = vk2;
            }
            let c = eval(cost(&x[p]));
            evaluations += 1;
            if c < pcost[p] {
                pcost[p] = c;
                pbest[p].copy_from_slice(&x[p]);
                if c < gcost {
                    gcost = c;
                    gbest.copy_from_slice(&x[p]);
                }
            }
        }
        if let Some(pr) = progress.as_mut() {
            pr(iterations, gcost);
        }
        if before - gcost > 1e-12 * before.abs() {
            stale = 0;
        } else {
            stale += 1;
            if opts.patience > 0 && stale >= opts.patience {
                break;
            }
        }
    }
    let mut order: Vec<usize> = (0..np).collect();
    order.sort_by(|&a, &b| pcost[a].total_cmp(&pcost[b]).then(a.cmp(&b)));
    let mut candidates: Vec<Vec<f64>> = Vec::new();
    if gcost.is_finite() {
        candidates.push(gbest.clone());
    }
    for p in order {
        if pcost[p].is_finite() && !candidates.iter().any(|c| c == &pbest[p]) {
            candidates.push(pbest[p].clone());
        }
    }
    Ok(PsoResult {
        candidates,
        x: gbest,
        cost: gcost,
        evaluations,
        iterations,
    })
}
