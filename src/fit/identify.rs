//! identify — which free parameters the data can determine, and how well.
//!
//! Works on the weighted Gram matrix A = JᵀΩJ of the linearised problem:
//! - a column whose effect ‖J_j‖·scale_j is negligible next to the largest
//!   one is **no effect** (e.g. camber terms on a zero-camber test, pressure
//!   terms on one pressure: their Jacobian columns are exactly zero);
//! - among the rest, a greedy pivoted Cholesky factorisation of the
//!   column-normalised Gram matrix (the correlation-like matrix
//!   Cᵢⱼ = Aᵢⱼ/√(AᵢᵢAⱼⱼ)) picks parameters in order of how much new
//!   direction they add; when the best remaining one has 1 − R² (its squared
//!   sine to the span of those already picked) below `collinear_tol`, it and
//!   all remaining are **collinear** with parameters already picked
//!   (e.g. two load terms on a single-load test). Ties go to the parameter
//!   listed first, so the problem's order states preference.
//!   This is the rank-revealing factorisation of Golub & Van Loan,
//!   *Matrix Computations*, 4th ed., §5.4.2, applied to JᵀJ.
//!
//! Standard errors are √diag(s²·A⁻¹) over the identified set, with
//! s² = Σωr²/(m − n) the residual variance (Bates & Watts, *Nonlinear
//! Regression Analysis*, §2.3).
//!
//! Must never: decide by randomness, or report a standard error for a
//! parameter that is not identified.
// `!(x > tol)` on purpose: a NaN must fail the test, not pass it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::lm::Linearisation;
use super::problem::Param;
use nalgebra::DMatrix;

/// Thresholds of the identifiability test.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IdentifyOptions {
    /// A column with ‖J_j‖·scale_j ≤ effect_tol × the largest is "no effect".
    pub effect_tol: f64,
    /// A column with squared sine to the span of better columns ≤ this is "collinear".
    /// 1e-10 ↔ an angle of 1e-5 rad, i.e. a correlation of 1 − 5e-11.
    pub collinear_tol: f64,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        IdentifyOptions {
            effect_tol: 1e-8,
            collinear_tol: 1e-10,
        }
    }
}

/// Verdict on one free parameter.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Verdict {
    /// Determined by the data: fitted, with a standard error.
    Identified,
    /// The residuals do not depend on it.
    NoEffect,
    /// Its effect is a combination of these parameters' effects.
    Collinear {
        /// Names of the identified parameters its column regresses on.
        with: Vec<String>,
    },
}

impl Verdict {
    /// Whether the parameter is [`Verdict::Identified`].
    pub fn is_identified(&self) -> bool {
        matches!(self, Verdict::Identified)
    }
}

