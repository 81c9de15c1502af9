//! The FMU's per-step path allocates nothing: fmi2SetReal (inputs) → fmi2DoStep →
//! fmi2GetReal (outputs), called through the exported C functions, is run under
//! the allocation binary's counting allocator (`tests/alloc.rs`) and must make 0
//! allocations.
//!
//! Only allocations made on the thread that drives the FMU are counted: the FMU
//! runs entirely on its caller's thread, while libtest's harness thread may
//! allocate at any moment as it waits for the test (a CI run on a loaded 2-core
//! machine once saw 2 such allocations in the window).

use crate::allocations_on_this_thread;
use std::ffi::CString;
use tyrekit::fmi::exports::*;
use tyrekit::fmi::types::{Fmi2Status, FMI2_CO_SIMULATION};
use tyrekit::fmi::vars::vr;

#[test]
fn step_path_does_not_allocate() {
    // `common::scratch` spelled out (in the allocation binary, tests/alloc.rs,
    // `common` is a private module of transient_alloc): a fresh folder,
    // removed when `tmp` drops.
    let tmp = tempfile::Builder::new()
        .prefix("tyrekit-alloc-")
        .tempdir()
        .unwrap();
    let dir = tmp.path();
    tyrekit::tir::TyreParams::builtin()
        .write(&dir.join("tyre.tir"))
        .unwrap();
    // Every transient model (and the non-linear relaxation variant), from
    // VXLOW up and below it (the low-speed offset correction, LuGre sub-steps).
    for (kind, nonlinear) in [
        ("steady", false),
        ("relaxation", false),
        ("relaxation", true),
        ("lugre", false),
    ] {
        steps_without_allocation(dir, kind, nonlinear);
    }
}

fn steps_without_allocation(dir: &std::path::Path, kind: &str, nonlinear: bool) {
    let name = CString::new("alloc").unwrap();
    let kind_c = CString::new(kind).unwrap();
    let guid = CString::new(tyrekit::fmi::GUID).unwrap();
    let res = CString::new(format!("file://{}", dir.display())).unwrap();
    let ok = Fmi2Status::Ok;
    unsafe {
        let c = fmi2Instantiate(
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            guid.as_ptr(),
            res.as_ptr(),
            std::ptr::null(),
            0,
            0,
        );
        assert!(!c.is_null());
        let kv = [kind_c.as_ptr()];
        assert_eq!(
            fmi2SetString(c, [vr::TRANSIENT].as_ptr(), 1, kv.as_ptr()),
            ok
        );
        let nl = [i32::from(nonlinear)];
        assert_eq!(
            fmi2SetBoolean(c, [vr::NONLINEAR].as_ptr(), 1, nl.as_ptr()),
            ok
        );
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), ok);
        assert_eq!(fmi2EnterInitializationMode(c), ok);
        assert_eq!(fmi2ExitInitializationMode(c), ok);
        let inputs = [vr::VX, vr::VY, vr::OMEGA, vr::FZ, vr::GAMMA];
        let outputs = [vr::FX, vr::FY, vr::MX, vr::MY, vr::MZ, vr::KAPPA, vr::ALPHA];
        let mut y = [0.0; 7];
        let before = allocations_on_this_thread();
        for k in 0..1000 {
            let vx = if k < 500 { 20.0 } else { 0.5 };
            let u = [vx, 0.001 * k as f64, vx * 3.15, 4000.0, 0.0];
            assert_eq!(
                fmi2SetReal(c, inputs.as_ptr(), inputs.len(), u.as_ptr()),
                ok
            );
            assert_eq!(fmi2DoStep(c, k as f64 * 1e-3, 1e-3, 1), ok);
            assert_eq!(
                fmi2GetReal(c, outputs.as_ptr(), outputs.len(), y.as_mut_ptr()),
                ok
            );
        }
        let after = allocations_on_this_thread();
        assert!(y[1].is_finite());
        fmi2FreeInstance(c);
        assert_eq!(
            after - before,
            0,
            "allocations in 1000 steps (transient {kind}, nonlinear {nonlinear})"
        );
    }
}
