//! lm — bounded Levenberg–Marquardt with Marquardt scaling, trust-region
//! style damping updates and IRLS robust weights.
//!
//! Why not the `levenberg-marquardt` crate (MINPACK port, already a
//! dependency)? Checked against v0.15: it has no bounds, no per-residual or
//! IRLS weights, asks the problem for a freshly allocated m×n Jacobian every
//! iteration and QR-factorises the whole m×n matrix; it also exposes no Gram
//! matrix for standard errors and the identifiability test. For m = 100 000
//! residuals and n ≈ 25 parameters the normal equations are the better
//! trade: JᵀWJ (n×n) is accumulated block by block — a problem offering
//! [`Problem::row_jacobian`] fills 128-row blocks that are multiplied into
//! the upper triangle while in L1, on its threads, in fixed 2048-row chunks
//! handed to whichever thread is free and summed in chunk order (so the
//! result does not depend on the thread count), and the m×n J is never
//! stored; other problems write J into a
//! buffer allocated once per fit — and everything after it is n×n work.
//! The normal equations square
//! the condition number, which is acceptable here because collinear or
//! inert parameters are removed first (see `identify`) and the damping
//! keeps the system positive definite.
//!
//! Algorithm (Marquardt 1963; Moré 1978 for the scaling; Nielsen 1999 for the
//! damping update; bounds by projection with an active set, as in Kanzow,
//! Yamashita & Fukushima 2004, "Levenberg–Marquardt methods with strong local
//! convergence properties for solving nonlinear equations with convex
//! constraints"):
//! 1. linearise at θ: r, J; IRLS weights ωᵢ = wᵢ ρ'(zᵢ); A = JᵀΩJ, g = JᵀΩr;
//! 2. active set: a parameter on a bound whose gradient pushes it outward is
//!    held this iteration;
//! 3. solve (A + λ·diag(D)) δ = −g on the rest, D the running maximum of
//!    diag(A) (Marquardt scaling, MINPACK style);
//! 4. project θ+δ into the box, accept if the actual cost reduction is a
//!    positive fraction of the one the quadratic model predicts for the
//!    projected step; update λ by the gain ratio (Nielsen). With λ ≤ 1e-2
//!    the trial point is linearised at once (its cost comes with it; one
//!    residual pass saved per accepted step);
//! 5. stop when the nearly undamped (λ ≤ 1e-3) step's predicted gain is
//!    below `ftol`·cost: that step is still taken if it lowers the cost
//!    (one residual pass), and the last linearisation is handed to the
//!    caller (identifiability, standard errors) instead of another J at a
//!    point one negligible step away. The cost reported is always θ's own,
//!    on all residuals. Also: actual and predicted reductions of an
//!    accepted step both below `ftol`, scaled step below `xtol`, scaled
//!    gradient below `gtol`; and, with `dchi2` > 0, both reductions below
//!    `dchi2`·cost/m (statistically negligible steps, see [`LmOptions::dchi2`]);
//!    with `stall`, the last few accepted steps together below a share of
//!    the cost (a creeping descent, see [`LmOptions::stall`]).
//!
//! Must never: step outside the bounds, use randomness or wall-clock time
//! (results are bit-reproducible), or panic on a non-finite residual (a
//! trial step producing one is rejected as if its cost were infinite).
// Index loops over several parallel per-parameter arrays read clearer than zips.
#![allow(clippy::needless_range_loop)]

use super::loss::Loss;
use super::problem::Problem;
use nalgebra::{DMatrix, DMatrixViewMut, DVector};

