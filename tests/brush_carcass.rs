//! The brush with a flexible (stretched-string) carcass: the cornering
//! stiffness against the paper's eq. (14) evaluated independently (a dense
//! nalgebra solve of C_y = Σ_i [k_y·(I + k_y·D_e·H)⁻¹·C]_i with H built here
//! from the documented Green's function), saturation at μ·Fz, and the
//! adhesion/sliding iteration's convergence over α ∈ ±90°, Fz ∈ 0..3·FNOMIN
//! (the final sliding boundary re-checked here by dense solves).

use nalgebra::{DMatrix, DVector};
use tyrekit::brush::{BrushInput, BrushParams, Patch};
use tyrekit::mf::Tyre;

fn builtin() -> BrushParams {
    BrushParams::from_tyre(&Tyre::builtin()).unwrap().0
}

/// H_e (module docs of brush::carcass): h·(e^{−|si−sj|/σc} − e^{−sj/σc}).
fn he(p: &BrushParams, patch: &Patch) -> DMatrix<f64> {
    let m = patch.m;
    DMatrix::from_fn(m, m, |i, j| {
        let (si, sj) = (patch.pts[i].s, patch.pts[j].s);
        p.compliance * ((-(si - sj).abs() / p.sigma_c).exp() - (-sj / p.sigma_c).exp())
    })
}

/// Lateral adhesion forces of points 0..n with points n.. sliding at μk·p_i
/// (pure side slip, tan α = t > 0), dense solve.
fn dense_forces(p: &BrushParams, patch: &Patch, t: f64, mu_k: f64, n: usize) -> DVector<f64> {
    let m = patch.m;
    let h = he(p, patch);
    let k = p.cpy * patch.delta;
    let mut f = DVector::from_fn(m, |i, _| mu_k * patch.pts[i].pz);
    if n > 0 {
        let a = DMatrix::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } + k * h[(i, j)]);
        let b = DVector::from_fn(n, |i, _| {
            let mut r = patch.pts[i].s * t;
            for j in n..m {
                r -= h[(i, j)] * f[j];
            }
            k * r
        });
        let x = a.lu().solve(&b).expect("regular");
        for i in 0..n {
            f[i] = x[i];
        }
    }
    f
}

#[test]
fn cornering_stiffness_is_eq14() {
    let p = builtin();
    assert!(
        p.compliance > 0.0,
        "the builtin tyre's default carcass is flexible"
    );
    for fz in [1000.0, 4000.0, 8000.0] {
        let patch = p.patch(fz);
        let m = patch.m;
        let k = p.cpy * patch.delta; // k_y·D_e with D_e = diag(Δ)
        let a = DMatrix::identity(m, m) + he(&p, &patch) * k;
        let c = DVector::from_fn(m, |i, _| patch.pts[i].s);
        let cy14 = (a.lu().solve(&c).unwrap() * k).sum();
        let cy = p.cornering_stiffness(fz);
        // Two solvers of the same linear system: agreement to round-off (1e-10).
        assert!((cy - cy14).abs() < 1e-10 * cy14, "Fz {fz}: {cy} vs {cy14}");
        // The carcass takes a share of the deflection: C_y below the rigid 2·c_p·a².
        let rigid = 2.0 * p.cpy * patch.a * patch.a;
        assert!(cy < 0.95 * rigid, "Fz {fz}: {cy} vs rigid {rigid}");
        // And the full model at a tiny slip angle has that slope (1e-6: the
        // trailing point's margin to its friction limit is ~1e3 times the force).
        let t = 1e-7;
        let f = p.forces(&BrushInput::new(fz, 0.0, t));
        assert!(((-f.fy / t) - cy14).abs() < 1e-6 * cy14, "Fz {fz}");
    }
}

#[test]
fn default_cornering_stiffness_matches_the_magic_formula() {
    let tyre = Tyre::builtin();
    let p = builtin();
    let o = tyre.slip_properties(
        &tyrekit::mf::MfInput {
            fz: p.fz0,
            vx: 20.0,
            ..Default::default()
        },
        tyrekit::mf::UseMode::from_code(211).unwrap(),
    );
    let cy = p.cornering_stiffness(p.fz0);
    // CPY is bisected to 1e-5 of the log bracket: C_y within 1e-4 relative.
    assert!(
        (cy - o.kya.abs()).abs() < 1e-4 * o.kya.abs(),
        "{cy} vs {}",
        o.kya
    );
    let cx = p.slip_stiffness(p.fz0);
    assert!((cx - o.kxk.abs()).abs() < 1e-9 * o.kxk.abs());
    println!("builtin brush: {p:?}");
}

#[test]
fn saturates_at_mu_fz() {
    let mut p = builtin();
    p.mu_s = 1.3 * p.mu_k; // static above sliding: the limit is still μk·Fz
    for fz in [500.0, 4000.0, 12000.0] {
        let (_, mu_k) = tyrekit::brush::friction(&p, fz, 1.0);
        for deg in [45.0f64, 80.0, 89.0, 90.0] {
            let t = deg.to_radians().tan();
            let f = p.forces(&BrushInput::new(fz, 0.0, t));
            // Fully sliding beyond ~20° for this tyre: exactly μk·Fz (element
            // loads sum to Fz) to round-off.
            assert!(
                (f.fy + mu_k * fz).abs() < 1e-9 * fz,
                "Fz {fz} α {deg}: {}",
                f.fy
            );
        }
    }
}

#[test]
fn iteration_converges_everywhere() {
    for mus_ratio in [1.0, 1.25] {
        let mut p = builtin();
        p.mu_s = mus_ratio * p.mu_k;
        let fz0 = p.fz0;
        let mut checked = 0;
        for il in 0..=12 {
            let fz = 3.0 * fz0 * il as f64 / 12.0;
            let patch = p.patch(fz);
            let (mu_s, mu_k) = tyrekit::brush::friction(&p, fz, 1.0);
            for ia in -180..=180 {
                let deg = ia as f64 * 0.5;
                let t = deg.to_radians().tan();
                let f = p.forces(&BrushInput::new(fz, 0.0, t));
                assert!(f.fy.is_finite() && f.mz.is_finite(), "Fz {fz} α {deg}");
                assert!(
                    f.fy.abs() <= mu_s * fz * (1.0 + 1e-9) + 1e-12,
                    "Fz {fz} α {deg}"
                );
                if t != 0.0 && fz > 0.0 {
                    assert!(f.fy * t < 0.0, "ISO sign at Fz {fz} α {deg}");
                }
                // at most ⌈log2 M⌉ + 2 linear solves (bisection)
                let bound = (patch.m as f64).log2().ceil() as usize + 2;
                assert!(f.solves <= bound, "{} solves", f.solves);
                // Converged boundary, re-checked independently every 5°:
                // points 0..n hold under μs, and with n+1 adhering some point cannot.
                if fz > 0.0 && ia % 10 == 0 && t > 0.0 {
                    let n = f.adhesion;
                    let ok = |n: usize| {
                        let v = dense_forces(&p, &patch, t, mu_k, n);
                        (0..n).all(|i| v[i].abs() <= mu_s * patch.pts[i].pz * (1.0 + 1e-9))
                    };
                    assert!(ok(n), "Fz {fz} α {deg}: boundary {n} does not hold");
                    if n < patch.m {
                        assert!(!ok(n + 1), "Fz {fz} α {deg}: boundary {n} could move back");
                    }
                    let v = dense_forces(&p, &patch, t, mu_k, n);
                    assert!((v.sum() + f.fy).abs() < 1e-8 * fz, "Fz {fz} α {deg}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 100);
    }
}
