//! Axis-system mappings: one physical situation, written down by hand in each
//! system from that system's definitions (not from the sign table), must map
//! onto the same ISO-W sample.
//!
//! The situation: a tyre loaded with 3000 N rolls forward while its contact
//! centre moves to the wheel's right (so the road pushes it to the left with
//! 2000 N), it is driven (κ = +0.05, Fx = +500 N), its top leans to the right
//! by 2°, the aligning moment (40 Nm) turns it clockwise seen from above, the
//! overturning moment about the forward axis is 50 Nm (right-hand rule about
//! the forward axis, common to all systems) and rolling resistance (−80 Nm
//! about the ISO y axis) opposes the forward spin.

use tyrekit::data::conventions::{
    from_iso, sign_table_markdown, to_iso, AxisSample, AxisSystem, SIGN_TABLE,
};

fn iso_truth() -> AxisSample {
    // ISO-W: y left, z up. Contact centre moving to the right → Vy < 0 → α = −5°.
    // Force to the left → Fy = +2000. Load up → Fz = +3000. Clockwise from above
    // = negative about z up → Mz = −40. Top to the right = positive rotation
    // about x → γ = +2°. Forward spin is positive about y (left), the
    // resisting moment negative → My = −80.
    AxisSample {
        fx: 500.0,
        fy: 2000.0,
        fz: 3000.0,
        mx: 50.0,
        my: -80.0,
        mz: -40.0,
        alpha: (-5f64).to_radians(),
        gamma: 2f64.to_radians(),
        kappa: 0.05,
        phit: 0.0,
        rl: 0.3,
    }
}

fn assert_same(a: &AxisSample, b: &AxisSample) {
    let pairs = [
        (a.fx, b.fx, "Fx"),
        (a.fy, b.fy, "Fy"),
        (a.fz, b.fz, "Fz"),
        (a.mx, b.mx, "Mx"),
        (a.my, b.my, "My"),
        (a.mz, b.mz, "Mz"),
        (a.alpha, b.alpha, "alpha"),
        (a.gamma, b.gamma, "gamma"),
        (a.kappa, b.kappa, "kappa"),
    ];
    for (x, y, n) in pairs {
        assert!((x - y).abs() < 1e-9 * (1.0 + x.abs()), "{n}: {x} vs {y}");
    }
}

#[test]
fn sae_j670_record_maps_to_iso() {
    // SAE: y right, z down. Moving right → SAE slip angle +5° (positive
    // clockwise seen from above). Force to the left → FY = −2000. Road force
    // upward → FZ = −3000. Clockwise from above is positive about z down →
    // MZ = +40. Top to the right → IA = +2°. Forward spin is negative about y
    // (right), resisting moment positive → MY = +80. Mx, Fx, κ unchanged.
    let sae = AxisSample {
        fx: 500.0,
        fy: -2000.0,
        fz: -3000.0,
        mx: 50.0,
        my: 80.0,
        mz: 40.0,
        alpha: 5f64.to_radians(),
        gamma: 2f64.to_radians(),
        kappa: 0.05,
        phit: 0.0,
        rl: 0.3,
    };
    assert_same(&to_iso(AxisSystem::Sae, &sae), &iso_truth());
    assert_same(&from_iso(AxisSystem::Sae, &iso_truth()), &sae);
}

#[test]
fn iso_and_tydex_w_are_identity() {
    assert_same(&to_iso(AxisSystem::Iso, &iso_truth()), &iso_truth());
    assert_same(&to_iso(AxisSystem::TydexW, &iso_truth()), &iso_truth());
}

#[test]
fn adapted_iso_flips_only_the_slip_angle() {
    // Pacejka's adapted ISO: ISO axes, α defined so that Fy and α share their
    // sign: this situation (Fy = +2000) has α = +5°.
    let mut a = iso_truth();
    a.alpha = 5f64.to_radians();
    assert_same(&to_iso(AxisSystem::AdaptedIso, &a), &iso_truth());
}

#[test]
fn tydex_c_rotates_by_inclination_and_moves_moments_to_the_contact() {
    // γ = 0: C differs from W only by the origin (wheel centre, Rl above the
    // contact point). A lateral force at the contact point seen from the
    // centre gives an extra moment about x of +Rl·Fy (r = (0, 0, −Rl) from
    // centre to contact, r × F). So Mx_C = Mx_W + Rl·Fy.
    let mut w = iso_truth();
    w.gamma = 0.0;
    let mut c = w;
    c.mx = w.mx + w.rl * w.fy;
    c.my = w.my - w.rl * w.fx;
    assert_same(&to_iso(AxisSystem::TydexC, &c), &w);
    // γ = 2°: a purely vertical road force of 3000 N has, in the wheel-fixed
    // C axes (y along the spin axis tilted by γ), components Fy_C = 3000 sin γ
    // and Fz_C = 3000 cos γ.
    let g = 2f64.to_radians();
    let vertical = AxisSample {
        fz: 3000.0,
        gamma: g,
        rl: 0.3,
        ..Default::default()
    };
    let c = from_iso(AxisSystem::TydexC, &vertical);
    assert!(
        (c.fy - 3000.0 * g.sin()).abs() < 1e-9 && (c.fz - 3000.0 * g.cos()).abs() < 1e-9,
        "{c:?}"
    );
    assert_same(&to_iso(AxisSystem::TydexC, &c), &vertical);
    // And the full situation round-trips.
    assert_same(
        &to_iso(
            AxisSystem::TydexC,
            &from_iso(AxisSystem::TydexC, &iso_truth()),
        ),
        &iso_truth(),
    );
}

#[test]
fn the_table_is_printable_and_complete() {
    let md = sign_table_markdown();
    for r in SIGN_TABLE.iter() {
        assert!(md.contains(r.label));
        for f in [r.sae, r.iso, r.adapted_iso, r.tydex_w, r.tydex_c] {
            assert!(f == 1.0 || f == -1.0);
        }
    }
    assert!(AxisSystem::parse("SAE") == Some(AxisSystem::Sae));
    assert!(AxisSystem::parse("adapted-iso") == Some(AxisSystem::AdaptedIso));
    assert!(AxisSystem::parse("iso-c") == Some(AxisSystem::TydexC));
}