/// Stopping criteria and loss of one LM run.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LmOptions {
    /// Maximum number of Jacobian evaluations (outer iterations).
    pub max_iter: usize,
    /// Stop when both actual and predicted relative cost reductions are below this.
    pub ftol: f64,
    /// Stop when the scaled step is below this relative to the scaled θ.
    pub xtol: f64,
    /// Stop when the largest cosine between the residual and a free Jacobian column is below this.
    pub gtol: f64,
    /// Initial damping, relative to the Marquardt scaling (dimensionless).
    /// Madsen, Nielsen & Tingleff, *Methods for non-linear least squares
    /// problems* (2004), §3.2: small (1e-6) when the start is believed close
    /// to the solution, up to 1 otherwise. The default 1e-2 is for starts
    /// from another tyre: with 1e-3 the first, nearly Gauss–Newton step of
    /// the benchmark's pure-Fy fit (`tyrekit bench fit`) was projected onto
    /// the PEY1 ≤ 1 bound and the fit ended in a worse local minimum
    /// (cost 1.42e8 against 1.03e8 at the truth); with 1e-2 it reaches the
    /// truth's basin in fewer iterations.
    pub lambda0: f64,
    /// Loss function (plain least squares by default).
    pub loss: Loss,
    /// Stop when a step changes χ² by less than this (0: off). With the
    /// residual variance estimated from the fit itself (σ² = 2·cost/m for m
    /// residuals), a cost reduction Δ is a change of χ² by Δ·m/cost; a step
    /// changing χ² by less than `dchi2` moves θ by less than √dchi2
    /// standard errors along any direction (Δχ² = 1 is one standard error
    /// of one parameter; Press et al., *Numerical Recipes*, 3rd ed., §15.6).
    /// Residuals of test recordings are correlated over many samples, so m
    /// overstates the independent observations and the bound is
    /// conservative. What it stops: a curved, flat valley the LM descends
    /// in many tiny damped steps, each above `ftol` (`tyrekit fit` on dev-set
    /// r05, stage Mx: 187 full-data iterations that lowered the cost by
    /// 1e-5 of it, Δχ² 0.26 in all, 90 % of the stage's time). Along a
    /// valley of collinear parameters such steps barely change the fit but
    /// can change extrapolation: keep it small (see
    /// `fit::mf_fit::STAGED_DCHI2`).
    #[serde(default)]
    pub dchi2: f64,
    /// Stop when the last `stall.0` accepted steps together lowered the
    /// cost by less than `stall.1` of it (None: off). What `ftol` and
    /// `dchi2` cannot stop: a slow descent whose every step is above both
    /// (each moves θ by a standard error or more, judged with m residuals
    /// that are in fact correlated over many samples) yet the whole walk
    /// changes the fit by nothing a figure shows. Measured on the
    /// benchmark's 250 Hz rig recording (`tyrekit bench fit`): the combined
    /// stage's full-data polish took 53 iterations and 147 of the fit's
    /// 170 s to lower the cost by 1.2e-4 of it. A stop rule, not a budget:
    /// a descent that still gains (dev-set r03, pure Fy: 15 % of the cost
    /// over 72 iterations) runs on. See `fit::mf_fit::STAGED_STALL`.
    #[serde(default)]
    pub stall: Option<(usize, f64)>,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iter: 200,
            ftol: 1e-12,
            xtol: 1e-10,
            gtol: 1e-10,
            lambda0: 1e-2,
            loss: Loss::default(),
            dchi2: 0.0,
            stall: None,
        }
    }
}

/// Why an LM run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Termination {
    /// Projected gradient below `gtol`.
    Gradient,
    /// Step below `xtol`.
    Step,
    /// Relative cost reduction below `ftol`.
    Cost,
    /// `max_iter` reached.
    MaxIterations,
    /// The last accepted steps together gained less than
    /// [`LmOptions::stall`] allows.
    Stalled,
    /// The damping grew without finding a better point (a minimum to machine precision).
    NoProgress,
    /// Nothing to fit.
    NoFreeParameters,
}

impl Termination {
    /// Whether the run converged (anything but running out of iterations).
    pub fn converged(&self) -> bool {
        !matches!(self, Termination::MaxIterations)
    }
}

/// Result of one LM run.
#[derive(Clone, Debug)]
pub struct LmResult {
    /// Solution (all parameters, θ order).
    pub theta: Vec<f64>,
    /// Cost ½Σ c²ρ(w r²/c²) at the start.
    pub initial_cost: f64,
    /// Cost at the solution.
    pub cost: f64,
    /// Outer iterations (accepted linearisations, the start's included).
    pub iterations: usize,
    /// Trial steps evaluated (by residuals, or by a linearisation at the
    /// trial point when the step is nearly undamped).
    pub residual_evals: usize,
    /// Why the run stopped.
    pub termination: Termination,
    /// The last linearisation over the free columns, when it is at `theta`
    /// or one final step of predicted gain ≤ ftol·cost away from it (the
    /// run's last step, taken without linearising again): good for
    /// identifiability and standard errors at the solution, and saves the
    /// caller an evaluation of J. Its `cost` is that of its own point.
    pub linearisation: Option<Linearisation>,
}

/// The problem linearised at θ over the columns `cols`: the weighted Gram
/// matrix A = JᵀΩJ, gradient g = JᵀΩr, the cost and Σωr².
#[derive(Clone, Debug)]
pub struct Linearisation {
    /// Parameter indices (θ order) of the linearised columns.
    pub cols: Vec<usize>,
    /// Weighted Gram matrix A = JᵀΩJ over `cols` (symmetric, n×n).
    pub a: DMatrix<f64>,
    /// Weighted gradient g = JᵀΩr over `cols`.
    pub g: DVector<f64>,
    /// Cost ½Σ c²ρ(w r²/c²) at the linearisation point.
    pub cost: f64,
    /// Σ ωᵢ rᵢ² with the IRLS weights ω (= 2·cost for plain least squares).
    pub wrss: f64,
    /// Number of residuals m.
    pub m: usize,
}

