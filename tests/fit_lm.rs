//! Levenberg–Marquardt on problems with known answers: Rosenbrock, an
//! exponential decay, a sine-atan (Magic-Formula-like) curve, bounds, robust
//! loss, determinism.

use crate::fit_support;
use fit_support::*;
use nalgebra::DMatrixViewMut;
use tyrekit::fit::{fit, lm, FitOptions, LmOptions, Loss, LossKind, Param, ParamStatus, Problem};

/// Rosenbrock as least squares: r = (10(y − x²), 1 − x), minimum 0 at (1, 1).
struct Rosenbrock(Vec<Param>);
impl Problem for Rosenbrock {
    fn params(&self) -> &[Param] {
        &self.0
    }
    fn n_residuals(&self) -> usize {
        2
    }
    fn residuals(&self, t: &[f64], r: &mut [f64]) {
        r[0] = 10.0 * (t[1] - t[0] * t[0]);
        r[1] = 1.0 - t[0];
    }
    fn jacobian(&self, t: &[f64], cols: &[usize], r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        self.residuals(t, r);
        let full = [[-20.0 * t[0], 10.0], [-1.0, 0.0]];
        for (k, &c) in cols.iter().enumerate() {
            jac[(0, k)] = full[0][c];
            jac[(1, k)] = full[1][c];
        }
    }
}

#[test]
fn rosenbrock_from_bad_starts() {
    for start in [[-1.2, 1.0], [-3.0, -4.0], [5.0, 30.0]] {
        let p = Rosenbrock(vec![
            Param::unbounded("x", start[0]),
            Param::unbounded("y", start[1]),
        ]);
        let res = lm::minimize(&p, &start, &[true, true], &LmOptions::default(), None).unwrap();
        // The minimum is exact (zero residual); LM converges quadratically there,
        // so 1e-8 is loose against the 1e-10 step tolerance.
        assert!(
            (res.theta[0] - 1.0).abs() < 1e-8,
            "{start:?} → {:?}",
            res.theta
        );
        assert!(
            (res.theta[1] - 1.0).abs() < 1e-8,
            "{start:?} → {:?}",
            res.theta
        );
        assert!(res.cost < 1e-20);
        assert!(res.termination.converged());
    }
}

#[test]
fn exponential_decay_from_bad_start() {
    let truth = [5.0, 1.3, 0.5];
    let x = linspace(0.0, 5.0, 60);
    let y: Vec<f64> = x.iter().map(|&x| exp_model(&truth, x)).collect();
    let p = Curve::new(
        vec![
            Param::unbounded("a", 1.0),
            Param::new("b", 0.01, 0.0, 100.0),
            Param::unbounded("c", 0.0),
        ],
        x,
        y,
        exp_model,
        exp_grad,
    );
    let out = fit(&p, None, None, &FitOptions::default(), "exp", None).unwrap();
    // Noise-free data: the truth is the exact zero-cost solution.
    for (v, t) in out.theta.iter().zip(truth) {
        assert!((v - t).abs() < 1e-8, "{:?}", out.theta);
    }
    assert!(out.cost < 1e-20);
}

#[test]
fn sine_atan_from_bad_start() {
    // θ = [B, C, D]: a Magic-Formula-shaped curve, peak D, shape C, stiffness B·C·D.
    let truth = [8.0, 1.5, 1.2];
    let x = linspace(-0.3, 0.3, 121);
    let y: Vec<f64> = x.iter().map(|&x| sinatan_model(&truth, x)).collect();
    let p = Curve::new(
        vec![
            Param::new("B", 2.0, 0.1, 50.0),
            Param::new("C", 1.1, 1.0, 2.0),
            Param::new("D", 0.3, 0.01, 10.0),
        ],
        x,
        y,
        sinatan_model,
        sinatan_grad,
    );
    let out = fit(&p, None, None, &FitOptions::default(), "sinatan", None).unwrap();
    for (v, t) in out.theta.iter().zip(truth) {
        assert!((v - t).abs() < 1e-7 * t, "{:?}", out.theta);
    }
}