/// Judge every column of `lin` (parameter indices `lin.cols`).
pub fn identify(params: &[Param], lin: &Linearisation, opts: &IdentifyOptions) -> Vec<Verdict> {
    let n = lin.cols.len();
    let mut verdict = vec![Verdict::Identified; n];
    let effect: Vec<f64> = (0..n)
        .map(|k| lin.a[(k, k)].max(0.0).sqrt() * params[lin.cols[k]].scale())
        .collect();
    let emax = effect.iter().cloned().fold(0.0, f64::max);
    let mut cand: Vec<usize> = Vec::new();
    for k in 0..n {
        if !(effect[k] > opts.effect_tol * emax) {
            verdict[k] = Verdict::NoEffect;
        } else {
            cand.push(k);
        }
    }
    // Normalised Gram of the candidates.
    let nc = cand.len();
    let c = DMatrix::from_fn(nc, nc, |i, j| {
        let (a, b) = (cand[i], cand[j]);
        lin.a[(a, b)] / (lin.a[(a, a)] * lin.a[(b, b)]).sqrt()
    });
    let mut d: Vec<f64> = (0..nc).map(|i| c[(i, i)]).collect();
    let mut l = DMatrix::<f64>::zeros(nc, nc);
    let mut picked: Vec<usize> = Vec::new();
    let mut remaining: Vec<usize> = (0..nc).collect();
    while !remaining.is_empty() {
        // Largest remaining diagonal; ties to the lowest index.
        let (pos, &p) = remaining
            .iter()
            .enumerate()
            .fold(None, |best: Option<(usize, &usize)>, (pos, j)| match best {
                Some((_, b)) if d[*b] >= d[*j] => best,
                _ => Some((pos, j)),
            })
            .expect("non-empty");
        if !(d[p] > opts.collinear_tol) {
            break;
        }
        remaining.remove(pos);
        let t = picked.len();
        let lpp = d[p].sqrt();
        l[(p, t)] = lpp;
        for &j in &remaining {
            let mut s = c[(j, p)];
            for q in 0..t {
                s -= l[(j, q)] * l[(p, q)];
            }
            l[(j, t)] = s / lpp;
            d[j] -= l[(j, t)] * l[(j, t)];
        }
        picked.push(p);
    }
    if !remaining.is_empty() {
        // Regress each collinear column on the picked ones to name its partners.
        let np = picked.len();
        let css = DMatrix::from_fn(np, np, |i, j| c[(picked[i], picked[j])]);
        let chol = css.cholesky();
        for &j in &remaining {
            let with = match &chol {
                Some(ch) => {
                    let rhs = nalgebra::DVector::from_fn(np, |i, _| c[(picked[i], j)]);
                    let beta = ch.solve(&rhs);
                    let bmax = beta.iter().map(|b| b.abs()).fold(0.0, f64::max);
                    (0..np)
                        .filter(|&i| beta[i].abs() > 1e-3 * bmax)
                        .map(|i| params[lin.cols[cand[picked[i]]]].name.clone())
                        .collect()
                }
                None => Vec::new(),
            };
            verdict[cand[j]] = Verdict::Collinear { with };
        }
    }
    verdict
}

/// Standard errors √diag(s²·A⁻¹) of the columns of `lin` marked in `keep`
/// (others get `None`), with s² = Σωr²/(m − n_keep). `None` throughout when
/// there are no degrees of freedom left or A is singular on the kept set.
pub fn standard_errors(lin: &Linearisation, keep: &[bool]) -> Vec<Option<f64>> {
    let idx: Vec<usize> = (0..lin.cols.len()).filter(|&k| keep[k]).collect();
    let n = idx.len();
    let mut out = vec![None; lin.cols.len()];
    if n == 0 || lin.m <= n {
        return out;
    }
    let s2 = lin.wrss / (lin.m - n) as f64;
    let a = DMatrix::from_fn(n, n, |i, j| lin.a[(idx[i], idx[j])]);
    if let Some(ch) = a.cholesky() {
        let inv = ch.inverse();
        for (i, &k) in idx.iter().enumerate() {
            let v = s2 * inv[(i, i)];
            if v.is_finite() && v >= 0.0 {
                out[k] = Some(v.sqrt());
            }
        }
    }
    out
}

/// Pairs of kept columns (indices into `lin.cols`) whose estimates are
/// correlated beyond `threshold` in absolute value, from the correlation
/// matrix of A⁻¹ (the posterior correlation of the estimates). Strong
/// correlation means the data determine mainly a combination of the two:
/// both are identified, but each alone only loosely.
pub fn correlated_pairs(
    lin: &Linearisation,
    keep: &[bool],
    threshold: f64,
) -> Vec<(usize, usize, f64)> {
    let idx: Vec<usize> = (0..lin.cols.len()).filter(|&k| keep[k]).collect();
    let n = idx.len();
    let a = DMatrix::from_fn(n, n, |i, j| lin.a[(idx[i], idx[j])]);
    let Some(ch) = a.cholesky() else {
        return Vec::new();
    };
    let inv = ch.inverse();
    let mut out = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let rho = inv[(i, j)] / (inv[(i, i)] * inv[(j, j)]).sqrt();
            if rho.abs() > threshold {
                out.push((idx[i], idx[j], rho));
            }
        }
    }
    out
}
