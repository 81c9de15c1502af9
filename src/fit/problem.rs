//! problem — the interface between a model and the fitter: named, bounded
//! parameters, a residual vector r(θ) and its exact Jacobian J(θ).
//!
//! Must never: know anything about tyres (the Magic Formula stages implement
//! [`Problem`] elsewhere), or approximate a Jacobian by finite differences
//! behind the caller's back.
// `!(a <= b)` on purpose: NaN bounds must be refused.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::DMatrixViewMut;

/// One model parameter as the fitter sees it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Param {
    /// Name (for the MF: the lower-case `.tir` key, e.g. `pdy1`).
    pub name: String,
    /// Start value (also the value an unidentifiable parameter is held at).
    pub start: f64,
    /// Lower bound (may be `-inf`).
    pub lower: f64,
    /// Upper bound (may be `+inf`).
    pub upper: f64,
    /// Whether the fitter may move it.
    pub free: bool,
}

impl Param {
    /// A free parameter with bounds.
    pub fn new(name: &str, start: f64, lower: f64, upper: f64) -> Param {
        Param {
            name: name.to_string(),
            start,
            lower,
            upper,
            free: true,
        }
    }

    /// A free parameter without bounds.
    pub fn unbounded(name: &str, start: f64) -> Param {
        Param::new(name, start, f64::NEG_INFINITY, f64::INFINITY)
    }

    /// The same parameter held fixed.
    pub fn fixed(mut self) -> Param {
        self.free = false;
        self
    }

    /// A typical magnitude of the parameter, used to judge whether its
    /// Jacobian column is "zero": the box width when both bounds are finite,
    /// else `max(|start|, 1)`.
    pub fn scale(&self) -> f64 {
        let w = self.upper - self.lower;
        if w.is_finite() && w > 0.0 {
            w
        } else {
            self.start.abs().max(1.0)
        }
    }

    /// Clamp a value into the bounds.
    pub fn clamp(&self, v: f64) -> f64 {
        v.max(self.lower).min(self.upper)
    }
}

/// A least-squares problem: minimise ½ Σ wᵢ ρ(rᵢ(θ)²) over the free parameters.
///
/// Residuals are `model − data` (sign does not matter to the fitter but does
/// to the reports). θ always has one entry per [`Problem::params`] entry,
/// free or not, in that order.
///
/// Implementations should not allocate per residual; the fitter calls
/// [`Problem::residuals`] for every trial step and [`Problem::jacobian`]
/// once per accepted step.
pub trait Problem {
    /// All parameters, in θ order.
    fn params(&self) -> &[Param];

    /// Number of residuals m.
    fn n_residuals(&self) -> usize;

    /// Write r(θ) into `r` (length m).
    fn residuals(&self, theta: &[f64], r: &mut [f64]);

    /// Write r(θ) into `r` and ∂r/∂θ for parameter `cols[k]` into column k of `jac`
    /// (m × cols.len(), column-major; a view, so several problems can be
    /// stacked into one matrix, see [`Stack`]). Only the listed columns are asked
    /// for, so a forward-mode AD implementation seeds only those.
    /// The derivatives must be exact (analytic or AD).
    fn jacobian(&self, theta: &[f64], cols: &[usize], r: &mut [f64], jac: &mut DMatrixViewMut<f64>);

    /// Optional per-residual weights wᵢ ≥ 0 (length m), e.g. 1/σᵢ² of the
    /// channel. `None` means all ones.
    fn weights(&self) -> Option<&[f64]> {
        None
    }

    /// Optional: the linearisation at θ over `cols` row block by row block
    /// ([`RowJacobian`]), so the fitter can accumulate JᵀΩJ and JᵀΩr block
    /// by block on [`Problem::threads`] threads without holding the m × n
    /// Jacobian. `None` (the default): the fitter calls [`Problem::jacobian`].
    fn row_jacobian<'s>(
        &'s self,
        _theta: &[f64],
        _cols: &[usize],
    ) -> Option<Box<dyn RowJacobian + 's>> {
        None
    }

    /// Threads the fitter may use for [`Problem::row_jacobian`] blocks.
    fn threads(&self) -> usize {
        1
    }
}

