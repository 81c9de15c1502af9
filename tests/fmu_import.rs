//! The packaged FMU loaded through the `fmi` crate's importer (rust-fmi, the
//! library fmi-sim is built on), stepped, and compared with the direct library
//! call for the same inputs: the C ABI must not change a single bit.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::traits::FmiImport;
use std::path::PathBuf;
use tyrekit::mf::Tyre;
use tyrekit::transient::{TransientConfig, TransientModel, WheelInput};

/// A freshly packaged FMU of this build, written by `tyrekit package` as a user
/// would (own path: tests run in parallel).
fn fmu(name: &str) -> PathBuf {
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("import-test-{name}"))
        .join("TyreKit.fmu");
    let st = std::process::Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .arg("package")
        .arg("--out")
        .arg(&out)
        .status()
        .expect("running tyrekit package");
    assert!(st.success(), "tyrekit package failed");
    out
}

fn vr(import: &Fmi2Import, name: &str) -> u32 {
    import
        .model_description()
        .model_variables
        .variables
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("variable {name} not in modelDescription.xml"))
        .value_reference
}

#[test]
fn fmi_crate_runs_the_fmu_like_the_library() {
    let path = fmu("steps");
    let import: Fmi2Import = fmi::import::from_path(&path).expect("fmi crate imports the FMU");
    assert_eq!(import.model_description().guid, tyrekit::fmi::GUID);
    let inputs = ["vx", "vy", "omega", "Fz", "gamma"].map(|n| vr(&import, n));
    let outputs = ["Fx", "Fy", "Mx", "My", "Mz", "kappa", "alpha"].map(|n| vr(&import, n));

    let mut inst = import
        .instantiate_cs("rust-fmi", false, false)
        .expect("instantiate");
    // Wrong state: stepping before initialisation is refused.
    assert!(inst.do_step(0.0, 1e-3, true).is_err());
    inst.setup_experiment(None, 0.0, None).expect("setup");
    inst.enter_initialization_mode().expect("enter init");
    inst.exit_initialization_mode().expect("exit init");

    // The very file the FMU loaded (so the test does not depend on the .tir
    // writer/reader round trip being exact).
    let tir = import.archive_path().join("resources").join("tyre.tir");
    let tyre = Tyre::from_file(&tir).expect("packaged tyre file");
    let mut model = TransientModel::new(TransientConfig::default());
    let h = 1e-3;
    let mut y = [0.0; 7];
    let mut max_fy: f64 = 0.0;
    for k in 0..500 {
        let u = [
            20.0,
            -2.0 + 0.008 * k as f64,
            63.0 + 0.01 * k as f64,
            4000.0,
            0.01,
        ];
        inst.set_real(&inputs, &u).expect("set inputs");
        inst.do_step(k as f64 * h, h, true).expect("step");
        inst.get_real(&outputs, &mut y).expect("get outputs");
        let want = model
            .step(
                &tyre,
                &WheelInput {
                    vx: u[0],
                    vy: u[1],
                    omega: u[2],
                    fz: u[3],
                    gamma: u[4],
                    p: 0.0,
                    phit: 0.0,
                    mu_scale: 1.0,
                    kappa_in: 0.0,
                    alpha_in: 0.0,
                },
                h,
            )
            .expect("library step");
        // Same compiled code, same inputs: bit-identical.
        assert_eq!(
            y,
            [want.fx, want.fy, want.mx, want.my, want.mz, want.kappa, want.alpha],
            "step {k}"
        );
        max_fy = max_fy.max(y[1].abs());
    }
    assert!(max_fy > 100.0, "the sweep produced lateral force");
    // Bad input through this importer too: refused, next step fine.
    assert!(inst.set_real(&inputs[..1], &[f64::NAN]).is_err());
    inst.do_step(500.0 * h, h, true)
        .expect("step after refused input");
    inst.terminate().expect("terminate");
}

#[test]
fn fmi_crate_two_instances_are_independent() {
    let path = fmu("two");
    let import: Fmi2Import = fmi::import::from_path(&path).expect("import");
    let vy = vr(&import, "vy");
    let fy = vr(&import, "Fy");
    let start = |name: &str| {
        let mut i = import
            .instantiate_cs(name, false, false)
            .expect("instantiate");
        i.setup_experiment(None, 0.0, None).expect("setup");
        i.enter_initialization_mode().expect("enter");
        i.exit_initialization_mode().expect("exit");
        i
    };
    let (mut a, mut b, mut solo) = (start("a"), start("b"), start("solo"));
    let (mut fa, mut fb, mut fs) = ([0.0], [0.0], [0.0]);
    for k in 0..50 {
        let t = k as f64 * 1e-3;
        a.set_real(&[vy], &[0.02 * k as f64]).expect("set a");
        b.set_real(&[vy], &[-1.0]).expect("set b");
        a.do_step(t, 1e-3, true).expect("a step");
        b.do_step(t, 1e-3, true).expect("b step");
        a.get_real(&[fy], &mut fa).expect("a get");
        b.get_real(&[fy], &mut fb).expect("b get");
        solo.set_real(&[vy], &[0.02 * k as f64]).expect("set solo");
        solo.do_step(t, 1e-3, true).expect("solo step");
        solo.get_real(&[fy], &mut fs).expect("solo get");
        assert_eq!(fa, fs, "instance a disturbed by b at step {k}");
    }
    assert!(fb[0] != fa[0]);
}