impl Linearisation {
    /// The same linearisation restricted to a subset of its columns
    /// (`keep[k]` for column k), e.g. after holding unidentified parameters.
    pub fn restrict(&self, keep: &[bool]) -> Linearisation {
        let idx: Vec<usize> = (0..self.cols.len()).filter(|&k| keep[k]).collect();
        Linearisation {
            cols: idx.iter().map(|&k| self.cols[k]).collect(),
            a: DMatrix::from_fn(idx.len(), idx.len(), |i, j| self.a[(idx[i], idx[j])]),
            g: DVector::from_fn(idx.len(), |i, _| self.g[idx[i]]),
            cost: self.cost,
            wrss: self.wrss,
            m: self.m,
        }
    }
}

/// Reusable buffers (allocated once per fit, never per iteration).
pub struct Workspace {
    r: Vec<f64>,
    r_trial: Vec<f64>,
    sw: Vec<f64>,
    /// Column-major Jacobian storage, m × (largest column count so far);
    /// a fit with fewer columns uses its leading part (no reallocation).
    jac: Vec<f64>,
}

impl Workspace {
    /// Buffers for `m` residuals and up to `n` Jacobian columns.
    pub fn new(m: usize, n: usize) -> Workspace {
        Workspace {
            r: vec![0.0; m],
            r_trial: vec![0.0; m],
            sw: vec![0.0; m],
            jac: vec![0.0; m * n],
        }
    }

    fn ensure_cols(&mut self, k: usize) {
        let need = self.r.len() * k;
        if self.jac.len() < need {
            self.jac.resize(need, 0.0);
        }
    }
}

/// Dot product with four independent accumulators (lets the compiler
/// vectorise; the summation order is fixed, so results are reproducible).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let ca = a.chunks_exact(4);
    let cb = b.chunks_exact(4);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// Four dot products of `a` with `b[0..4]`, each over four interleaved
/// accumulators (row i → accumulator i mod 4) combined as (0 + 1) + (2 + 3):
/// a fixed summation order, so the result is reproducible and the same for
/// whichever instruction set [`gram_add`] compiled it for.
#[inline(always)]
fn dot4(a: &[f64], b: [&[f64]; 4]) -> [f64; 4] {
    let n = a.len();
    let (b0, b1, b2, b3) = (&b[0][..n], &b[1][..n], &b[2][..n], &b[3][..n]);
    let mut acc = [[0.0f64; 4]; 4];
    let n4 = n / 4 * 4;
    for (((x, y0), (y1, y2)), y3) in a[..n4]
        .chunks_exact(4)
        .zip(b0[..n4].chunks_exact(4))
        .zip(b1[..n4].chunks_exact(4).zip(b2[..n4].chunks_exact(4)))
        .zip(b3[..n4].chunks_exact(4))
    {
        for j in 0..4 {
            acc[0][j] += x[j] * y0[j];
            acc[1][j] += x[j] * y1[j];
            acc[2][j] += x[j] * y2[j];
            acc[3][j] += x[j] * y3[j];
        }
    }
    let mut out = [0.0; 4];
    for l in 0..4 {
        out[l] = (acc[l][0] + acc[l][1]) + (acc[l][2] + acc[l][3]);
        for i in n4..n {
            out[l] += a[i] * b[l][i];
        }
    }
    out
}

/// A = JᵀJ and g = Jᵀr for a column-major m×k `jac`: only the upper
/// triangle is computed (then mirrored), over row blocks small enough that
/// the k column pieces stay in cache while all k(k+1)/2 products are taken.
/// Half the products of `jac.tr_mul(&jac)`, four columns per pass over a
/// column piece, no m-sized temporaries: ≈ 4.8 ms against 8.5 ms for
/// `tr_mul` at m = 100 000, k = 18 on the project machine.
pub fn gram(jac: &DMatrix<f64>, r: &[f64], a: &mut DMatrix<f64>, g: &mut DVector<f64>) {
    let (m, k) = jac.shape();
    gram_slice(jac.as_slice(), m, k, r, a, g);
}

/// [`gram`] on raw column-major storage (`data.len() ≥ m·k`).
fn gram_slice(
    data: &[f64],
    m: usize,
    k: usize,
    r: &[f64],
    a: &mut DMatrix<f64>,
    g: &mut DVector<f64>,
) {
    a.fill(0.0);
    g.fill(0.0);
    gram_add(data, m, k, r, a, g);
    mirror_upper(a);
}

/// Copy the upper triangle of `a` into the lower.
fn mirror_upper(a: &mut DMatrix<f64>) {
    for p in 0..a.ncols() {
        for q in 0..p {
            a[(p, q)] = a[(q, p)];
        }
    }
}