/// A problem's Jacobian at one θ, prepared once ([`Problem::row_jacobian`])
/// and evaluated by row blocks, possibly from several threads.
pub trait RowJacobian: Sync {
    /// r and ∂r/∂θ for the rows `first..first + r.len()`: column k of `jac`
    /// (r.len() × cols.len(), column-major) ↔ `cols[k]`. Every row must be
    /// computed exactly as [`Problem::jacobian`] computes it.
    fn rows(&self, first: usize, r: &mut [f64], jac: &mut DMatrixViewMut<f64>);
}

/// Check a problem's parameter table and a θ against it: finite starts, lower
/// ≤ start ≤ upper, unique names, θ of the right length.
pub fn validate(problem: &dyn Problem, theta: &[f64]) -> crate::Result<()> {
    let params = problem.params();
    if theta.len() != params.len() {
        return Err(crate::Error::Input(format!(
            "fit: {} parameter values given, the problem has {} parameters",
            theta.len(),
            params.len()
        )));
    }
    for (i, (p, &v)) in params.iter().zip(theta).enumerate() {
        if !(p.lower <= p.upper) || p.lower.is_nan() || p.upper.is_nan() {
            return Err(crate::Error::Input(format!(
                "fit: parameter '{}': bounds [{}, {}] are not an interval",
                p.name, p.lower, p.upper
            )));
        }
        if !v.is_finite() || v < p.lower || v > p.upper {
            return Err(crate::Error::Input(format!(
                "fit: parameter '{}': value {} is not finite or outside its bounds [{}, {}]",
                p.name, v, p.lower, p.upper
            )));
        }
        if params[..i].iter().any(|q| q.name == p.name) {
            return Err(crate::Error::Input(format!(
                "fit: parameter name '{}' appears twice",
                p.name
            )));
        }
    }
    if let Some(w) = problem.weights() {
        if w.len() != problem.n_residuals() {
            return Err(crate::Error::Input(format!(
                "fit: {} weights for {} residuals",
                w.len(),
                problem.n_residuals()
            )));
        }
        if let Some(i) = w.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
            return Err(crate::Error::Input(format!(
                "fit: weight {i} is {} (must be finite and ≥ 0)",
                w[i]
            )));
        }
    }
    Ok(())
}

/// Several problems over the same parameter table fitted together, e.g. Fy
/// and Mz of a pure-lateral stage: residuals are concatenated and each
/// part's weights (1 where it has none) multiplied by its factor (typically
/// 1/σ² of its channel, so newtons and newton-metres compare).
pub struct Stack<'a> {
    parts: Vec<(&'a dyn Problem, f64)>,
    weights: Option<Vec<f64>>,
    m: usize,
}