#[test]
fn bounds_are_respected_and_reported() {
    // Truth a = 5 but a ≤ 4: the solution sits on the bound; no evaluation outside.
    let truth = [5.0, 1.3, 0.5];
    let x = linspace(0.0, 5.0, 60);
    let y: Vec<f64> = x.iter().map(|&x| exp_model(&truth, x)).collect();
    let p = Curve::new(
        vec![
            Param::new("a", 1.0, 0.0, 4.0),
            Param::new("b", 3.0, 0.5, 3.0),
            Param::new("c", 0.0, -1.0, 1.0),
        ],
        x,
        y,
        exp_model,
        exp_grad,
    );
    let out = fit(&p, None, None, &FitOptions::default(), "bounded", None).unwrap();
    assert_eq!(out.theta[0], 4.0);
    assert_eq!(out.params[0].status, ParamStatus::AtBound);
    for th in p.seen.borrow().iter() {
        for (v, q) in th.iter().zip(&p.params) {
            assert!(
                *v >= q.lower && *v <= q.upper,
                "evaluated outside bounds: {th:?}"
            );
        }
    }
    // With a held at 4 the remaining two are a proper optimum: the gradient
    // of the cost wrt b and c vanishes (checked by the LM gradient test), and
    // the cost is above zero because the truth is unreachable.
    assert!(out.cost > 1e-3);
    assert!(matches!(out.params[1].status, ParamStatus::Fitted));
}

#[test]
fn start_outside_bounds_is_an_error_not_a_panic() {
    let p = Curve::new(
        vec![Param::new("a", 5.0, 0.0, 1.0), Param::unbounded("b", 0.0)],
        vec![0.0, 1.0],
        vec![0.0, 1.0],
        line_model,
        line_grad,
    );
    assert!(fit(&p, None, None, &FitOptions::default(), "bad", None).is_err());
}

fn outlier_line() -> Curve {
    // y = 2 + 3x + small noise (±0.05), every 10th point shifted by +20.
    let n = 200;
    let x = linspace(0.0, 10.0, n);
    let e = noise(n, 7);
    let y: Vec<f64> = (0..n)
        .map(|i| 2.0 + 3.0 * x[i] + 0.05 * e[i] + if i % 10 == 3 { 20.0 } else { 0.0 })
        .collect();
    Curve::new(
        vec![Param::unbounded("a", 0.0), Param::unbounded("b", 0.0)],
        x,
        y,
        line_model,
        line_grad,
    )
}

#[test]
fn huber_resists_ten_percent_outliers() {
    let p = outlier_line();
    let ls = fit(&p, None, None, &FitOptions::default(), "ls", None).unwrap();
    // Least squares absorbs the +20 outliers into the intercept: a ≈ 2 + 0.1·20 = 4.
    assert!(
        (ls.theta[0] - 2.0).abs() > 1.0,
        "LS should be pulled off: {:?}",
        ls.theta
    );
    for kind in [LossKind::Huber, LossKind::SoftL1, LossKind::Cauchy] {
        let mut o = FitOptions::default();
        // scale 0.1: twice the noise amplitude, far below the outliers.
        o.lm.loss = Loss::new(kind, 0.1);
        let rb = fit(&p, None, None, &o, "robust", None).unwrap();
        // Huber's linear tails still give each outlier a bounded pull of
        // c = 0.1 per point (20 of 200) → bias ≲ 0.1·20/180 ≈ 0.011 in a;
        // 0.05 leaves room for the noise.
        assert!((rb.theta[0] - 2.0).abs() < 0.05, "{kind:?}: {:?}", rb.theta);
        assert!((rb.theta[1] - 3.0).abs() < 0.01, "{kind:?}: {:?}", rb.theta);
    }
}

#[test]
fn fits_are_bit_reproducible() {
    let p = outlier_line();
    let mut o = FitOptions::default();
    o.lm.loss = Loss::new(LossKind::Cauchy, 0.1);
    let a = fit(&p, None, None, &o, "x", None).unwrap();
    let b = fit(&p, None, None, &o, "x", None).unwrap();
    assert_eq!(a.theta, b.theta);
    assert_eq!(a.cost.to_bits(), b.cost.to_bits());
}

