//! Guan & Dang's study (brush::study): the cornering stiffness is far more
//! sensitive to the tread's shear stiffness than the vertical stiffness is,
//! and C_y has the right limits — a rigid tread gives the stretched string's
//! own C_y = (σ_c + a)²/(σ_c·h) (Pacejka 3rd ed. §5.3), a vanishing tread
//! gives the rigid-carcass brush 2·c_py·a² → 0.

use tyrekit::brush::{
    cy_at, cy_elasticity, sensitivity, string_cornering_stiffness, BrushParams, VerticalSeries,
    BETA_MIN, M_MAX, STUDY_FACTORS,
};
use tyrekit::mf::Tyre;

/// The built-in tyre's brush (string carcass) at M = 64.
fn brush() -> BrushParams {
    let b = BrushParams::from_tyre(&Tyre::builtin()).unwrap().0;
    assert!(b.compliance > 0.0, "the study needs a flexible carcass");
    BrushParams { points: M_MAX, ..b }
}

#[test]
fn cornering_is_more_sensitive_to_the_tread_than_vertical_stiffness() {
    let b = brush();
    for beta in [BETA_MIN, 6.0] {
        let rows = sensitivity(&b, &STUDY_FACTORS, beta).unwrap();
        for w in rows.windows(2) {
            // A stiffer tread: both stiffnesses grow, both elasticities fall
            // (the tread takes a smaller share of either deflection).
            assert!(w[1].cy > w[0].cy && w[1].kz > w[0].kz, "{w:?}");
            assert!(w[1].e_cy < w[0].e_cy && w[1].e_kz < w[0].e_kz, "{w:?}");
        }
        for r in &rows {
            assert!(
                r.e_cy > 0.0 && r.e_cy < 1.0 && r.e_kz > 0.0 && r.e_kz < 1.0,
                "{r:?}"
            );
            // The paper's finding, over the whole 1/32..32 range: the
            // cornering stiffness responds more to the tread than K_z does.
            assert!(r.e_cy > r.e_kz, "beta {beta}: {r:?}");
        }
        // At the file's tread the shares are comparable laterally (0.2..0.8)
        // and small vertically (< 0.1 even for the softest rubber, β = 3):
        // measured 0.60 and 0.053 (β = 3).
        let r0 = rows.iter().find(|r| r.cpy_rel == 1.0).unwrap();
        assert!(r0.e_cy > 0.2 && r0.e_cy < 0.8, "{r0:?}");
        assert!(r0.e_kz < 0.1, "{r0:?}");
        assert!(r0.e_cy > 5.0 * r0.e_kz, "{r0:?}");
    }
}

#[test]
fn vertical_series_model() {
    let b = brush();
    let a = b.patch(b.fz0).a;
    let v = VerticalSeries::calibrated(b.cz, b.cpy, BETA_MIN, a).unwrap();
    // Calibrated to the file's VERTICAL_STIFFNESS at the file's tread.
    assert!((v.kz(b.cpy) / b.cz - 1.0).abs() < 1e-12);
    // The analytic elasticity K_z/K_t against a central difference of ln K_z
    // (step 1e-4: truncation O(1e-8)).
    for f in [0.1, 1.0, 10.0] {
        let c = b.cpy * f;
        let h = 1e-4;
        let num = (v.kz(c * f64::exp(h)).ln() - v.kz(c * f64::exp(-h)).ln()) / (2.0 * h);
        assert!(
            (num - v.elasticity(c)).abs() < 1e-7,
            "{num} vs {}",
            v.elasticity(c)
        );
    }
    // A tread softer than the whole tyre leaves no carcass: an error naming it.
    let e = VerticalSeries::calibrated(b.cz, b.cz / (BETA_MIN * 2.0 * a) * 0.5, BETA_MIN, a)
        .unwrap_err()
        .to_string();
    assert!(e.contains("VERTICAL_STIFFNESS"), "{e}");
}

#[test]
fn rigid_tread_gives_the_strings_cornering_stiffness() {
    let b = brush();
    let err = |m: usize| {
        let q = BrushParams { points: m, ..b };
        let patch = q.patch(q.fz0);
        cy_at(&q, &patch, b.cpy * 1e6) / string_cornering_stiffness(&q, patch.a) - 1.0
    };
    // The discrete carcass converges at first order in 1/M to the continuous
    // string (measured −0.59 %, −0.30 %, −0.15 % at M = 16, 32, 64: the
    // leading edge's force concentrates in the first element). 0.5 % at
    // M = 64 leaves a 3× margin; the first order is checked by the ratio.
    let (e16, e64) = (err(16), err(64));
    assert!(e64.abs() < 5e-3, "M = 64: {e64}");
    let ratio = e16 / e64;
    assert!(
        (3.0..5.0).contains(&ratio),
        "first order: e16/e64 = {ratio}"
    );
}

#[test]
fn vanishing_tread_gives_the_rigid_carcass_brush() {
    let b = brush();
    let patch = b.patch(b.fz0);
    let cpy = b.cpy * 1e-6;
    // With a tread 1e6 times softer the carcass takes a share ~ c_py·2a·h·σ
    // of the deflection, ≈ 1e-5 here: C_y is the rigid-carcass brush
    // Σ c_py·Δ·s_i = 2·c_py·a² (midpoint rule, exact) to 1e-4, and → 0.
    let cy = cy_at(&b, &patch, cpy);
    let rigid = 2.0 * cpy * patch.a * patch.a;
    assert!((cy / rigid - 1.0).abs() < 1e-4, "{cy} vs {rigid}");
    assert!(cy < 1e-5 * cy_at(&b, &patch, b.cpy));
    // And all of the lateral deflection is the tread's: elasticity → 1.
    assert!((cy_elasticity(&b, &patch, cpy) - 1.0).abs() < 1e-4);
}