impl<'a> Stack<'a> {
    /// Stack `parts` (problem, weight factor ≥ 0). All must have the same
    /// parameter names in the same order; bounds and start come from the first.
    pub fn new(parts: Vec<(&'a dyn Problem, f64)>) -> crate::Result<Stack<'a>> {
        let first = parts
            .first()
            .ok_or_else(|| crate::Error::Input("fit: nothing to stack".into()))?
            .0;
        for (k, (p, f)) in parts.iter().enumerate() {
            let same = p.params().len() == first.params().len()
                && p.params()
                    .iter()
                    .zip(first.params())
                    .all(|(a, b)| a.name == b.name);
            if !same {
                return Err(crate::Error::Input(format!(
                    "fit: stacked problem {k} has a different parameter table"
                )));
            }
            if !(f.is_finite() && *f >= 0.0) {
                return Err(crate::Error::Input(format!(
                    "fit: stacked problem {k}: weight factor {f} (must be finite and ≥ 0)"
                )));
            }
        }
        let m = parts.iter().map(|(p, _)| p.n_residuals()).sum();
        let plain = parts
            .iter()
            .all(|(p, f)| *f == 1.0 && p.weights().is_none());
        let weights = (!plain).then(|| {
            let mut w = Vec::with_capacity(m);
            for (p, f) in &parts {
                match p.weights() {
                    Some(pw) => w.extend(pw.iter().map(|x| x * f)),
                    None => w.extend(std::iter::repeat_n(*f, p.n_residuals())),
                }
            }
            w
        });
        Ok(Stack { parts, weights, m })
    }
}

impl Problem for Stack<'_> {
    fn params(&self) -> &[Param] {
        self.parts[0].0.params()
    }
    fn n_residuals(&self) -> usize {
        self.m
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        let mut off = 0;
        for (p, _) in &self.parts {
            let n = p.n_residuals();
            p.residuals(theta, &mut r[off..off + n]);
            off += n;
        }
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        let mut off = 0;
        for (p, _) in &self.parts {
            let n = p.n_residuals();
            p.jacobian(theta, cols, &mut r[off..off + n], &mut jac.rows_mut(off, n));
            off += n;
        }
    }
    fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    fn row_jacobian<'s>(
        &'s self,
        theta: &[f64],
        cols: &[usize],
    ) -> Option<Box<dyn RowJacobian + 's>> {
        let mut parts = Vec::with_capacity(self.parts.len());
        let mut off = 0;
        for (p, _) in &self.parts {
            parts.push((off, p.row_jacobian(theta, cols)?));
            off += p.n_residuals();
        }
        parts.push((off, Box::new(NoRows)));
        Some(Box::new(StackRows(parts)))
    }
    fn threads(&self) -> usize {
        self.parts
            .iter()
            .map(|(p, _)| p.threads())
            .max()
            .unwrap_or(1)
    }
}

/// The end marker of [`StackRows`] (never asked for rows).
struct NoRows;

impl RowJacobian for NoRows {
    fn rows(&self, _first: usize, _r: &mut [f64], _jac: &mut DMatrixViewMut<f64>) {}
}

/// The parts' row Jacobians of a [`Stack`] as (first row, part), in order,
/// ending with the total row count; a block spanning parts is split.
struct StackRows<'s>(Vec<(usize, Box<dyn RowJacobian + 's>)>);

impl RowJacobian for StackRows<'_> {
    fn rows(&self, first: usize, r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        let end = first + r.len();
        for w in self.0.windows(2) {
            let (a, b) = (w[0].0.max(first), w[1].0.min(end));
            if a < b {
                w[0].1.rows(
                    a - w[0].0,
                    &mut r[a - first..b - first],
                    &mut jac.rows_mut(a - first, b - a),
                );
            }
        }
    }
}

/// Rows per block below which [`par_rows`] does not split further.
const PAR_MIN_ROWS: usize = 4096;

/// Fill a row-separable problem's residuals (and Jacobian) on up to
/// `threads` scoped threads: rows are cut into contiguous blocks and
/// `f(first_row, r_block, jac_block)` fills each block. Every row is computed
/// exactly as it would be serially, so results do not depend on `threads`.
/// A helper for [`Problem`] implementations (the fitter itself stays serial).
pub fn par_rows<F>(
    threads: usize,
    first: usize,
    r: &mut [f64],
    jac: Option<&mut DMatrixViewMut<f64>>,
    f: &F,
) where
    F: Fn(usize, &mut [f64], Option<&mut DMatrixViewMut<f64>>) + Sync,
{
    let m = r.len();
    if threads <= 1 || m < 2 * PAR_MIN_ROWS {
        f(first, r, jac);
        return;
    }
    let left_threads = threads / 2;
    let mid = m * left_threads / threads;
    let (r1, r2) = r.split_at_mut(mid);
    match jac {
        Some(j) => {
            let (mut j1, mut j2) = j.rows_range_pair_mut(0..mid, mid..m);
            std::thread::scope(|s| {
                s.spawn(|| par_rows(left_threads, first, r1, Some(&mut j1), f));
                par_rows(threads - left_threads, first + mid, r2, Some(&mut j2), f);
            });
        }
        None => {
            std::thread::scope(|s| {
                s.spawn(|| par_rows(left_threads, first, r1, None, f));
                par_rows(threads - left_threads, first + mid, r2, None, f);
            });
        }
    }
}
