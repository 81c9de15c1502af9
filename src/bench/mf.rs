//! Benchmark section `mf`: nanoseconds per steady-state Magic Formula
//! evaluation on one core — `Tyre::forces` (combined slip: Fx, Fy, Mx, My, Mz)
//! and `Tyre::evaluate` (all 30 outputs) — beside the same workload in
//! Python: a NumPy-vectorised MF 6.1 combined-slip implementation
//! (`python/bench_mf.py`, checked against ours on a few points) and the PyPI
//! `pacejka` package where it applies.
//!
//! Must never: assert on timings, or fail when Python or a package is missing
//! (print "skipped: …" instead).

use super::BenchContext;
use crate::mf::{Forces, MfInput, Tyre, UseMode};
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Instant;

/// Keys the Python implementation needs (MF 6.1 combined slip, no turn slip).
const PY_KEYS: &[&str] = &[
    "FNOMIN",
    "UNLOADED_RADIUS",
    "LONGVL",
    "NOMPRES",
    "FZMIN",
    "LFZO",
    "LCX",
    "LMUX",
    "LEX",
    "LKX",
    "LHX",
    "LVX",
    "LCY",
    "LMUY",
    "LEY",
    "LKY",
    "LKYC",
    "LKZC",
    "LHY",
    "LVY",
    "LTR",
    "LRES",
    "LXAL",
    "LYKA",
    "LVYKA",
    "LS",
    "LMX",
    "LVMX",
    "LMY",
    "PCX1",
    "PDX1",
    "PDX2",
    "PDX3",
    "PEX1",
    "PEX2",
    "PEX3",
    "PEX4",
    "PKX1",
    "PKX2",
    "PKX3",
    "PHX1",
    "PHX2",
    "PVX1",
    "PVX2",
    "PPX1",
    "PPX2",
    "PPX3",
    "PPX4",
    "RBX1",
    "RBX2",
    "RBX3",
    "RCX1",
    "REX1",
    "REX2",
    "RHX1",
    "QSX1",
    "QSX2",
    "QSX3",
    "QSX4",
    "QSX5",
    "QSX6",
    "QSX7",
    "QSX8",
    "QSX9",
    "QSX10",
    "QSX11",
    "QSX12",
    "QSX13",
    "QSX14",
    "PPMX1",
    "PCY1",
    "PDY1",
    "PDY2",
    "PDY3",
    "PEY1",
    "PEY2",
    "PEY3",
    "PEY4",
    "PEY5",
    "PKY1",
    "PKY2",
    "PKY3",
    "PKY4",
    "PKY5",
    "PKY6",
    "PKY7",
    "PHY1",
    "PHY2",
    "PVY1",
    "PVY2",
    "PVY3",
    "PVY4",
    "PPY1",
    "PPY2",
    "PPY3",
    "PPY4",
    "PPY5",
    "RBY1",
    "RBY2",
    "RBY3",
    "RBY4",
    "RCY1",
    "REY1",
    "REY2",
    "RHY1",
    "RHY2",
    "RVY1",
    "RVY2",
    "RVY3",
    "RVY4",
    "RVY5",
    "RVY6",
    "QSY1",
    "QSY2",
    "QSY3",
    "QSY4",
    "QSY5",
    "QSY6",
    "QSY7",
    "QSY8",
    "QBZ1",
    "QBZ2",
    "QBZ3",
    "QBZ4",
    "QBZ5",
    "QBZ9",
    "QBZ10",
    "QCZ1",
    "QDZ1",
    "QDZ2",
    "QDZ3",
    "QDZ4",
    "QDZ6",
    "QDZ7",
    "QDZ8",
    "QDZ9",
    "QDZ10",
    "QDZ11",
    "QEZ1",
    "QEZ2",
    "QEZ3",
    "QEZ4",
    "QEZ5",
    "QHZ1",
    "QHZ2",
    "QHZ3",
    "QHZ4",
    "PPZ1",
    "PPZ2",
    "SSZ1",
    "SSZ2",
    "SSZ3",
    "SSZ4",
];

/// Varied inputs inside the tyre's ranges, above VXLOW (so use mode 111
/// clips nothing and the Python implementation needs no limit logic).
fn inputs(tyre: &Tyre, n: usize) -> Vec<MfInput> {
    let p = &tyre.params().p;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
    (0..n)
        .map(|_| MfInput {
            fz: p.fnomin * rng.gen_range(0.3..1.8),
            kappa: rng.gen_range(-0.25..0.25),
            alpha: rng.gen_range(-0.25..0.25),
            gamma: rng.gen_range(-0.08..0.08),
            phit: 0.0,
            vx: rng.gen_range(3.0..40.0),
            p: p.nompres * rng.gen_range(0.85..1.15),
            omega: 0.0,
        })
        .collect()
}

