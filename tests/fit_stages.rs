//! Staged fits pass their solution on by name; each stage fits only its own set.

mod fit_support;
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