/// Add JᵀJ (upper triangle only) and Jᵀr of a column-major m×k `data` to
/// `a` and `g`, over row blocks small enough that the k column pieces stay
/// in cache while all k(k+1)/2 products are taken.
#[inline(always)]
fn gram_add_impl(
    data: &[f64],
    m: usize,
    k: usize,
    r: &[f64],
    a: &mut DMatrix<f64>,
    g: &mut DVector<f64>,
) {
    const BLOCK: usize = 2048;
    let mut start = 0;
    while start < m {
        let end = (start + BLOCK).min(m);
        let col = |q: usize| &data[q * m + start..q * m + end];
        for p in 0..k {
            let cp = col(p);
            // Four columns against cp at a time: cp is loaded once per four products.
            let mut q = p;
            while q + 4 <= k {
                let d = dot4(cp, [col(q), col(q + 1), col(q + 2), col(q + 3)]);
                for (l, v) in d.iter().enumerate() {
                    a[(p, q + l)] += v;
                }
                q += 4;
            }
            while q < k {
                a[(p, q)] += dot(cp, col(q));
                q += 1;
            }
            g[p] += dot(cp, &r[start..end]);
        }
        start = end;
    }
}

/// [`gram_add_impl`], compiled for AVX2 when the CPU has it (4-wide
/// vectors instead of SSE2's 2; no FMA, and the kernels fix the summation
/// order, so the result has the same bits either way).
fn gram_add(
    data: &[f64],
    m: usize,
    k: usize,
    r: &[f64],
    a: &mut DMatrix<f64>,
    g: &mut DVector<f64>,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        unsafe { gram_add_avx2(data, m, k, r, a, g) };
        return;
    }
    gram_add_impl(data, m, k, r, a, g)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gram_add_avx2(
    data: &[f64],
    m: usize,
    k: usize,
    r: &[f64],
    a: &mut DMatrix<f64>,
    g: &mut DVector<f64>,
) {
    gram_add_impl(data, m, k, r, a, g)
}

/// Rows per chunk of the blocked linearisation ([`linearise_rows`]): fixed,
/// not per thread, so the chunks' partial sums, added in chunk order, are
/// the same whatever the thread count (bit-reproducible results). Small
/// enough that the 3 000-sample start races of the num-dual stages
/// (`mf_stages::RACE_SAMPLES`, ≈ 3 µs per Mz row) split over two cores;
/// each chunk's partial JᵀJ (k × k) costs nothing beside its 2 048 rows.
const CHUNK_ROWS: usize = 2048;
/// Rows per Jacobian block within a chunk: a 128 × 30 block (30 kB) stays in
/// L1 between being written and being multiplied.
const BLOCK_ROWS: usize = 128;

/// One chunk's share of the linearisation.
struct Partial {
    a: DMatrix<f64>,
    g: DVector<f64>,
    cost: f64,
    wrss: f64,
}