/// Best-of-`reps` nanoseconds per call of `f` over all inputs.
fn time_ns(inp: &[MfInput], reps: usize, mut f: impl FnMut(&MfInput) -> f64) -> f64 {
    // One untimed pass first (page faults, caches, frequency ramp-up).
    black_box(inp.iter().map(|x| f(black_box(x))).sum::<f64>());
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t0 = cpu_ns();
        let mut acc = 0.0;
        for x in inp {
            acc += f(black_box(x));
        }
        black_box(acc);
        best = best.min((cpu_ns() - t0) / inp.len() as f64);
    }
    best
}

/// CPU time of this thread (ns): the machine is shared, so wall time would
/// mostly measure other processes. Falls back to wall time if unavailable.
pub(super) fn cpu_ns() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 * 1e9 + ts.tv_nsec as f64
    } else {
        wall_origin().elapsed().as_nanos() as f64
    }
}

fn wall_origin() -> Instant {
    static ORIGIN: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    *ORIGIN.get_or_init(Instant::now)
}

/// Run this section, printing its figures.
pub fn run(ctx: &BenchContext) -> crate::Result<()> {
    let tyre = Tyre::builtin();
    let mode = UseMode::default();
    let n = if ctx.quick { 20_000 } else { 200_000 };
    let reps = if ctx.quick { 3 } else { 7 };
    let inp = inputs(&tyre, n);
    println!(
        "[mf] built-in MF 6.1 tyre, use mode 111, {n} varied inputs, one core, thread CPU time, best of {reps}"
    );
    let sum = |f: Forces| f.fx + f.fy + f.mx + f.my + f.mz;
    let ns_forces = time_ns(&inp, reps, |x| sum(tyre.forces(x, mode)));
    let ns_eval = time_ns(&inp, reps, |x| tyre.evaluate(x, mode).re);
    println!("[mf] Tyre::forces   (Fx Fy Mx My Mz, combined slip): {ns_forces:8.1} ns/eval");
    println!("[mf] Tyre::evaluate (all 30 outputs):                {ns_eval:8.1} ns/eval");
    let ns_mu = time_ns(&inp, reps, |x| sum(tyre.forces_mu(x, mode, 0.6)));
    let ns_props = time_ns(&inp, reps, |x| tyre.slip_properties(x, mode).kya);
    println!("[mf] Tyre::forces_mu (road friction scale 0.6):      {ns_mu:8.1} ns/eval");
    println!("[mf] Tyre::slip_properties (zero-slip Re, C, K, σ, μ): {ns_props:8.1} ns/eval");
    let ns_xy = time_ns(&inp, reps, |x| {
        let (fx, fy) = tyre.forces_xy(x, mode, 1.0, None);
        fx + fy
    });
    let ns_parts = time_ns(&inp, reps, |x| {
        tyre.slip_properties_terms(x, mode, 1.0, false, true).0.kya
    });
    let ns_radius = time_ns(&inp, reps, |x| tyre.zero_slip_radius(x, mode));
    let ns_fp = time_ns(&inp, reps, |x| {
        let (f, p) = tyre.forces_and_props(x, mode, 1.0);
        sum(f) + p.sigmay
    });
    println!("[mf] Tyre::forces_xy (Fx Fy only, no moments):        {ns_xy:8.1} ns/eval");
    println!("[mf] Tyre::slip_properties_terms (no Fx Fy; the transient models' probe): {ns_parts:8.1} ns/eval");
    println!("[mf] the steady step's MF: Tyre::zero_slip_radius {ns_radius:.1} ns + Tyre::forces_and_props {ns_fp:.1} ns");
    // A fully populated MF 6.1 file (every curvature factor and shift non-zero,
    // so none of the zero-coefficient shortcuts applies), when the shared data
    // is there; the Python peers then run on it.
    let shared = match std::env::var_os("TYREKIT_SHARED") {
        Some(s) => std::path::PathBuf::from(s),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared"),
    };
    let full = shared.join("data/tir/MagicFormula61_Parameters.tir");
    let (peer_tyre, peer_inp, peer_ns) = match Tyre::from_file(&full) {
        Ok(t61) => {
            let inp61 = inputs(&t61, n);
            let ns61 = time_ns(&inp61, reps, |x| sum(t61.forces(x, mode)));
            println!("[mf] Tyre::forces, MFeval's MagicFormula61_Parameters.tir: {ns61:8.1} ns/eval (used for the peers)");
            (t61, inp61, ns61)
        }
        Err(_) => {
            println!("[mf] skipped: MagicFormula61_Parameters.tir (shared data not found); peers use the built-in tyre");
            (tyre, inp, ns_forces)
        }
    };
    python_peers(ctx, &peer_tyre, mode, &peer_inp, peer_ns);
    Ok(())
}

