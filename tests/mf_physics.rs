//! Physics checks of the steady-state Magic Formula where MFeval gives no
//! reference: PAC2002 (no FITTYP) and MF 5.2 files, turn slip, the clamping
//! report. Expected values are computed here independently from the file's
//! coefficients (never taken from the code under test).

use crate::common;
use common::shared;
use tyrekit::mf::{Clamped, MfInput, Tyre, UseMode};
use tyrekit::tir::{MfVersion, TyreParams};

const NO_LIMITS: UseMode = UseMode {
    limits: false,
    alpha_star: false,
    turn_slip: false,
};

fn input(fz: f64, kappa: f64, alpha: f64, gamma: f64) -> MfInput {
    MfInput {
        fz,
        kappa,
        alpha,
        gamma,
        phit: 0.0,
        vx: 15.0,
        p: 0.0,
        omega: 0.0,
    }
}

/// A PAC2002 passenger-car tyre with every shift and asymmetry set to zero,
/// so Fy(α), Fx(κ) and Mz(α) must be exactly odd.
fn symmetric_pac2002() -> TyreParams {
    let mut t = TyreParams::builtin();
    t.version = MfVersion::Pac2002;
    t.p.fittyp = 0.0;
    for k in [
        "PHX1", "PHX2", "PVX1", "PVX2", "PEX4", "PHY1", "PHY2", "PHY3", "PVY1", "PVY2", "PVY3",
        "PVY4", "PEY3", "RHX1", "RHY1", "RHY2", "RVY1", "RVY2", "RVY3", "QHZ1", "QHZ2", "QHZ3",
        "QHZ4", "QDZ6", "QDZ7", "QDZ8", "QDZ9", "QEZ4", "SSZ1", "SSZ2", "SSZ3", "SSZ4", "QSX1",
        "QSX2", "QSX3",
    ] {
        assert!(t.p.set(k, 0.0), "{k}");
    }
    let set = |t: &mut TyreParams, k: &str, v: f64| assert!(t.p.set(k, v), "{k}");
    set(&mut t, "FNOMIN", 4000.0);
    set(&mut t, "PKY1", -18.0);
    set(&mut t, "PKY2", 1.8);
    // A PAC2002 file has no PKY4 (its Kya has a fixed 2, Adams PAC2002 /
    // MF-Tyre 5.2): the reader gives the table default 2. The built-in file
    // is an MF 6.1 set (TVD3 App. 3) with PKY4 = 2.0005, which must not leak
    // into this PAC2002 fixture.
    set(&mut t, "PKY4", 2.0);
    set(&mut t, "PDY1", 1.05);
    set(&mut t, "PDY2", -0.08);
    set(&mut t, "PCY1", 1.35);
    set(&mut t, "PEY1", -0.6);
    set(&mut t, "PDX1", 1.2);
    set(&mut t, "PKX1", 22.0);
    set(&mut t, "PCX1", 1.6);
    set(&mut t, "QBZ1", 9.0);
    set(&mut t, "QCZ1", 1.2);
    set(&mut t, "QDZ1", 0.09);
    t
}

#[test]
fn pac2002_signs_and_odd_symmetry() {
    let tyre = Tyre::new(symmetric_pac2002()).unwrap();
    assert_eq!(tyre.version(), MfVersion::Pac2002);
    let fz = 4500.0;
    for a in [0.01, 0.05, 0.1, 0.2, 0.4] {
        let pos = tyre.forces(&input(fz, 0.0, a, 0.0), NO_LIMITS);
        let neg = tyre.forces(&input(fz, 0.0, -a, 0.0), NO_LIMITS);
        assert!(
            pos.fy < 0.0,
            "ISO-W: alpha > 0 gives Fy < 0 (alpha {a}: {})",
            pos.fy
        );
        // Exactly odd up to rounding: 1e-12 of the force scale.
        assert!(
            (pos.fy + neg.fy).abs() <= 1e-12 * fz,
            "Fy odd at {a}: {} {}",
            pos.fy,
            neg.fy
        );
        assert!(
            (pos.mz + neg.mz).abs() <= 1e-12 * fz,
            "Mz odd at {a}: {} {}",
            pos.mz,
            neg.mz
        );
    }
    let mz = tyre.forces(&input(fz, 0.0, 0.02, 0.0), NO_LIMITS).mz;
    assert!(mz > 0.0, "Mz > 0 at small positive alpha (ISO-W), got {mz}");
    for k in [0.01, 0.05, 0.1, 0.3] {
        let pos = tyre.forces(&input(fz, k, 0.0, 0.0), NO_LIMITS);
        let neg = tyre.forces(&input(fz, -k, 0.0, 0.0), NO_LIMITS);
        assert!(pos.fx > 0.0, "kappa > 0 gives Fx > 0 ({k}: {})", pos.fx);
        assert!((pos.fx + neg.fx).abs() <= 1e-12 * fz, "Fx odd at {k}");
    }
}