#[test]
fn weights_change_the_fit_as_expected() {
    // Two inconsistent observations of a constant: y = 0 (weight 3) and y = 4
    // (weight 1). The weighted mean is (3·0 + 1·4)/4 = 1.
    let mut p = Curve::new(
        vec![
            Param::unbounded("a", 10.0),
            Param::unbounded("b", 0.0).fixed(),
        ],
        vec![0.0, 0.0],
        vec![0.0, 4.0],
        line_model,
        line_grad,
    );
    p.w = Some(vec![3.0, 1.0]);
    // Stop on the gradient only: |g|/√(A·Σωr²) ≤ gtol = 1e-10 bounds the error
    // by gtol·√(Σωr²/A) = 1e-10·√(12/4) ≈ 1.7e-10.
    let mut o = FitOptions::default();
    o.lm.ftol = 0.0;
    o.lm.xtol = 0.0;
    let out = fit(&p, None, None, &o, "w", None).unwrap();
    assert!((out.theta[0] - 1.0).abs() < 2e-10, "{out:?}");
    assert_eq!(out.params[1].status, ParamStatus::Fixed);
    // cost = ½(3·1² + 1·3²) = 6
    assert!((out.cost - 6.0).abs() < 1e-10);
}

#[test]
fn steps_into_undefined_region_are_rejected_not_fatal() {
    // y = ln(a)·x is undefined for a ≤ 0 (NaN). From a = 10 towards the truth
    // a = 0.05 the full Gauss–Newton step overshoots below zero; such trial
    // points must be rejected (cost = ∞) and the damping raised.
    let x = linspace(0.1, 1.0, 10);
    let y: Vec<f64> = x.iter().map(|&x| 0.05f64.ln() * x).collect();
    let p = Curve::new(
        vec![
            Param::unbounded("a", 10.0),
            Param::unbounded("b", 0.0).fixed(),
        ],
        x,
        y,
        |t, x| t[0].ln() * x,
        |t, x, g| {
            g[0] = x / t[0];
            g[1] = 0.0;
        },
    );
    let out = fit(&p, None, None, &FitOptions::default(), "ln", None).unwrap();
    assert!((out.theta[0] - 0.05).abs() < 1e-9, "{:?}", out.theta);
    // and it did try an undefined point on the way (otherwise the test proves nothing)
    assert!(p.seen.borrow().iter().any(|t| t[0] <= 0.0));
}

/// Residual `i` of the noise floor shared by the LM stop tests: fixed
/// values in ±0.05 the parameters cannot change.
fn noise_floor(i: usize) -> f64 {
    0.05 * (((i * 7919) % 101) as f64 / 50.0 - 1.0)
}

/// Rosenbrock's two residuals, then m − 2 constants (the noise floor).
struct Noisy(Rosenbrock, usize);
impl Problem for Noisy {
    fn params(&self) -> &[Param] {
        self.0.params()
    }
    fn n_residuals(&self) -> usize {
        self.1
    }
    fn residuals(&self, t: &[f64], r: &mut [f64]) {
        self.0.residuals(t, &mut r[..2]);
        for (i, x) in r.iter_mut().enumerate().skip(2) {
            *x = noise_floor(i);
        }
    }
    fn jacobian(&self, t: &[f64], cols: &[usize], r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        self.residuals(t, r);
        jac.fill(0.0);
        let mut top = jac.rows_mut(0, 2);
        self.0.jacobian(t, cols, &mut r[..2], &mut top);
    }
}

/// [`Noisy`] Rosenbrock of `m` residuals with unbounded x, y at `start`.
fn noisy_rosenbrock(m: usize, start: [f64; 2]) -> Noisy {
    Noisy(
        Rosenbrock(vec![
            Param::unbounded("x", start[0]),
            Param::unbounded("y", start[1]),
        ]),
        m,
    )
}

