//! The FMU's per-step path allocates nothing: fmi2SetReal (inputs) → fmi2DoStep →
//! fmi2GetReal (outputs), called through the exported C functions, is run with a
//! counting global allocator (this test binary only) and must make 0 allocations.
//!
//! Only allocations made on the thread that drives the FMU are counted (a
//! thread-local switch): the FMU runs entirely on its caller's thread, while
//! libtest's harness thread may allocate at any moment as it waits for the test
//! (a CI run on a loaded 2-core machine saw 2 such allocations in the window).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::CString;
use std::sync::atomic::{AtomicUsize, Ordering};
use tyrekit::fmi::exports::*;
use tyrekit::fmi::types::{Fmi2Status, FMI2_CO_SIMULATION};
use tyrekit::fmi::vars::vr;

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// True while this thread's allocations are counted (const-initialised,
    /// no destructor: reading it from the allocator never allocates).
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        System.realloc(p, l, n)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn step_path_does_not_allocate() {
    // The counter itself works: a deliberate allocation on this thread is seen.
    let n0 = ALLOCATIONS.load(Ordering::Relaxed);
    COUNTING.with(|f| f.set(true));
    let probe = std::hint::black_box(vec![0u8; 64]);
    COUNTING.with(|f| f.set(false));
    drop(probe);
    assert!(
        ALLOCATIONS.load(Ordering::Relaxed) > n0,
        "counting allocator is not counting"
    );
    let dir = std::env::temp_dir().join(format!("tyrekit-alloc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
        steps_without_allocation(&dir, kind, nonlinear);
    }
    let _ = std::fs::remove_dir_all(dir);
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
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        COUNTING.with(|f| f.set(true));
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
        COUNTING.with(|f| f.set(false));
        let after = ALLOCATIONS.load(Ordering::Relaxed);
        assert!(y[1].is_finite());
        fmi2FreeInstance(c);
        assert_eq!(
            after - before,
            0,
            "allocations in 1000 steps (transient {kind}, nonlinear {nonlinear})"
        );
    }
}