#[test]
fn pac2002_peak_friction_and_cornering_stiffness() {
    let t = symmetric_pac2002();
    let p = t.p.clone();
    let tyre = Tyre::new(t).unwrap();
    for fz in [2000.0, 4000.0, 6500.0] {
        let dfz = (fz - p.fnomin) / p.fnomin;
        // Peak of D·sin(C·atan(…)) is D (C > 1, E < 1, no shifts): mu = PDY1 + PDY2·dfz.
        let mu = p.pdy1 + p.pdy2 * dfz;
        let peak = (0..=6000)
            .map(|i| {
                tyre.forces(&input(fz, 0.0, i as f64 * 1e-4, 0.0), NO_LIMITS)
                    .fy
                    .abs()
            })
            .fold(0.0, f64::max);
        // Sweep step 1e-4 rad near a smooth maximum: error ≪ 1e-6 relative.
        assert!(
            (peak / fz - mu).abs() < 1e-6 * mu,
            "peak |Fy|/Fz {} vs mu {mu} at Fz {fz}",
            peak / fz
        );
        // Cornering stiffness at alpha -> 0 (PAC2002 formula, LFZO = LKY = 1).
        let kya = p.pky1 * p.fnomin * (2.0 * (fz / (p.pky2 * p.fnomin)).atan()).sin();
        let h = 1e-6;
        let slope = (tyre.forces(&input(fz, 0.0, h, 0.0), NO_LIMITS).fy
            - tyre.forces(&input(fz, 0.0, -h, 0.0), NO_LIMITS).fy)
            / (2.0 * h);
        // Central difference: truncation O(h²·Fy''') and rounding ~1e-16·Fz/h: < 1e-6 relative.
        assert!(
            (slope - kya).abs() < 1e-6 * kya.abs(),
            "dFy/dalpha {slope} vs {kya} at Fz {fz}"
        );
        let out = tyre.evaluate(&input(fz, 0.0, 0.0, 0.0), NO_LIMITS);
        assert!(
            (out.kya - kya).abs() < 1e-9 * kya.abs(),
            "Kya output {} vs {kya}",
            out.kya
        );
        assert!(
            (out.muy - mu).abs() < 1e-12,
            "muy output {} vs {mu}",
            out.muy
        );
    }
}

#[test]
fn pac2002_honours_lgay_but_mf61_does_not() {
    let mut t = symmetric_pac2002();
    t.p.pvy3 = -0.3;
    t.p.phy3 = 0.02;
    t.p.pky3 = 0.5;
    t.p.lgay = 0.0;
    let pac = Tyre::new(t.clone()).unwrap();
    let (a, g) = (0.05, 0.06);
    let cambered = pac.forces(&input(4000.0, 0.0, a, g), NO_LIMITS).fy;
    let flat = pac.forces(&input(4000.0, 0.0, a, 0.0), NO_LIMITS).fy;
    assert_eq!(
        cambered, flat,
        "PAC2002 with LGAY = 0: camber must not change Fy"
    );
    t.version = MfVersion::Mf61;
    t.p.fittyp = 61.0;
    let mf61 = Tyre::new(t).unwrap();
    let c61 = mf61.forces(&input(4000.0, 0.0, a, g), NO_LIMITS).fy;
    let f61 = mf61.forces(&input(4000.0, 0.0, a, 0.0), NO_LIMITS).fy;
    assert!(
        (c61 - f61).abs() > 1.0,
        "MF 6.1 ignores LGAY: camber still acts ({c61} vs {f61})"
    );
}