/// The linearisation by row blocks of a [`RowJacobian`]: each block's r and
/// J are computed into a small buffer, weighted by √ω (IRLS), and their
/// upper-triangle JᵀJ and Jᵀr added to the chunk's partial; the chunks are
/// handed out one at a time to `threads` scoped threads (whichever is free
/// takes the next) and their partials summed in chunk order. The m × k
/// Jacobian is never stored.
///
/// Handing chunks out one at a time, not in contiguous halves: a stacked
/// problem's rows cost unequal amounts (the combined stage's Mz rows, last in
/// the stack, cost several times its Fx rows), and with halves the thread
/// holding the Mz rows did ≈ 80 % of the work while the other waited. Which
/// thread computes a chunk does not change its partial, and the partials are
/// still added in chunk order: the result is bit-identical to the serial one.
#[allow(clippy::too_many_arguments)]
fn linearise_rows(
    rows: &dyn super::problem::RowJacobian,
    m: usize,
    k: usize,
    w: Option<&[f64]>,
    loss: &Loss,
    threads: usize,
) -> (DMatrix<f64>, DVector<f64>, f64, f64) {
    let unit = w.is_none() && loss.kind == super::loss::LossKind::Linear;
    let n_chunks = m.div_ceil(CHUNK_ROWS).max(1);
    // One chunk's partial, computed block by block in row order.
    let chunk = |ci: usize, r: &mut [f64], jac: &mut [f64]| -> Partial {
        let mut part = Partial {
            a: DMatrix::zeros(k, k),
            g: DVector::zeros(k),
            cost: 0.0,
            wrss: 0.0,
        };
        let chunk_start = ci * CHUNK_ROWS;
        let chunk_end = (chunk_start + CHUNK_ROWS).min(m);
        let mut b0 = chunk_start;
        while b0 < chunk_end {
            let nb = BLOCK_ROWS.min(chunk_end - b0);
            let (rb, jb) = (&mut r[..nb], &mut jac[..nb * k]);
            rows.rows(b0, rb, &mut DMatrixViewMut::from_slice(jb, nb, k));
            for i in 0..nb {
                let (c, om) = loss.cost_and_weight(rb[i], w.map_or(1.0, |w| w[b0 + i]));
                part.cost += c;
                part.wrss += om * rb[i] * rb[i];
                if !unit {
                    let s = om.sqrt();
                    rb[i] *= s;
                    for j in 0..k {
                        jb[j * nb + i] *= s;
                    }
                }
            }
            gram_add(jb, nb, k, rb, &mut part.a, &mut part.g);
            b0 += nb;
        }
        part
    };
    // Take chunks from the shared counter until none is left.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let work = || -> Vec<(usize, Partial)> {
        let mut r = vec![0.0; BLOCK_ROWS];
        let mut jac = vec![0.0; BLOCK_ROWS * k];
        let mut done = Vec::new();
        loop {
            let ci = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            if ci >= n_chunks {
                return done;
            }
            done.push((ci, chunk(ci, &mut r, &mut jac)));
        }
    };
    let threads = threads.clamp(1, n_chunks);
    let mut slots: Vec<Option<Partial>> = (0..n_chunks).map(|_| None).collect();
    let mut place = |done: Vec<(usize, Partial)>| {
        for (ci, p) in done {
            slots[ci] = Some(p);
        }
    };
    if threads == 1 {
        place(work());
    } else {
        std::thread::scope(|s| {
            let others: Vec<_> = (1..threads).map(|_| s.spawn(work)).collect();
            place(work());
            for h in others {
                // A panic in a worker is re-raised here, as the serial
                // path would raise it.
                match h.join() {
                    Ok(done) => place(done),
                    Err(e) => std::panic::resume_unwind(e),
                }
            }
        });
    }
    let parts = slots.into_iter().map(|p| p.expect("every chunk computed"));
    let mut a = DMatrix::zeros(k, k);
    let mut g = DVector::zeros(k);
    let (mut cost, mut wrss) = (0.0, 0.0);
    for p in parts {
        a += &p.a;
        g += &p.g;
        cost += p.cost;
        wrss += p.wrss;
    }
    mirror_upper(&mut a);
    (a, g, cost, wrss)
}

/// Robust cost of a residual vector (∞ if any residual is not finite).
fn cost_of(loss: &Loss, r: &[f64], w: Option<&[f64]>) -> f64 {
    let c = loss.cost(r, w);
    if c.is_finite() {
        c
    } else {
        f64::INFINITY
    }
}

/// The linearisation through [`Problem::jacobian`]: the whole m × k
/// Jacobian into the workspace, then one blocked product.
fn linearise_full(
    problem: &dyn Problem,
    theta: &[f64],
    cols: &[usize],
    loss: &Loss,
    ws: &mut Workspace,
) -> (DMatrix<f64>, DVector<f64>, f64, f64) {
    let m = problem.n_residuals();
    let k = cols.len();
    if ws.r.len() != m {
        *ws = Workspace::new(m, 0);
    }
    ws.ensure_cols(k);
    problem.jacobian(
        theta,
        cols,
        &mut ws.r,
        &mut DMatrixViewMut::from_slice(&mut ws.jac[..m * k], m, k),
    );
    let w = problem.weights();
    let mut cost = 0.0;
    let mut wrss = 0.0;
    for i in 0..m {
        let (c, om) = loss.cost_and_weight(ws.r[i], w.map_or(1.0, |w| w[i]));
        cost += c;
        wrss += om * ws.r[i] * ws.r[i];
        ws.sw[i] = om.sqrt();
    }
    // Row scaling by √ω (skipped when every ω is 1: plain, unweighted LS).
    let unit = w.is_none() && loss.kind == super::loss::LossKind::Linear;
    if unit {
        ws.r_trial.copy_from_slice(&ws.r);
    } else {
        for j in 0..k {
            let col = &mut ws.jac[j * m..(j + 1) * m];
            for (x, s) in col.iter_mut().zip(&ws.sw) {
                *x *= s;
            }
        }
        for i in 0..m {
            ws.r_trial[i] = ws.r[i] * ws.sw[i];
        }
    }
    let mut a = DMatrix::zeros(k, k);
    let mut g = DVector::zeros(k);
    gram_slice(&ws.jac, m, k, &ws.r_trial, &mut a, &mut g);
    (a, g, cost, wrss)
}

