//! Identifiability (inert and collinear parameters held at their start) and
//! standard errors against the closed-form linear-regression formulas.

use crate::fit_support;
use fit_support::*;
use tyrekit::fit::{fit, FitOptions, Param, ParamStatus, Verdict};

/// y = a·x + (b + c)·x² + 0·d + e: d has no effect, b and c are collinear.
fn degenerate_model(t: &[f64], x: f64) -> f64 {
    t[0] * x + (t[1] + t[2]) * x * x + t[4]
}
fn degenerate_grad(_t: &[f64], x: f64, g: &mut [f64]) {
    g[0] = x;
    g[1] = x * x;
    g[2] = x * x;
    g[3] = 0.0;
    g[4] = 1.0;
}

#[test]
fn inert_and_collinear_parameters_are_held_and_reported() {
    let x = linspace(-2.0, 3.0, 50);
    // truth: a = 1, b + c = 3, e = 0.5
    let y: Vec<f64> = x.iter().map(|&x| x + 3.0 * x * x + 0.5).collect();
    let p = Curve::new(
        vec![
            Param::unbounded("a", 0.0),
            Param::unbounded("b", 0.5),
            Param::unbounded("c", 0.7),
            Param::new("d", 4.0, -10.0, 10.0),
            Param::unbounded("e", 0.0),
        ],
        x,
        y,
        degenerate_model,
        degenerate_grad,
    );
    let out = fit(&p, None, None, &FitOptions::default(), "degenerate", None).unwrap();
    let st = |n: &str| out.param(n).unwrap().clone();
    // d: no effect, held at its start, no standard error.
    assert_eq!(
        st("d").status,
        ParamStatus::NotIdentified {
            reason: Verdict::NoEffect
        }
    );
    assert_eq!(st("d").value, 4.0);
    assert_eq!(st("d").stderr, None);
    // c: collinear with b (b listed first is kept), held at its start.
    assert_eq!(
        st("c").status,
        ParamStatus::NotIdentified {
            reason: Verdict::Collinear {
                with: vec!["b".to_string()]
            }
        }
    );
    assert_eq!(st("c").value, 0.7);
    // b absorbs the combination: b = 3 − 0.7; noise-free data so exact to solver precision.
    assert!((st("b").value - 2.3).abs() < 1e-9, "{out:?}");
    assert!((st("a").value - 1.0).abs() < 1e-9);
    assert!((st("e").value - 0.5).abs() < 1e-9);
    for n in ["a", "b", "e"] {
        assert_eq!(st(n).status, ParamStatus::Fitted);
    }
    // The verdicts survive fit.json.
    let js = serde_json::to_string(&out).unwrap();
    assert!(js.contains("not_identified"), "{js}");
    let back: tyrekit::fit::FitOutcome = serde_json::from_str(&js).unwrap();
    assert_eq!(back.params, out.params);
    // and the printed table says why
    let t = tyrekit::fit::report::param_table(&out);
    assert!(
        t.contains("not identified (collinear with b)") && t.contains("not identified (no effect)"),
        "{t}"
    );
}

#[test]
fn standard_errors_match_linear_regression_formula() {
    // y = a + b·x + noise: OLS with s² = RSS/(n − 2),
    // se(b) = s/√Sxx, se(a) = s·√(1/n + x̄²/Sxx)  (any regression textbook,
    // e.g. Draper & Smith, Applied Regression Analysis, §1.4).
    let n = 40;
    let x = linspace(1.0, 9.0, n);
    let e = noise(n, 3);
    let y: Vec<f64> = (0..n).map(|i| 1.5 - 0.7 * x[i] + 0.3 * e[i]).collect();
    let p = Curve::new(
        vec![Param::unbounded("a", 0.0), Param::unbounded("b", 0.0)],
        x.clone(),
        y.clone(),
        line_model,
        line_grad,
    );
    let out = fit(&p, None, None, &FitOptions::default(), "ols", None).unwrap();
    // closed-form OLS
    let nf = n as f64;
    let xm = x.iter().sum::<f64>() / nf;
    let ym = y.iter().sum::<f64>() / nf;
    let sxx: f64 = x.iter().map(|v| (v - xm) * (v - xm)).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(u, v)| (u - xm) * (v - ym)).sum();
    let b = sxy / sxx;
    let a = ym - b * xm;
    let rss: f64 = x.iter().zip(&y).map(|(u, v)| (v - a - b * u).powi(2)).sum();
    let s = (rss / (nf - 2.0)).sqrt();
    let se_b = s / sxx.sqrt();
    let se_a = s * (1.0 / nf + xm * xm / sxx).sqrt();
    assert!((out.theta[0] - a).abs() < 1e-9 && (out.theta[1] - b).abs() < 1e-9);
    // Both sides are the same closed form evaluated two ways; 1e-8 relative
    // covers the LM stopping a hair off the exact optimum.
    let se = |k: usize| out.params[k].stderr.unwrap();
    assert!((se(0) - se_a).abs() < 1e-8 * se_a, "{} vs {se_a}", se(0));
    assert!((se(1) - se_b).abs() < 1e-8 * se_b, "{} vs {se_b}", se(1));
    assert!((out.residual_variance - s * s).abs() < 1e-8 * s * s);
}

