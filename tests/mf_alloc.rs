//! `Tyre::evaluate`, `evaluate_checked` and `forces` allocate nothing:
//! counted with the allocation binary's global allocator (`tests/alloc.rs`).
//!
//! The count is per thread: the test harness's own threads (output capture,
//! the slow-test watcher) allocate at any time, and CI once saw 4 of their
//! allocations land inside the measured window. Only the evaluating thread's
//! allocations say anything about the model.

use crate::allocations_on_this_thread;
use tyrekit::mf::{MfInput, Tyre, UseMode};

#[test]
fn evaluation_does_not_allocate() {
    let mut tyres = vec![Tyre::builtin()];
    for (v, f) in [
        (tyrekit::tir::MfVersion::Mf62, 62.0),
        (tyrekit::tir::MfVersion::Pac2002, 0.0),
    ] {
        let mut p = tyrekit::tir::TyreParams::builtin();
        p.version = v;
        p.p.fittyp = f;
        tyres.push(Tyre::new(p).unwrap());
    }
    let inputs: Vec<MfInput> = (0..50)
        .map(|i| MfInput {
            fz: 200.0 * i as f64 - 500.0,
            kappa: 0.03 * i as f64 - 0.7,
            alpha: 0.02 * i as f64 - 0.5,
            gamma: 0.004 * i as f64 - 0.1,
            phit: if i % 3 == 0 { 0.1 } else { 0.0 },
            vx: 0.5 * i as f64 - 2.0,
            p: 0.0,
            omega: 0.0,
        })
        .collect();
    let modes: Vec<UseMode> = [111, 112, 121, 211, 212, 222]
        .iter()
        .map(|&c| UseMode::from_code(c).unwrap())
        .collect();
    let before = allocations_on_this_thread();
    let mut acc = 0.0;
    for t in &tyres {
        for m in &modes {
            for x in &inputs {
                acc += t.evaluate(x, *m).fx + t.forces(x, *m).mz + t.evaluate_checked(x, *m).0.rl;
            }
        }
    }
    let after = allocations_on_this_thread();
    std::hint::black_box(acc);
    assert_eq!(
        after,
        before,
        "evaluation allocated {} times",
        after - before
    );
}