/// The Python peers: write the tyre values and the inputs, run
/// `python/bench_mf.py`, check agreement, print ratios.
fn python_peers(ctx: &BenchContext, tyre: &Tyre, mode: UseMode, inp: &[MfInput], ns_forces: f64) {
    let Some(py) = &ctx.python else {
        println!("[mf] skipped: Python peers (no Python interpreter given)");
        return;
    };
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("python/bench_mf.py");
    if !script.exists() {
        println!(
            "[mf] skipped: Python peers ({} not found)",
            script.display()
        );
        return;
    }
    let scratch = match super::ScratchDir::new("mf") {
        Ok(s) => s,
        Err(e) => {
            // `e` reads "PATH: reason", as this message always did.
            println!("[mf] skipped: Python peers (cannot create {e})");
            return;
        }
    };
    let dir = scratch.path();
    let p = &tyre.params().p;
    let params: serde_json::Map<String, serde_json::Value> = PY_KEYS
        .iter()
        .map(|k| {
            (
                k.to_string(),
                serde_json::json!(p.get(k).unwrap_or(f64::NAN)),
            )
        })
        .collect();
    let mut csv = String::from("Fz,kappa,alpha,gamma,Vx,P\n");
    for x in inp {
        csv.push_str(&format!(
            "{:?},{:?},{:?},{:?},{:?},{:?}\n",
            x.fz, x.kappa, x.alpha, x.gamma, x.vx, x.p
        ));
    }
    let (pj, ic) = (dir.join("params.json"), dir.join("inputs.csv"));
    let written = std::fs::write(&pj, serde_json::Value::Object(params).to_string())
        .and_then(|_| std::fs::write(&ic, csv));
    if let Err(e) = written {
        println!("[mf] skipped: Python peers (cannot write inputs: {e})");
        return;
    }
    let out = std::process::Command::new(py)
        .arg(&script)
        .arg(&pj)
        .arg(&ic)
        .arg(if ctx.quick { "3" } else { "7" })
        .output();
    let out = match out {
        Ok(o) => o,
        Err(e) => {
            println!(
                "[mf] skipped: Python peers (cannot run {}: {e})",
                py.display()
            );
            return;
        }
    };
    let text = String::from_utf8_lossy(&out.stdout);
    let Some(json) = text
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
    else {
        println!(
            "[mf] skipped: Python peers (bench_mf.py gave no result: {})",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
        return;
    };
    // Agreement on the first points: ours vs NumPy.
    if let Some(rows) = json["check"].as_array() {
        let mut worst = 0.0f64;
        for (i, r) in rows.iter().enumerate() {
            let f = tyre.forces(&inp[i], mode);
            for (k, v) in [f.fx, f.fy, f.mx, f.my, f.mz].iter().enumerate() {
                let theirs = r[k].as_f64().unwrap_or(f64::NAN);
                worst = worst.max((theirs - v).abs() / v.abs().max(1.0));
            }
        }
        println!(
            "[mf] NumPy MF 6.1 agrees with tyrekit on {} points: max rel diff {worst:.1e}{}",
            rows.len(),
            if worst < 1e-9 { "" } else { "  (DISAGREES)" }
        );
    }
    match json["numpy_ns"].as_f64() {
        Some(ns) => println!(
            "[mf] NumPy-vectorised MF 6.1 (Fx Fy Mx My Mz):        {ns:8.1} ns/eval  (peer / tyrekit forces = {:.2})",
            ns / ns_forces
        ),
        None => println!("[mf] skipped: NumPy MF 6.1 ({})", json["numpy_error"].as_str().unwrap_or("not run")),
    }
    match json["pacejka_ns"].as_f64() {
        Some(ns) => println!(
            "[mf] PyPI pacejka {} calculate_forces (Fx Fy only):  {ns:8.1} ns/eval  (peer / tyrekit forces = {:.2})\n\
             [mf]   note: `pacejka` is a 4-coefficient B,C,D,E formula with a friction circle; it cannot read a\n\
             [mf]   .tir or evaluate MF 6.1 (no pressure, camber, Mx/My/Mz), so this only times its Fx,Fy.",
            json["pacejka_version"].as_str().unwrap_or("?"),
            ns / ns_forces
        ),
        None => println!("[mf] skipped: PyPI pacejka ({})", json["pacejka_error"].as_str().unwrap_or("not run")),
    }
}
