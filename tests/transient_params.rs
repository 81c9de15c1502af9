//! Parameters from the `.tir`: the low-speed damping of the file (DAMP_VLOW,
//! DAMP_LAT, BELT_MASS) sets the standstill decay rate; MF 5.2/PAC2002
//! PTX/PTY relaxation lengths; turn-slip lag; every shared real `.tir` steps
//! without panicking or producing non-finite output.

use crate::common;
use common::*;
use tyrekit::mf::{Tyre, UseMode};
use tyrekit::tir::{MfVersion, TyreParams};
use tyrekit::transient::{
    InputMode, TransientConfig, TransientKind, TransientModel, TransientOptions, SLOT_PHI,
};

/// Envelope decay rate of a wheel-at-rest oscillation (a 400 kg mass on the
/// lateral tyre spring, kicked by a side-force step): c/(2m) with
/// c = DAMP_VLOW·Cy + 2·DAMP_LAT·√(Cy·BELT_MASS), within 10 % (the light
/// damping makes the envelope exponential; 10 % covers the co-simulation
/// delay at dt = 0.1 ms and the MF's curvature at this deflection).
/// Tripling DAMP_VLOW must raise the rate accordingly.
#[test]
fn standstill_damping_follows_file_parameters() {
    for factor in [1.0, 3.0] {
        let mut params = TyreParams::builtin();
        params.p.damp_vlow *= factor;
        let p = params.p.clone();
        let tyre = Tyre::new(params).unwrap();
        let (_, cy) = carcass(&tyre);
        let c = p.damp_vlow * cy + 2.0 * p.damp_lat * (cy * p.belt_mass).sqrt();
        let mass = 400.0;
        let rate = c / (2.0 * mass);
        let mut m = model(TransientKind::Relaxation, InputMode::Velocities);
        let dt = 1e-4;
        let fext = 200.0;
        let (mut y, mut v) = (0.0f64, 0.0f64);
        let y_eq = fext / cy;
        // Envelope: largest |y − y_eq| in the first and the last 0.5 s of 6 s.
        let (mut a0, mut a1) = (0.0f64, 0.0f64);
        let n = (6.0 / dt) as usize;
        for k in 0..n {
            let out = m.step(&tyre, &vel(0.0, v, 0.0), dt).unwrap();
            v += (fext + out.fy) / mass * dt;
            y += v * dt;
            let t = (k + 1) as f64 * dt;
            if t < 0.5 {
                a0 = a0.max((y - y_eq).abs());
            } else if t > 5.5 {
                a1 = a1.max((y - y_eq).abs());
            }
        }
        let measured = (a0 / a1).ln() / 5.5;
        assert!(
            (measured / rate - 1.0).abs() < 0.1,
            "DAMP_VLOW ×{factor}: decay {measured}/s vs c/2m = {rate}/s"
        );
    }
}

/// MF 5.2 / PAC2002 files whose MF gives no σ use the PTX/PTY forms
/// (MF 5.2 equation set: σκ = Fz(PTX1 + PTX2·dfz)·exp(−PTX3·dfz)·R0/Fz0,
/// σα = PTY1·sin(2·atan(Fz/(PTY2·Fz0)))·R0 at γ = 0, LFZO = LSGKP = LSGAL = 1),
/// when the MF reports σ it is used as is.
#[test]
fn mf52_relaxation_lengths_from_ptx_pty() {
    let mut params = TyreParams::builtin();
    params.version = MfVersion::Mf52;
    params.p.fittyp = 52.0;
    params.p.ptx1 = 2.3;
    params.p.ptx2 = 1.4;
    params.p.ptx3 = 0.2;
    params.p.pty1 = 2.1;
    params.p.pty2 = 1.9;
    let p = params.p.clone();
    let tyre = Tyre::new(params).unwrap();
    let o = mf(&tyre, 20.0, 0.0, 0.0);
    let fz0 = p.fnomin;
    let dfz = (FZ - fz0) / fz0;
    let r0 = p.unloaded_radius;
    let sx = if o.sigmax > 0.0 {
        o.sigmax
    } else {
        FZ * (p.ptx1 + p.ptx2 * dfz) * (-p.ptx3 * dfz).exp() * r0 / fz0
    };
    let sy = if o.sigmay > 0.0 {
        o.sigmay
    } else {
        p.pty1 * (2.0 * (FZ / (p.pty2 * fz0)).atan()).sin() * r0
    };
    let mut m = model(TransientKind::Relaxation, InputMode::Slips);
    let out = m.step(&tyre, &slips(20.0, 0.0, 0.0), 1e-3).unwrap();
    assert!(
        (out.sigma_x / sx - 1.0).abs() < 1e-9,
        "{} vs {sx}",
        out.sigma_x
    );
    assert!(
        (out.sigma_y / sy - 1.0).abs() < 1e-9,
        "{} vs {sy}",
        out.sigma_y
    );
}

