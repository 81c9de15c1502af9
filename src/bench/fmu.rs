//! Benchmark section `fmu`: the cost of one co-simulation step through the C
//! ABI as a master sees it — fmi2SetReal of the 10 inputs, fmi2DoStep,
//! fmi2GetReal of the 14 Real outputs — on the packaged FMU loaded with dlopen,
//! beside the direct library call (`TransientModel::step`) for the same inputs.
//! Goal (issue #3): ≤ 250 ns per step for the steady-state tyre.
//! Must never: assert on timings (figures are printed, not tested).

use crate::fmi::master::{callbacks, Fmu};
use crate::fmi::packaging;
use crate::fmi::vars::vr;
use crate::mf::Tyre;
use crate::tir::TyreParams;
use crate::transient::{TransientConfig, TransientModel, WheelInput};
use std::hint::black_box;
use std::time::Instant;

const INPUTS: [u32; 10] = [
    vr::VX,
    vr::VY,
    vr::OMEGA,
    vr::FZ,
    vr::GAMMA,
    vr::P,
    vr::PHIT,
    vr::MU_SCALE,
    vr::KAPPA_IN,
    vr::ALPHA_IN,
];
const OUTPUTS: [u32; 14] = [
    vr::FX,
    vr::FY,
    vr::MX,
    vr::MY,
    vr::MZ,
    vr::KAPPA,
    vr::ALPHA,
    vr::RE,
    vr::MUX,
    vr::MUY,
    vr::VSX,
    vr::VSY,
    vr::SIGMA_X,
    vr::SIGMA_Y,
];

/// Inputs of step `k`: free rolling at 20 m/s with a small lateral-speed sweep.
fn inputs(k: usize) -> [f64; 10] {
    let vy = 0.5 * ((k % 1000) as f64 / 1000.0 - 0.5);
    [20.0, vy, 63.8, 4000.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
}

/// Run this section, printing its figures.
pub fn run(ctx: &super::BenchContext) -> crate::Result<()> {
    let n: usize = if ctx.quick { 20_000 } else { 1_000_000 };
    let h = 1e-3;
    println!("[fmu] one co-simulation step, steady-state tyre, {n} steps");

    // Direct library call.
    let tyre = Tyre::new(TyreParams::builtin())?;
    let mut model = TransientModel::new(TransientConfig::default());
    let t0 = Instant::now();
    let mut acc = 0.0;
    for k in 0..n {
        let u = inputs(k);
        let w = WheelInput {
            vx: u[0],
            vy: u[1],
            omega: u[2],
            fz: u[3],
            gamma: u[4],
            p: u[5],
            phit: u[6],
            mu_scale: u[7],
            kappa_in: u[8],
            alpha_in: u[9],
        };
        acc += model.step(&tyre, black_box(&w), h)?.fy;
    }
    black_box(acc);
    let direct = t0.elapsed().as_secs_f64() * 1e9 / n as f64;

    // Through the C ABI of the packaged FMU.
    let fmu_path = packaging::package(&packaging::Options {
        out: Some(
            packaging::target_dir()
                .join("fmu")
                .join("bench")
                .join("TyreKit.fmu"),
        ),
        ..Default::default()
    })?;
    let dir = packaging::target_dir()
        .join("fmu")
        .join(format!("bench-{}", std::process::id()));
    let result = (|| -> crate::Result<f64> {
        let fmu = Fmu::open(&fmu_path, &dir)?;
        let cb = callbacks();
        let s = fmu.slave("bench", &cb, &[])?;
        s.exit_initialization()?;
        let mut y = [0.0; 14];
        let t0 = Instant::now();
        let mut acc = 0.0;
        for k in 0..n {
            s.set_real(&INPUTS, black_box(&inputs(k)))?;
            s.do_step(k as f64 * h, h)?;
            s.get_real(&OUTPUTS, &mut y)?;
            acc += y[1];
        }
        black_box(acc);
        Ok(t0.elapsed().as_secs_f64() * 1e9 / n as f64)
    })();
    let _ = std::fs::remove_dir_all(&dir);
    let abi = result?;
    println!("  direct TransientModel::step            {direct:>9.1} ns/step");
    println!(
        "  FMU C ABI (SetReal 10, DoStep, GetReal 14) {abi:>6.1} ns/step  ({:.2}x direct, overhead {:.1} ns; goal <= 250 ns: {})",
        abi / direct,
        abi - direct,
        if abi <= 250.0 { "met" } else { "NOT met" }
    );
    Ok(())
}