/// Linearise `problem` at `theta` over `cols` (see [`Linearisation`]).
pub fn linearise(
    problem: &dyn Problem,
    theta: &[f64],
    cols: &[usize],
    loss: &Loss,
    ws: &mut Workspace,
) -> crate::Result<Linearisation> {
    let m = problem.n_residuals();
    let k = cols.len();
    let w = problem.weights();
    let (a, g, cost, wrss) = match problem.row_jacobian(theta, cols) {
        Some(rows) => linearise_rows(rows.as_ref(), m, k, w, loss, problem.threads()),
        None => linearise_full(problem, theta, cols, loss, ws),
    };
    if !cost.is_finite() {
        return Err(crate::Error::Numeric(
            "fit: the residuals are not finite at the current parameters".into(),
        ));
    }
    // A non-finite Jacobian entry makes its column's diagonal non-finite.
    if (0..k).any(|j| !a[(j, j)].is_finite() || !g[j].is_finite()) {
        return Err(crate::Error::Numeric(
            "fit: the Jacobian is not finite at the current parameters".into(),
        ));
    }
    Ok(Linearisation {
        cols: cols.to_vec(),
        a,
        g,
        cost,
        wrss,
        m,
    })
}

/// Minimise the problem over the parameters with `free[i]` true, starting at
/// `theta0` (which must lie within the bounds). `progress(iteration, cost)` is
/// called after every outer iteration.
pub fn minimize(
    problem: &dyn Problem,
    theta0: &[f64],
    free: &[bool],
    opts: &LmOptions,
    progress: Option<&mut dyn FnMut(usize, f64)>,
) -> crate::Result<LmResult> {
    let m = problem.n_residuals();
    minimize_from(
        problem,
        theta0,
        free,
        opts,
        None,
        &mut Workspace::new(m, 0),
        progress,
    )
}