#[test]
fn strongly_correlated_but_identifiable_parameters_are_fitted() {
    // y = a·x + b·(x + 0.05x²): the columns correlate at ≈ 0.999 but are not
    // collinear (1 − R² ≈ 1e-4 ≫ the 1e-10 threshold), so both must be fitted.
    let x = linspace(0.0, 1.0, 21);
    let y: Vec<f64> = x
        .iter()
        .map(|&x| 2.0 * x - 1.0 * (x + 0.05 * x * x))
        .collect();
    let p = Curve::new(
        vec![Param::unbounded("a", 0.0), Param::unbounded("b", 0.0)],
        x,
        y,
        |t, x| t[0] * x + t[1] * (x + 0.05 * x * x),
        |_t, x, g| {
            g[0] = x;
            g[1] = x + 0.05 * x * x;
        },
    );
    let out = fit(&p, None, None, &FitOptions::default(), "corr", None).unwrap();
    assert_eq!(out.params[0].status, ParamStatus::Fitted);
    assert_eq!(out.params[1].status, ParamStatus::Fitted);
    // noise-free: exact up to the conditioning (cond(JᵀJ) ≈ 1e5) × solver tolerance
    assert!(
        (out.theta[0] - 2.0).abs() < 1e-6 && (out.theta[1] + 1.0).abs() < 1e-6,
        "{:?}",
        out.theta
    );
    // For two parameters the estimates' correlation is minus the columns'
    // cosine: ρ = −Σx·u / √(Σx²·Σu²), u = x + 0.05x² (exact algebra of A⁻¹).
    let x = linspace(0.0, 1.0, 21);
    let u: Vec<f64> = x.iter().map(|&x| x + 0.05 * x * x).collect();
    let sxu: f64 = x.iter().zip(&u).map(|(a, b)| a * b).sum();
    let sxx: f64 = x.iter().map(|a| a * a).sum();
    let suu: f64 = u.iter().map(|a| a * a).sum();
    let rho = -sxu / (sxx * suu).sqrt();
    assert_eq!(out.correlated.len(), 1);
    let (a, b, r) = &out.correlated[0];
    assert_eq!((a.as_str(), b.as_str()), ("a", "b"));
    assert!((r - rho).abs() < 1e-9, "{r} vs {rho}");
}

#[test]
fn parameter_inert_only_at_the_start_is_released_and_fitted() {
    // y = a·exp(b·x) from a = 0: ∂y/∂b = a·x·exp(b·x) is exactly zero at the
    // start, so b looks inert there; once a is fitted it is not, and b must be
    // fitted too (the MF has such products, e.g. PEY3 multiplies PEY1).
    let x = linspace(0.0, 2.0, 30);
    let y: Vec<f64> = x.iter().map(|&x| 2.0 * (0.5 * x).exp()).collect();
    let p = Curve::new(
        vec![Param::unbounded("a", 0.0), Param::new("b", 0.0, -3.0, 3.0)],
        x,
        y,
        |t, x| t[0] * (t[1] * x).exp(),
        |t, x, g| {
            g[0] = (t[1] * x).exp();
            g[1] = t[0] * x * (t[1] * x).exp();
        },
    );
    let out = fit(&p, None, None, &FitOptions::default(), "released", None).unwrap();
    assert_eq!(out.params[1].status, ParamStatus::Fitted, "{out:?}");
    // noise-free: the truth to solver precision
    assert!(
        (out.theta[0] - 2.0).abs() < 1e-8 && (out.theta[1] - 0.5).abs() < 1e-8,
        "{:?}",
        out.theta
    );
}