/// The real PAC2002 and MF 5.2 files MFeval refuses: they load with the
/// right equation set and give ISO-W signs and finite outputs.
#[test]
fn refused_files_evaluate_with_iso_w_signs() {
    let dir = shared().join("data/tir");
    if !dir.exists() {
        println!("SKIPPED: {} not found", dir.display());
        return;
    }
    for (name, version) in [
        ("Generic_Pac02Tire.tir", MfVersion::Pac2002),
        ("HMMWV_Pac02Tire.tir", MfVersion::Pac2002),
        ("Sedan_Pac02Tire.tir", MfVersion::Pac2002),
        ("MF5.2-Hoosier-R25B-43105-MX26-7in-rim.TIR", MfVersion::Mf52),
    ] {
        let path = dir.join(name);
        if !path.exists() {
            println!("SKIPPED: {name} not found");
            continue;
        }
        let tyre = Tyre::from_file(&path).unwrap();
        assert_eq!(tyre.version(), version, "{name}");
        let fz = tyre.params().p.fnomin;
        let m = UseMode::default();
        let lat = tyre.evaluate(&input(fz, 0.0, 0.08, 0.0), m);
        let lon = tyre.evaluate(&input(fz, 0.08, 0.0, 0.0), m);
        assert!(lat.fy < 0.0, "{name}: Fy {} at alpha 0.08", lat.fy);
        assert!(lon.fx > 0.0, "{name}: Fx {} at kappa 0.08", lon.fx);
        assert!(lat.kya < 0.0, "{name}: Kya {}", lat.kya);
        for (k, v) in tyrekit::mf::OUTPUT_COLUMNS.iter().zip(lat.to_array()) {
            assert!(v.is_finite(), "{name}: {k} = {v}");
        }
        assert!(
            lat.rl > 0.0 && lat.rl < tyre.params().p.unloaded_radius * 1.05,
            "{name}: Rl {}",
            lat.rl
        );
    }
}

#[test]
fn turn_slip_reduces_to_no_turn_slip_at_zero_spin() {
    let tyre = Tyre::builtin();
    let with = UseMode {
        limits: false,
        alpha_star: false,
        turn_slip: true,
    };
    for (k, a) in [(0.0, 0.05), (0.05, 0.0), (-0.1, 0.1)] {
        let x = input(4500.0, k, a, 0.0);
        let (f0, f1) = (tyre.forces(&x, NO_LIMITS), tyre.forces(&x, with));
        // γ = 0, φt = 0: every ζ factor is 1 (ζ0 = 0 only removes camber terms).
        assert!((f0.fx - f1.fx).abs() < 1e-9 * 4500.0 && (f0.fy - f1.fy).abs() < 1e-9 * 4500.0);
        assert!(
            f1.mz.is_finite(),
            "Mz finite at zero turn slip (limit of 0/0 in zeta7)"
        );
        // Continuity in φt: a tiny spin changes Mz only a little.
        let mut xs = x;
        xs.phit = 1e-7;
        let f2 = tyre.forces(&xs, with);
        assert!(
            (f2.mz - f1.mz).abs() < 1e-3 * (1.0 + f1.mz.abs()),
            "Mz jump at phit→0: {} vs {}",
            f2.mz,
            f1.mz
        );
    }
    // Turn slip reduces the peak side force (ζ2 < 1, Pacejka eq. 4.77).
    let peak = |phit: f64| {
        (-500..=500)
            .map(|i| {
                let mut x = input(4500.0, 0.0, i as f64 * 0.001, 0.0);
                x.phit = phit;
                tyre.forces(&x, with).fy.abs()
            })
            .fold(0.0, f64::max)
    };
    let (p0, p1) = (peak(0.0), peak(2.0));
    // Built-in tyre: PDYP2..4 = 0, γ = 0, so ζ2 = cos(atan(PDYP1·R0·|φt|)) and
    // the peak |Fy| = Dy·ζ2 (SVy = 0). Sweep step 1e-3 rad: peak error < 1e-5.
    let p = &tyre.params().p;
    let zeta2 = (p.pdyp1 * p.unloaded_radius * 2.0).atan().cos();
    assert!(
        (p1 / p0 - zeta2).abs() < 2e-5,
        "peak ratio {} vs zeta2 {zeta2}",
        p1 / p0
    );
}

