//! `TransientModel::step` allocates nothing (every model, both input modes,
//! including standstill, sliding and the non-linear sub-stepping), counted on
//! the stepping thread by the allocation binary's allocator (`tests/alloc.rs`).

mod common;
use crate::allocations_on_this_thread;
use common::*;
use tyrekit::mf::Tyre;
use tyrekit::transient::{InputMode, TransientOptions};

#[test]
fn step_does_not_allocate() {
    let tyre = Tyre::builtin();
    let mut models = Vec::new();
    for kind in KINDS {
        for mode in [InputMode::Velocities, InputMode::Slips] {
            for nonlinear in [false, true] {
                let o = TransientOptions {
                    nonlinear,
                    ..Default::default()
                };
                models.push(model_opts(kind, mode, o));
            }
        }
    }
    let inputs: Vec<_> = (0..2000)
        .map(|k| {
            let t = k as f64 * 1e-3;
            let vx = 40.0 * (t * 1.5).sin().abs();
            let mut i = vel(
                vx,
                1.5 * (3.0 * t).sin(),
                vx * (1.0 + 0.3 * (2.0 * t).cos()) / 0.3,
            );
            i.kappa_in = 0.3 * (2.0 * t).cos();
            i.alpha_in = 0.2 * (3.0 * t).sin();
            i.mu_scale = if k % 2 == 0 { 1.0 } else { 0.6 };
            i
        })
        .collect();
    let before = allocations_on_this_thread();
    let mut sum = 0.0;
    for m in models.iter_mut() {
        for (k, i) in inputs.iter().enumerate() {
            let dt = if k % 3 == 0 { 1e-2 } else { 1e-4 };
            if let Ok(o) = m.step(&tyre, i, dt) {
                sum += o.fx;
            }
        }
    }
    let after = allocations_on_this_thread();
    assert!(sum.is_finite());
    assert_eq!(after - before, 0, "step allocated {} times", after - before);
}