/// [`minimize`] with a caller-owned workspace and, optionally, the
/// linearisation at `theta0` over exactly the free columns (saves one
/// Jacobian evaluation when the caller already has it).
pub fn minimize_from(
    problem: &dyn Problem,
    theta0: &[f64],
    free: &[bool],
    opts: &LmOptions,
    start: Option<Linearisation>,
    ws: &mut Workspace,
    mut progress: Option<&mut dyn FnMut(usize, f64)>,
) -> crate::Result<LmResult> {
    super::problem::validate(problem, theta0)?;
    if free.len() != theta0.len() {
        return Err(crate::Error::Input(format!(
            "fit: free mask of length {} for {} parameters",
            free.len(),
            theta0.len()
        )));
    }
    let params = problem.params();
    let cols: Vec<usize> = (0..params.len()).filter(|&i| free[i]).collect();
    let m = problem.n_residuals();
    let n = cols.len();
    let mut theta = theta0.to_vec();
    let w = problem.weights();
    let loss = &opts.loss;
    if ws.r.len() != m {
        *ws = Workspace::new(m, 0);
    }
    if n == 0 || m == 0 {
        problem.residuals(&theta, &mut ws.r);
        let cost = cost_of(loss, &ws.r, w);
        return Ok(LmResult {
            theta,
            initial_cost: cost,
            cost,
            iterations: 0,
            residual_evals: 1,
            termination: Termination::NoFreeParameters,
            linearisation: None,
        });
    }
    let lower: Vec<f64> = cols.iter().map(|&c| params[c].lower).collect();
    let upper: Vec<f64> = cols.iter().map(|&c| params[c].upper).collect();

    let mut lin = match start {
        Some(l) if l.cols == cols && l.m == m => l,
        _ => linearise(problem, &theta, &cols, loss, ws)?,
    };
    let initial_cost = lin.cost;
    let mut cost = lin.cost;
    let mut diag = vec![0.0f64; n];
    let mut lambda = opts.lambda0;
    let mut nu = 2.0;
    let mut iterations = 0;
    let mut residual_evals = 0;
    let mut trial = theta.clone();
    let mut mat = DMatrix::<f64>::zeros(n, n);
    let mut rhs = DVector::<f64>::zeros(n);
    let mut active = vec![false; n];
    // Whether `lin` is at `theta` (false only after a final accepted step),
    // or one last step of gain below ftol away from it.
    let mut lin_at_theta = true;
    let mut lin_near_theta = false;
    // Cost after each of the last `stall.0` accepted steps (a ring).
    let stall_window = opts.stall.map_or(0, |s| s.0);
    let mut after = vec![f64::NAN; stall_window];
    let mut accepted = 0usize;

    let termination = 'outer: loop {
        iterations += 1;
        // Active set: on a bound with the descent direction (−g) pointing out.
        for k in 0..n {
            let v = theta[cols[k]];
            let g = lin.g[k];
            active[k] = (v <= lower[k] && g > 0.0) || (v >= upper[k] && g < 0.0);
        }
        // Gradient test (scaled: cosine between residual and each free column).
        let mut gmax = 0.0f64;
        for k in 0..n {
            if !active[k] && lin.a[(k, k)] > 0.0 && lin.wrss > 0.0 {
                gmax = gmax.max(lin.g[k].abs() / (lin.a[(k, k)] * lin.wrss).sqrt());
            }
        }
        if gmax <= opts.gtol {
            break Termination::Gradient;
        }
        let amax = (0..n).map(|k| lin.a[(k, k)]).fold(0.0, f64::max);
        for k in 0..n {
            diag[k] = diag[k]
                .max(lin.a[(k, k)])
                .max(1e-12 * amax)
                .max(f64::MIN_POSITIVE);
        }
        // Inner loop: find an acceptable damped step.
        loop {
            mat.copy_from(&lin.a);
            for k in 0..n {
                if active[k] {
                    for j in 0..n {
                        mat[(k, j)] = 0.0;
                        mat[(j, k)] = 0.0;
                    }
                    mat[(k, k)] = 1.0;
                    rhs[k] = 0.0;
                } else {
                    mat[(k, k)] += lambda * diag[k];
                    rhs[k] = -lin.g[k];
                }
            }
            let step = match mat.clone().cholesky() {
                Some(ch) => ch.solve(&rhs),
                None => {
                    lambda *= nu;
                    nu *= 2.0;
                    if lambda > 1e16 {
                        break 'outer Termination::NoProgress;
                    }
                    continue;
                }
            };
            // Projected step s.
            trial.copy_from_slice(&theta);
            let mut s = DVector::<f64>::zeros(n);
            for k in 0..n {
                let c = cols[k];
                let v = (theta[c] + step[k]).max(lower[k]).min(upper[k]);
                trial[c] = v;
                s[k] = v - theta[c];
            }
            // Predicted reduction of the quadratic model for s.
            let pred = -(lin.g.dot(&s) + 0.5 * s.dot(&(&lin.a * &s)));
            // Nearly undamped (λ ≤ 1e-3: the step is the Gauss–Newton step
            // to 0.1 %) and the model predicts a gain below ftol: θ is the
            // minimum to that tolerance. Take this last step if it lowers the
            // cost (one residual evaluation) and stop without linearising
            // again: the last linearisation is one step of negligible
            // predicted gain away, good for the caller's standard errors.
            let tol = (opts.ftol * cost).max(opts.dchi2 * cost / m as f64);
            let last = lambda <= 1e-3 && (0.0..=tol).contains(&pred);
            let mut dx = 0.0;
            let mut xn = 0.0;
            for k in 0..n {
                dx += diag[k] * s[k] * s[k];
                xn += diag[k] * theta[cols[k]] * theta[cols[k]];
            }
            let (dx, xn) = (dx.sqrt(), xn.sqrt());
            // Little damped (λ ≤ 1e-2), the step is usually accepted: then linearise
            // at the trial point at once (its cost comes with it), saving
            // the separate residual evaluation. A trial whose residuals or
            // Jacobian are not finite counts as infinitely costly.
            let fused = !last && lambda <= 1e-2;
            let mut trial_lin = None;
            let new_cost = if fused {
                match linearise(problem, &trial, &cols, loss, ws) {
                    Ok(l) => {
                        let c = l.cost;
                        trial_lin = Some(l);
                        c
                    }
                    Err(_) => f64::INFINITY,
                }
            } else {
                problem.residuals(&trial, &mut ws.r_trial);
                cost_of(loss, &ws.r_trial, w)
            };
            residual_evals += 1;
            let actual = cost - new_cost;
            if last {
                if actual > 0.0 {
                    theta.copy_from_slice(&trial);
                    cost = new_cost;
                }
                lin_near_theta = true;
                break 'outer Termination::Cost;
            }
            let rho = if pred > 0.0 { actual / pred } else { -1.0 };
            if rho > 1e-4 {
                theta.copy_from_slice(&trial);
                lin_at_theta = false;
                let small_f = actual <= tol && pred <= tol;
                let stalled = match opts.stall {
                    Some((win, rtol)) if win > 0 => {
                        // The gain of the last `win` accepted steps.
                        let ago = after[accepted % win];
                        after[accepted % win] = new_cost;
                        accepted += 1;
                        accepted > win && ago - new_cost <= rtol * new_cost
                    }
                    _ => false,
                };
                cost = new_cost;
                lambda *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
                nu = 2.0;
                if let Some(p) = progress.as_mut() {
                    p(iterations, cost);
                }
                if let Some(l) = trial_lin {
                    lin = l;
                    lin_at_theta = true;
                }
                if small_f {
                    break 'outer Termination::Cost;
                }
                if stalled {
                    break 'outer Termination::Stalled;
                }
                if dx <= opts.xtol * (xn + opts.xtol) {
                    break 'outer Termination::Step;
                }
                if iterations >= opts.max_iter {
                    break 'outer Termination::MaxIterations;
                }
                if !lin_at_theta {
                    lin = linearise(problem, &theta, &cols, loss, ws)?;
                    lin_at_theta = true;
                }
                cost = lin.cost;
                continue 'outer;
            }
            // Rejected: a vanishing step means we are at a minimum to precision.
            if dx <= opts.xtol * (xn + opts.xtol)
                || (pred <= 0.0 && actual <= 0.0 && pred.abs() <= 1e-15 * cost)
            {
                break 'outer Termination::Step;
            }
            lambda *= nu;
            nu *= 2.0;
            if lambda > 1e16 {
                break 'outer Termination::NoProgress;
            }
        }
    };
    if let Some(p) = progress.as_mut() {
        p(iterations, cost);
    }
    Ok(LmResult {
        theta,
        initial_cost,
        cost,
        iterations,
        residual_evals,
        termination,
        linearisation: (lin_at_theta || lin_near_theta).then_some(lin),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked symmetric product against nalgebra's plain JᵀJ on an
    /// awkward shape (rows not a multiple of the block or of 4, 7 columns so
    /// both the 4-wide and the scalar paths run). Summation orders differ, so
    /// agreement is to rounding: 1e-12 relative to the largest entry.
    #[test]
    fn gram_matches_plain_product() {
        let (m, k) = (5003, 7);
        let j = DMatrix::from_fn(m, k, |i, c| ((i * 31 + c * 17) % 97) as f64 / 97.0 - 0.4);
        let r: Vec<f64> = (0..m).map(|i| ((i * 13) % 29) as f64 - 14.0).collect();
        let mut a = DMatrix::zeros(k, k);
        let mut g = DVector::zeros(k);
        gram(&j, &r, &mut a, &mut g);
        let a_ref = j.tr_mul(&j);
        let g_ref = j.tr_mul(&DVector::from_column_slice(&r));
        let amax = a_ref.amax();
        assert!((&a - &a_ref).amax() < 1e-12 * amax);
        assert!((&g - &g_ref).amax() < 1e-12 * g_ref.amax());
        assert_eq!(a, a.transpose());
    }

    /// Rows of a fixed J and r; rows past `slow_from` spin before returning
    /// (the combined stage's costly Mz rows at the end of its stack), so the
    /// threads finish their chunks in an order that differs from run to run.
    struct Rows {
        j: DMatrix<f64>,
        r: Vec<f64>,
        slow_from: usize,
    }

    impl super::super::problem::RowJacobian for Rows {
        fn rows(&self, first: usize, r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
            for (i, ri) in r.iter_mut().enumerate() {
                let row = first + i;
                if row >= self.slow_from {
                    let mut x = 1.0f64;
                    for _ in 0..200 {
                        x = std::hint::black_box(x.sqrt() + 1.0);
                    }
                }
                *ri = self.r[row];
                for c in 0..self.j.ncols() {
                    jac[(i, c)] = self.j[(row, c)];
                }
            }
        }
    }

    /// The blocked linearisation hands chunks to whichever thread is free;
    /// the partials are added in chunk order, so JᵀΩJ, JᵀΩr and the cost are
    /// bit-identical for every thread count (with and without IRLS weights),
    /// and agree with the plain product to rounding.
    #[test]
    fn row_linearisation_is_bit_identical_for_any_thread_count() {
        let (m, k) = (3 * CHUNK_ROWS + 777, 5);
        let j = DMatrix::from_fn(m, k, |i, c| ((i * 37 + c * 11) % 89) as f64 / 89.0 - 0.3);
        let r: Vec<f64> = (0..m).map(|i| ((i * 7) % 31) as f64 / 3.0 - 5.0).collect();
        let rows = Rows {
            j: j.clone(),
            r: r.clone(),
            slow_from: 2 * CHUNK_ROWS,
        };
        let w: Vec<f64> = (0..m).map(|i| 0.5 + (i % 3) as f64).collect();
        for (weights, loss) in [
            (None, Loss::default()),
            (Some(&w[..]), Loss::default()),
            (
                None,
                Loss {
                    kind: super::super::loss::LossKind::Huber,
                    scale: 2.0,
                },
            ),
        ] {
            let one = linearise_rows(&rows, m, k, weights, &loss, 1);
            for t in [2, 3, 8] {
                let many = linearise_rows(&rows, m, k, weights, &loss, t);
                assert_eq!(one.0, many.0, "JᵀΩJ, {t} threads");
                assert_eq!(one.1, many.1, "JᵀΩr, {t} threads");
                assert_eq!(one.2.to_bits(), many.2.to_bits(), "cost, {t} threads");
                assert_eq!(one.3.to_bits(), many.3.to_bits(), "ΩRSS, {t} threads");
            }
            if weights.is_none() && loss.kind == super::super::loss::LossKind::Linear {
                let a_ref = j.tr_mul(&j);
                assert!((&one.0 - &a_ref).amax() < 1e-12 * a_ref.amax());
                let g_ref = j.tr_mul(&DVector::from_column_slice(&r));
                assert!((&one.1 - &g_ref).amax() < 1e-12 * g_ref.amax());
            }
        }
    }
}
