//! The force equations evaluated on dual numbers give exact parameter
//! derivatives: checked against central finite differences of the `f64`
//! evaluation, for parameters of every force/moment, in several conditions.

use num_dual::{Dual64, DualNum, DualSVec64};
use tyrekit::mf::{MfInput, Model, Tyre, UseMode};
use tyrekit::tir::keys::key_index;

fn cases() -> Vec<(MfInput, UseMode)> {
    let x = |fz, kappa, alpha, gamma, vx, p| MfInput {
        fz,
        kappa,
        alpha,
        gamma,
        phit: 0.0,
        vx,
        p,
        omega: 0.0,
    };
    let m = UseMode::default();
    let star = UseMode {
        alpha_star: true,
        ..m
    };
    vec![
        (x(4000.0, 0.05, 0.08, 0.02, 20.0, 2.2e5), m),
        (x(2500.0, -0.12, -0.15, -0.04, 8.0, 2.5e5), m),
        (x(6000.0, 0.0, 0.03, 0.0, 30.0, 2.0e5), star),
        (x(5000.0, 0.2, -0.05, 0.05, 0.6, 2.2e5), m), // low speed
    ]
}

/// Parameters touching Fx, Fy, Mx, My, Mz (including load, camber, pressure terms).
const KEYS: &[&str] = &[
    "PDY1",
    "PKY1",
    "PKY4",
    "PCY1",
    "PEY1",
    "PHY1",
    "PVY3",
    "PCX1",
    "PDX1",
    "PKX1",
    "PKX3",
    "PEX1",
    "RBX1",
    "RHX1",
    "RBY1",
    "RVY1",
    "RHY1",
    "QBZ1",
    "QDZ1",
    "QDZ6",
    "QDZ8",
    "QEZ1",
    "SSZ1",
    "QSX3",
    "QSX4",
    "QSX10",
    "QSY1",
    "QSY7",
    "QSY8",
    "PPY1",
    "FNOMIN",
    "LFZO",
    "UNLOADED_RADIUS",
    "NOMPRES",
];

fn outputs<T: DualNum<f64> + Copy>(s: &tyrekit::mf::Solution<T>) -> [T; 5] {
    [s.fx, s.fy, s.mx, s.my, s.mz]
}

#[test]
fn dual_derivatives_match_finite_differences() {
    let tyre = Tyre::builtin();
    let base = tyre.params().p.clone();
    let form = tyre.model().form;
    for (inp, mode) in cases() {
        let (cond, _) = tyre.conditions(&inp, mode);
        let plain = tyre.model().solve(&cond);
        for key in KEYS {
            let k = key_index(key).unwrap();
            let dual = Model::new(
                base.map(|i, v| {
                    if i == k {
                        Dual64::new(v, 1.0)
                    } else {
                        Dual64::from(v)
                    }
                }),
                form,
            );
            let sd = dual.solve(&cond);
            let v = base.as_slice()[k];
            let h = 1e-5 * v.abs().max(1e-2);
            let at = |d: f64| {
                let mut q = base.clone();
                q.as_mut_slice()[k] = v + d;
                outputs(&Model::new(q, form).solve(&cond))
            };
            let (up, dn) = (at(h), at(-h));
            for (j, name) in ["Fx", "Fy", "Mx", "My", "Mz"].iter().enumerate() {
                let d = outputs(&sd)[j];
                // Value parts agree with the f64 path (value-only shortcuts such
                // as sin(2 atan x) = 2x/(1+x²) differ by rounding only).
                let f = outputs(&plain)[j];
                assert!(
                    (d.re - f).abs() <= 1e-12 * f.abs().max(1.0),
                    "{key} {name}: value {} vs {f}",
                    d.re
                );
                let fd = (up[j] - dn[j]) / (2.0 * h);
                // Central difference: O(h²) truncation + ~1e-16·|F|/h rounding.
                let tol = 1e-6 * fd.abs().max(d.eps.abs()) + 1e-9 * f.abs().max(1.0) / h;
                assert!(
                    (d.eps - fd).abs() <= tol,
                    "{key} {name} at {inp:?}: dual {} vs fd {fd}",
                    d.eps
                );
            }
        }
    }
}

#[test]
fn gradient_in_one_pass_with_dual_vectors() {
    let tyre = Tyre::builtin();
    let base = tyre.params().p.clone();
    let idx = [
        key_index("PDY1").unwrap(),
        key_index("PKY1").unwrap(),
        key_index("QDZ1").unwrap(),
    ];
    let model = Model::new(
        base.map(|i, v| match idx.iter().position(|&j| j == i) {
            Some(n) => DualSVec64::<3>::new(
                v,
                num_dual::Derivative::derivative_generic(
                    nalgebra::Const::<3>,
                    nalgebra::Const::<1>,
                    n,
                ),
            ),
            None => DualSVec64::<3>::from(v),
        }),
        tyre.model().form,
    );
    let (inp, mode) = cases()[0];
    let (cond, _) = tyre.conditions(&inp, mode);
    let s = model.solve(&cond);
    for (n, &k) in idx.iter().enumerate() {
        let single = Model::new(
            base.map(|i, v| {
                if i == k {
                    Dual64::new(v, 1.0)
                } else {
                    Dual64::from(v)
                }
            }),
            tyre.model().form,
        )
        .solve(&cond);
        let g =
            s.mz.eps
                .unwrap_generic(nalgebra::Const::<3>, nalgebra::Const::<1>)[n];
        assert!(
            (g - single.mz.eps).abs() <= 1e-12 * g.abs().max(1.0),
            "gradient entry {n}: {g} vs {}",
            single.mz.eps
        );
    }
}
