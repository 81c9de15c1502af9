//! Staged fits pass their solution on by name; each stage fits only its own set.

use crate::fit_support;
use fit_support::*;
use tyrekit::fit::{run_stages, FitOptions, Param, ParamStatus, ParamValues, Stage};

fn line(x: Vec<f64>, a0: f64, b0: f64) -> Curve {
    let y: Vec<f64> = x.iter().map(|&x| 2.0 + 3.0 * x).collect();
    Curve::new(
        vec![Param::unbounded("a", a0), Param::unbounded("b", b0)],
        x,
        y,
        line_model,
        line_grad,
    )
}

#[test]
fn stages_pass_values_on() {
    // Stage 1 sees only x = 0 (determines a), stage 2 the full line but only b is free:
    // b comes out right only if stage 2 starts from stage 1's a.
    let s1 = line(vec![0.0; 5], 0.0, 0.0);
    let s2 = line(linspace(-1.0, 1.0, 9), 0.0, 0.0);
    let stages = [
        Stage {
            name: "intercept".into(),
            problem: &s1,
            free: vec!["a".into()],
            options: FitOptions::default(),
            swarm_problem: None,
        },
        Stage {
            name: "slope".into(),
            problem: &s2,
            free: vec!["b".into()],
            options: FitOptions::default(),
            swarm_problem: None,
        },
    ];
    let mut values = ParamValues::default();
    let out = run_stages(&stages, &mut values, None).unwrap();
    assert_eq!(out.len(), 2);
    assert!((values.get("a").unwrap() - 2.0).abs() < 1e-9);
    assert!((values.get("b").unwrap() - 3.0).abs() < 1e-9);
    assert_eq!(out[0].param("b").unwrap().status, ParamStatus::Fixed);
    assert_eq!(out[1].param("a").unwrap().status, ParamStatus::Fixed);
    assert_eq!(out[1].param("a").unwrap().start, out[0].value("a").unwrap());
}

#[test]
fn unknown_stage_parameter_is_an_error() {
    let s1 = line(vec![0.0, 1.0], 0.0, 0.0);
    let stages = [Stage {
        name: "x".into(),
        problem: &s1,
        free: vec!["pdy1".into()],
        options: FitOptions::default(),
        swarm_problem: None,
    }];
    let e = run_stages(&stages, &mut ParamValues::default(), None).unwrap_err();
    assert!(e.to_string().contains("pdy1"), "{e}");
}

#[test]
fn stacked_problems_fit_jointly_with_their_weight_factors() {
    use tyrekit::fit::{fit, Stack};
    // Part A: y = 1 + 2x on x = 0, 1. Part B: the points (2, 5), (3, 9): off the
    // line by +0, +2. Weighted LS over the four points with factors wA, wB
    // has the closed form below; with wB = 0 it is A's exact line.
    let a = Curve::new(
        vec![Param::unbounded("a", 0.0), Param::unbounded("b", 0.0)],
        vec![0.0, 1.0],
        vec![1.0, 3.0],
        line_model,
        line_grad,
    );
    let b = Curve::new(
        vec![Param::unbounded("a", 0.0), Param::unbounded("b", 0.0)],
        vec![2.0, 3.0],
        vec![5.0, 9.0],
        line_model,
        line_grad,
    );
    let only_a = Stack::new(vec![(&a, 1.0), (&b, 0.0)]).unwrap();
    let o = fit(&only_a, None, None, &FitOptions::default(), "a", None).unwrap();
    assert!(
        (o.theta[0] - 1.0).abs() < 1e-9 && (o.theta[1] - 2.0).abs() < 1e-9,
        "{:?}",
        o.theta
    );
    // Weights (1, 1, 2, 2) on x = (0, 1, 2, 3), y = (1, 3, 5, 9):
    // Σw = 6, Σwx = 11, Σwx² = 27, Σwy = 32, Σwxy = 3 + 20 + 54 = 77
    // → b = (6·77 − 11·32)/(6·27 − 11²) = 110/41, a = (32 − 11b)/6.
    let both = Stack::new(vec![(&a, 1.0), (&b, 2.0)]).unwrap();
    let o = fit(&both, None, None, &FitOptions::default(), "ab", None).unwrap();
    let bb = 110.0 / 41.0;
    let aa = (32.0 - 11.0 * bb) / 6.0;
    assert!(
        (o.theta[0] - aa).abs() < 1e-9 && (o.theta[1] - bb).abs() < 1e-9,
        "{:?}",
        o.theta
    );
    // mismatched parameter tables are refused
    let c = Curve::new(
        vec![Param::unbounded("x", 0.0)],
        vec![0.0],
        vec![0.0],
        line_model,
        line_grad,
    );
    assert!(Stack::new(vec![(&a, 1.0), (&c, 1.0)]).is_err());
}