#[test]
fn clamping_is_reported() {
    let tyre = Tyre::builtin();
    let p = tyre.params().p.clone();
    let m = UseMode::default();
    let (_, c) = tyre.evaluate_checked(&input(p.fnomin, 0.0, 0.1, 0.0), m);
    assert!(
        c.is_empty(),
        "nothing clamped in range: {:?}",
        c.names().collect::<Vec<_>>()
    );
    let (o, c) = tyre.evaluate_checked(
        &input(
            p.fzmax * 2.0,
            p.kpumax + 1.0,
            p.alpmax + 0.2,
            p.cammax + 0.1,
        ),
        m,
    );
    for bit in [
        Clamped::FZ_HIGH,
        Clamped::KAPPA_HIGH,
        Clamped::ALPHA_HIGH,
        Clamped::GAMMA_HIGH,
    ] {
        assert!(
            c.has(bit),
            "flag {bit:#x} missing: {:?}",
            c.names().collect::<Vec<_>>()
        );
    }
    assert_eq!(
        o.fz,
        p.fzmax * 2.0,
        "the Fz output is the (unclipped) input"
    );
    let mut slow = input(p.fnomin, 0.1, 0.1, 0.0);
    slow.vx = 0.5 * p.vxlow;
    let (o, c) = tyre.evaluate_checked(&slow, m);
    assert!(c.has(Clamped::LOW_SPEED));
    assert!(
        (o.kappa - 0.05).abs() < 1e-15,
        "kappa reduced linearly below VXLOW: {}",
        o.kappa
    );
    let (_, c) = tyre.evaluate_checked(&input(-10.0, 0.0, 0.0, 0.0), m);
    assert!(c.has(Clamped::FZ_NEGATIVE));
    // Without limit checks nothing but the sign of Fz is touched.
    let (_, c) = tyre.evaluate_checked(&input(p.fzmax * 2.0, 3.0, 1.6, 0.3), NO_LIMITS);
    assert!(c.is_empty());
}

/// Whatever the inputs (NaN, ±Inf, zero, huge), evaluation returns (no panic,
/// no endless iteration) in every use mode, for every equation family.
#[test]
fn extreme_inputs_do_not_panic() {
    let vals = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        1e300,
        -1e300,
        1e-300,
        0.5,
        -3.0,
    ];
    let mut tyres = vec![Tyre::builtin(), Tyre::new(symmetric_pac2002()).unwrap()];
    let mut t62 = TyreParams::builtin();
    t62.version = MfVersion::Mf62;
    t62.p.fittyp = 62.0;
    tyres.push(Tyre::new(t62).unwrap());
    let modes: Vec<UseMode> = [111, 112, 121, 122, 211, 212, 221, 222]
        .iter()
        .map(|&c| UseMode::from_code(c).unwrap())
        .collect();
    let mut n = 0usize;
    for t in &tyres {
        for (i, &a) in vals.iter().enumerate() {
            for &b in &vals {
                let x = MfInput {
                    fz: if i % 2 == 0 { a } else { 4000.0 },
                    kappa: b,
                    alpha: a,
                    gamma: b * 0.01,
                    phit: a,
                    vx: b,
                    p: if i % 3 == 0 { a } else { 0.0 },
                    omega: if i % 4 == 0 { b } else { 0.0 },
                };
                for m in &modes {
                    let (o, _) = t.evaluate_checked(&x, *m);
                    let f = t.forces(&x, *m);
                    std::hint::black_box((o, f));
                    n += 1;
                }
            }
        }
    }
    assert_eq!(n, 3 * 10 * 10 * 8);
}