/// Rosenbrock's valley under a noise floor: m − 2 residuals the parameters
/// cannot change (noise). With `dchi2` the LM stops once a step changes χ²
/// (σ² = 2·cost/m) by less than `dchi2`: what is left to gain must then be a
/// small fraction of one unit of χ², reached in fewer iterations than
/// without the rule; `dchi2 = 0` is the default and changes nothing.
#[test]
fn dchi2_stops_statistically_negligible_steps() {
    let m = 2000;
    let start = [-1.2, 1.0];
    let p = noisy_rosenbrock(m, start);
    let run = |dchi2: f64| {
        let o = LmOptions {
            dchi2,
            ..LmOptions::default()
        };
        lm::minimize(&p, &start, &[true, true], &o, None).unwrap()
    };
    let exact = run(0.0);
    let default = lm::minimize(&p, &start, &[true, true], &LmOptions::default(), None).unwrap();
    assert_eq!(exact.theta, default.theta);
    assert_eq!(exact.iterations, default.iterations);
    // The floor: the noise residuals alone (Rosenbrock's part is 0 at (1, 1)).
    let floor = exact.cost;
    assert!((exact.theta[0] - 1.0).abs() < 1e-6, "{:?}", exact.theta);
    let quick = run(1e-3);
    let left_chi2 = (quick.cost - floor) * m as f64 / floor;
    assert!(
        (0.0..0.01).contains(&left_chi2),
        "Δχ² left {left_chi2:e} ({:?} after {} iterations)",
        quick.theta,
        quick.iterations
    );
    assert!(
        quick.iterations < exact.iterations,
        "{} vs {}",
        quick.iterations,
        exact.iterations
    );
    assert_eq!(quick.termination, lm::Termination::Cost);
}

/// A descent toward a minimum at infinity under a noise floor: residual
/// 10·e^(−x) (each Gauss–Newton step moves x by 1 and removes 86 % of what
/// is left), then m − 1 constants. Every step is accepted and gains less
/// than the last, so `ftol` (1e-12 of the cost) stops it only after many.
struct Fading(Vec<Param>, usize);

impl Problem for Fading {
    fn params(&self) -> &[Param] {
        &self.0
    }
    fn n_residuals(&self) -> usize {
        self.1
    }
    fn residuals(&self, t: &[f64], r: &mut [f64]) {
        r[0] = 10.0 * (-t[0]).exp();
        for (i, x) in r.iter_mut().enumerate().skip(1) {
            *x = noise_floor(i);
        }
    }
    fn jacobian(&self, t: &[f64], _: &[usize], r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        self.residuals(t, r);
        jac.fill(0.0);
        jac[(0, 0)] = -10.0 * (-t[0]).exp();
    }
}

/// The stall rule stops the creeping descent of [`Fading`]: with
/// `stall = (5, 1e-3)` the LM stops `Stalled` in fewer iterations than
/// without it, and what is left to gain is below the share the rule
/// tolerates (1e-3 of the cost: the gains of such a descent shrink, so the
/// rest is less than the last five steps gained). Without `stall` nothing
/// changes.
#[test]
fn stall_stops_a_creeping_descent() {
    let p = Fading(vec![Param::unbounded("x", 0.0)], 2000);
    let run = |stall: Option<(usize, f64)>| {
        let o = LmOptions {
            stall,
            ..LmOptions::default()
        };
        lm::minimize(&p, &[0.0], &[true], &o, None).unwrap()
    };
    let exact = run(None);
    let default = lm::minimize(&p, &[0.0], &[true], &LmOptions::default(), None).unwrap();
    assert_eq!(exact.theta, default.theta);
    assert_eq!(exact.iterations, default.iterations);
    let quick = run(Some((5, 1e-3)));
    assert_eq!(quick.termination, lm::Termination::Stalled);
    assert!(
        quick.iterations < exact.iterations,
        "{} vs {}",
        quick.iterations,
        exact.iterations
    );
    let left = (quick.cost - exact.cost) / quick.cost;
    assert!(
        (0.0..1e-3).contains(&left),
        "left {left:e} at {:?}",
        quick.theta
    );
}