/// Turn slip (use mode with turn slip on) lags with σα: φ'(t) = φt·(1 − e^{−Vt/σα}).
/// σα is the MF's at the same inputs: with turn slip on, the cornering
/// stiffness Kyα (hence σα = Kyα/Cy) carries the turn-slip reduction ζ3, so
/// σα at φt = 0.05 1/m is not the one at φt = 0.
#[test]
fn turn_slip_lags_with_lateral_relaxation_length() {
    let tyre = Tyre::builtin();
    let mode = UseMode::from_code(112).unwrap();
    let (v, phit, dt) = (15.0, 0.05, 1e-3);
    let sy = tyre
        .evaluate(
            &tyrekit::mf::MfInput {
                fz: FZ,
                vx: v,
                phit,
                ..Default::default()
            },
            mode,
        )
        .sigmay;
    assert!(sy > 0.0, "MF gives no sigmay: {sy}");
    let mut m = TransientModel::new(TransientConfig {
        kind: TransientKind::Relaxation,
        input_mode: InputMode::Slips,
        use_mode: mode,
    });
    for k in 1..=200 {
        let mut inp = slips(v, 0.0, 0.0);
        inp.phit = phit;
        m.step(&tyre, &inp, dt).unwrap();
        let expect = phit * (1.0 - (-v * k as f64 * dt / sy).exp());
        assert!((m.state.x[SLOT_PHI] - expect).abs() < 1e-9 * phit);
    }
}

/// Every shared real `.tir` the reader accepts steps through a manoeuvre from
/// standstill to 300 km/h with every model at 1 ms and 10 ms without a panic;
/// every accepted step is finite, and a refused step leaves the state alone.
/// Well-formed files (MF 6.1 example, Pacejka book defaults) are never refused.
#[test]
fn real_tir_files_never_crash() {
    let dir = shared().join("data/tir");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        println!("SKIP: {} not found (shared data absent)", dir.display());
        return;
    };
    let mut files: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("tir")))
        .collect();
    files.sort();
    let mut stepped = 0;
    for f in &files {
        let Ok(tyre) = Tyre::from_file(f) else {
            println!("{}: not accepted by the reader", f.display());
            continue;
        };
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        let must_work =
            name == "MagicFormula61_Parameters.tir" || name == "PacejkaBook_Defaults.tir";
        let fz = if tyre.params().p.fnomin > 0.0 {
            tyre.params().p.fnomin
        } else {
            4000.0
        };
        let r0 = tyre.params().p.unloaded_radius.max(0.1);
        for kind in KINDS {
            for nonlinear in [false, true] {
                for dt in [1e-3, 1e-2] {
                    let o = TransientOptions {
                        nonlinear,
                        ..Default::default()
                    };
                    let mut m = model_opts(kind, InputMode::Velocities, o);
                    let n = (3.0f64 / dt) as usize;
                    for k in 0..n {
                        let t = k as f64 * dt;
                        let vx = 83.3 * (t / 3.0).powi(2);
                        let mut inp = vel(
                            vx,
                            0.5 * (5.0 * t).sin(),
                            vx * (1.0 + 0.2 * (3.0 * t).sin()) / r0,
                        );
                        inp.fz = fz * (1.0 + 0.5 * (7.0 * t).sin());
                        let before = m.state;
                        match m.step(&tyre, &inp, dt) {
                            Ok(out) => {
                                assert!(
                                    out.fx.is_finite() && out.fy.is_finite() && out.mz.is_finite(),
                                    "{name}: {out:?}"
                                );
                                stepped += 1;
                            }
                            Err(e) => {
                                assert!(!must_work, "{name} refused: {e}");
                                assert_eq!(m.state, before);
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(stepped > 0, "no file stepped");
}
