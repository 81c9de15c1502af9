//! Benchmark section `brush`: nanoseconds per brush evaluation
//! (`BrushParams::forces`, Fx Fy Mz, combined slip) for M = 10, 20, 40, 80,
//! 160 contact points — rigid and string carcass — beside the Magic Formula's
//! combined-slip `Tyre::forces` measured in the same run (ratios), the
//! transient step with the brush as its force model, and the accuracy of each
//! M (change of Fy against M = M_MAX over a slip sweep), so the M for a 1 kHz
//! real-time step can be chosen from cost against accuracy.
//!
//! Must never: assert on timings; M beyond the solver's capacity (M_MAX) is
//! reported as not available, not silently clamped.

use super::transient::time_ns;
use crate::brush::{BrushInput, BrushParams, M_MAX};
use crate::mf::{MfInput, Tyre, UseMode};
use crate::transient::{
    InputMode, TransientConfig, TransientKind, TransientModel, TransientOptions, WheelInput,
};
use std::hint::black_box;

/// The contact point counts the issue asks about, and M_MAX = 64.
const POINTS: [usize; 6] = [10, 20, 40, 64, 80, 160];

/// A slip/load sequence over the whole curve (α within ±8°, κ within ±0.05,
/// Fz 4000 ± 1500 N), so the adhesion boundary moves through the patch and
/// the string carcass' bisection runs its full course.
fn slips(i: usize) -> (f64, f64, f64) {
    let t = i as f64 * 1e-3;
    (
        4000.0 + 1500.0 * (3.0 * t).sin(),
        0.05 * (1.7 * t).sin(),
        (8f64.to_radians() * (0.9 * t).sin()).tan(),
    )
}

/// Largest |Fy(M) − Fy(M_MAX)| / Fz over pure side slip α = 0.5..10° at FNOMIN.
fn accuracy(b: &BrushParams, m: usize) -> f64 {
    let fy = |m: usize, t: f64| {
        BrushParams { points: m, ..*b }
            .forces(&BrushInput::new(b.fz0, 0.0, t))
            .fy
    };
    (1..=20)
        .map(|k| (0.5 * k as f64).to_radians().tan())
        .map(|t| (fy(m, t) - fy(M_MAX, t)).abs() / b.fz0)
        .fold(0.0, f64::max)
}

/// Run this section, printing its figures.
pub fn run(ctx: &super::BenchContext) -> crate::Result<()> {
    let tyre = Tyre::builtin();
    let (flex, _) = BrushParams::from_tyre(&tyre)?;
    let rigid = BrushParams {
        compliance: 0.0,
        ..flex
    };
    let (n, reps) = if ctx.quick { (5_000, 1) } else { (50_000, 3) };
    let mf_ns = time_ns(n, reps, |i| {
        let (fz, kappa, ta) = slips(i);
        let mi = MfInput {
            fz,
            kappa,
            alpha: ta.atan(),
            vx: 20.0,
            ..Default::default()
        };
        black_box(tyre.forces(black_box(&mi), UseMode::default()));
    });
    println!("[brush] MF forces() (reference)                  {mf_ns:9.1} ns");
    println!(
        "[brush]   M   rigid carcass           string carcass          max |dFy|/Fz vs M={M_MAX}"
    );
    for m in POINTS {
        if m > M_MAX {
            println!("[brush] {m:3}   not available: the solver's stack capacity is M_MAX = {M_MAX} points");
            continue;
        }
        let mut t = [0.0; 2];
        for (k, b) in [rigid, flex].iter().enumerate() {
            let b = BrushParams { points: m, ..*b };
            t[k] = time_ns(n, reps, |i| {
                let (fz, kappa, ta) = slips(i);
                black_box(b.forces(black_box(&BrushInput::new(fz, kappa, ta))));
            });
        }
        println!(
            "[brush] {m:3}   {:9.1} ns ({:6.1}× MF)  {:9.1} ns ({:6.1}× MF)  {:.2e}",
            t[0],
            t[0] / mf_ns,
            t[1],
            t[1] / mf_ns,
            accuracy(&flex, m)
        );
    }
    // The transient step with the brush as its force model (M = the file's POINTS).
    for (name, kind) in [
        ("steady", TransientKind::Steady),
        ("relaxation", TransientKind::Relaxation),
    ] {
        let cfg = TransientConfig {
            kind,
            input_mode: InputMode::Slips,
            use_mode: UseMode::default(),
        };
        let mut step_ns = [0.0; 2];
        for (k, brush) in [None, Some(flex)].into_iter().enumerate() {
            let opts = TransientOptions {
                brush,
                ..Default::default()
            };
            let mut model = TransientModel::with_options(cfg, opts);
            let mut failed = false;
            step_ns[k] = time_ns(n, reps, |i| {
                let (fz, kappa, ta) = slips(i);
                let w = WheelInput {
                    vx: 20.0,
                    fz,
                    kappa_in: kappa,
                    alpha_in: ta.atan(),
                    mu_scale: 1.0,
                    ..Default::default()
                };
                match model.step(&tyre, black_box(&w), 1e-3) {
                    Ok(o) => {
                        black_box(o);
                    }
                    Err(_) => failed = true,
                }
            });
            if failed {
                return Err(crate::Error::Other(format!(
                    "bench brush: transient step '{name}' failed"
                )));
            }
        }
        println!(
            "[brush] transient step {name:<11} force model brush (M = {}) {:9.1} ns vs mf {:9.1} ns ({:.1}×)",
            flex.points,
            step_ns[1],
            step_ns[0],
            step_ns[1] / step_ns[0]
        );
    }
    Ok(())
}
