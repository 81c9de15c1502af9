//! The brush model against the classic closed forms (Pacejka, *Tyre and
//! Vehicle Dynamics*, 3rd ed., §3.2.2, parabolic pressure, one friction
//! coefficient, rigid carcass): with θ = 2·c_p·a²/(3·μ·Fz) and
//! λ = 1 − θ·|tan α| (re-derived for this test by integrating the adhesion
//! and sliding line loads over the patch),
//!   |Fy| = μ·Fz·(1 − λ³),   Mz = μ·Fz·a·λ³·(1 − λ)   for θ|tan α| < 1,
//!   |Fy| = μ·Fz, Mz = 0 beyond.
//! The discrete model is a midpoint sum of a continuous, piecewise-smooth
//! line load: the error must fall as M⁻² (measured order ≥ 1.7 over
//! M = 8..64, the envelope over several slip angles so that a kink falling
//! on a lucky spot of one grid does not decide).

use tyrekit::brush::{BrushInput, BrushParams};

fn rigid(points: usize) -> BrushParams {
    BrushParams {
        points,
        compliance: 0.0,
        mu_s: 1.0,
        mu_k: 1.0,
        mu_dfz: 0.0,
        pressure_n: 1.0,
        ..Default::default()
    }
}

fn closed(theta: f64, t: f64, mu: f64, fz: f64, a: f64) -> (f64, f64) {
    let l = 1.0 - theta * t.abs();
    if l <= 0.0 {
        (mu * fz * t.signum(), 0.0)
    } else {
        (
            mu * fz * (1.0 - l * l * l) * t.signum(),
            mu * fz * a * l * l * l * (1.0 - l) * t.signum(),
        )
    }
}

#[test]
fn rigid_brush_converges_to_closed_form_at_second_order() {
    let fz = 4000.0;
    let ms = [8usize, 16, 32, 64];
    let mut env_fy = vec![0.0f64; ms.len()];
    let mut env_mz = vec![0.0f64; ms.len()];
    for (k, &m) in ms.iter().enumerate() {
        let p = rigid(m);
        let a = p.patch(fz).a;
        let theta = 2.0 * p.cpy * a * a / (3.0 * p.mu_k * fz);
        for frac in [0.05, 0.2, 0.37, 0.5, 0.63, 0.8, 0.95] {
            let t = frac / theta;
            let (fy, mz) = closed(theta, t, 1.0, fz, a);
            let f = p.forces(&BrushInput::new(fz, 0.0, t));
            // ISO-W: Fy = −|Fy| for positive α, Mz = +.
            env_fy[k] = env_fy[k].max((-f.fy - fy).abs() / fz);
            env_mz[k] = env_mz[k].max((f.mz - mz).abs() / (fz * a));
        }
    }
    let order = |e: &[f64]| {
        // least-squares slope of ln e against ln M
        let xs: Vec<f64> = ms.iter().map(|&m| (m as f64).ln()).collect();
        let ys: Vec<f64> = e.iter().map(|v| v.ln()).collect();
        let n = xs.len() as f64;
        let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
        let num: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let den: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
        -num / den
    };
    let (ofy, omz) = (order(&env_fy), order(&env_mz));
    println!("Fy error/Fz {env_fy:?} order {ofy:.2}; Mz error/(Fz a) {env_mz:?} order {omz:.2}");
    assert!(ofy >= 1.7, "Fy order {ofy}");
    assert!(omz >= 1.7, "Mz order {omz}");
    // At M = 64 the error is below 0.1 % of μFz (second order from ~1/M² ≈ 2.4e-4).
    assert!(env_fy[3] < 1e-3 && env_mz[3] < 1e-3);
}

#[test]
fn full_sliding_gives_mu_fz_and_no_moment() {
    let fz = 4000.0;
    for m in [1usize, 7, 20, 64] {
        let p = rigid(m);
        let a = p.patch(fz).a;
        let theta = 2.0 * p.cpy * a * a / (3.0 * fz);
        let f = p.forces(&BrushInput::new(fz, 0.0, -1.2 / theta));
        // all points slide: the element loads sum to Fz exactly (renormalised),
        // so Fy = μ·Fz to round-off and Mz is the first moment of a symmetric
        // pressure about the centre, zero to round-off.
        assert!((f.fy - fz).abs() < 1e-9 * fz, "M={m}: {}", f.fy);
        assert!(f.mz.abs() < 1e-9 * fz * a, "M={m}: {}", f.mz);
        assert_eq!(f.adhesion, 0);
    }
}

#[test]
fn small_slip_gives_the_brush_cornering_stiffness() {
    // Rigid carcass: C = 2·c_p·a² exactly for the midpoint rule (linear integrand).
    let p = rigid(20);
    let fz = 4000.0;
    let a = p.patch(fz).a;
    let t = 1e-7;
    let f = p.forces(&BrushInput::new(fz, 0.0, t));
    let c = 2.0 * p.cpy * a * a;
    assert!(((-f.fy / t) - c).abs() < 1e-9 * c);
    assert!((p.cornering_stiffness(fz) - c).abs() < 1e-9 * c);
    assert!((p.slip_stiffness(fz) - 2.0 * p.cpx * a * a).abs() < 1e-9 * c);
    // pneumatic trail of the triangular adhesion load: a/3 (Pacejka eq. 3.17 at α → 0)
    let trail = f.mz / -f.fy;
    assert!(
        (trail - a / 3.0).abs() < 1e-3 * a,
        "trail {trail} a/3 {}",
        a / 3.0
    );
}
