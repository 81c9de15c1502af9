//! Helpers shared by the integration tests: the shared-data path, per-test
//! scratch folders, reference CSV reading, and the transient tests' models,
//! inputs and expectations.
#![allow(dead_code, unused_imports)]

use std::path::{Path, PathBuf};

/// `../shared` next to the crate, or `$TYREKIT_SHARED` (for worktrees that
/// live elsewhere). Tests skip with a message when it is absent.
pub fn shared() -> PathBuf {
    let p = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared")).to_path_buf();
    match std::env::var_os("TYREKIT_SHARED") {
        Some(s) if !p.exists() => PathBuf::from(s),
        _ => p,
    }
}

/// A test's scratch folder: a fresh `tyrekit-{tag}-XXXXXX` under the system
/// temp dir, removed (with everything in it) when the returned guard drops —
/// at the end of the test, also when the test panics. Bind the guard to a
/// named variable (`let d = scratch("…");`, never `_`) that lives until the
/// last use of its files, and use `d.path()`.
///
/// With the environment variable `TYREKIT_KEEP` set (to anything) the folder
/// is kept instead and its path printed to stderr, for looking at a test's
/// outputs afterwards.
pub fn scratch(tag: &str) -> tempfile::TempDir {
    let prefix = format!("tyrekit-{tag}-");
    let mut d = tempfile::Builder::new()
        .prefix(&prefix)
        .tempdir()
        .unwrap_or_else(|e| panic!("scratch folder {prefix}*: {e}"));
    if std::env::var_os("TYREKIT_KEEP").is_some() {
        d.disable_cleanup(true);
        eprintln!("kept {}", d.path().display());
    }
    d
}

/// A CSV number with MATLAB/Octave's NaN/Inf spelling.
#[allow(dead_code)]
pub fn num(s: &str) -> f64 {
    match s {
        "NaN" | "" => f64::NAN,
        "Inf" => f64::INFINITY,
        "-Inf" => f64::NEG_INFINITY,
        _ => s.parse().unwrap_or_else(|_| panic!("bad number {s:?}")),
    }
}

/// The 8 MFeval inputs of a reference CSV row (`col` maps a header name to
/// its index).
#[allow(dead_code)]
pub fn reference_input(r: &[f64], col: impl Fn(&str) -> usize) -> tyrekit::mf::MfInput {
    tyrekit::mf::MfInput {
        fz: r[col("in_Fz")],
        kappa: r[col("in_kappa")],
        alpha: r[col("in_alpha")],
        gamma: r[col("in_gamma")],
        phit: r[col("in_phit")],
        vx: r[col("in_Vx")],
        p: r[col("in_P")],
        omega: r[col("in_omega")],
    }
}

use tyrekit::mf::{MfInput, MfOutput, Tyre, UseMode};
use tyrekit::transient::{
    InputMode, TransientConfig, TransientKind, TransientModel, TransientOptions, WheelInput,
};

pub const G: f64 = 9.81;

/// Every transient model kind.
pub const KINDS: [TransientKind; 3] = [
    TransientKind::Steady,
    TransientKind::Relaxation,
    TransientKind::LuGre,
];

/// A velocity-input model of `kind` driven `n` steps of 1 ms with `inp`.
pub fn driven(tyre: &Tyre, kind: TransientKind, n: usize, inp: WheelInput) -> TransientModel {
    let mut m = model(kind, InputMode::Velocities);
    for _ in 0..n {
        m.step(tyre, &inp, 1e-3).expect("driving step");
    }
    m
}
pub const FZ: f64 = 4000.0;

pub fn model(kind: TransientKind, mode: InputMode) -> TransientModel {
    TransientModel::new(TransientConfig {
        kind,
        input_mode: mode,
        use_mode: UseMode::default(),
    })
}

pub fn model_opts(kind: TransientKind, mode: InputMode, o: TransientOptions) -> TransientModel {
    TransientModel::with_options(
        TransientConfig {
            kind,
            input_mode: mode,
            use_mode: UseMode::default(),
        },
        o,
    )
}

/// Prescribed-slip input at speed `vx`.
pub fn slips(vx: f64, kappa: f64, alpha: f64) -> WheelInput {
    WheelInput {
        vx,
        omega: 0.0,
        fz: FZ,
        mu_scale: 1.0,
        kappa_in: kappa,
        alpha_in: alpha,
        ..Default::default()
    }
}

/// Velocity input.
pub fn vel(vx: f64, vy: f64, omega: f64) -> WheelInput {
    WheelInput {
        vx,
        vy,
        omega,
        fz: FZ,
        mu_scale: 1.0,
        ..Default::default()
    }
}

/// The steady Magic Formula at (κ, α) and speed vx, for the same load.
pub fn mf(tyre: &Tyre, vx: f64, kappa: f64, alpha: f64) -> MfOutput {
    tyre.evaluate(
        &MfInput {
            fz: FZ,
            kappa,
            alpha,
            vx,
            ..Default::default()
        },
        UseMode::default(),
    )
}

/// Relaxation lengths the MF implies for this tyre at FZ (MfOutput σ when the
/// MF gives them, else |K|/C from the MF's slip stiffnesses and the file's
/// carcass stiffnesses — the documented fallback of a placeholder MF).
pub fn mf_sigmas(tyre: &Tyre) -> (f64, f64) {
    let o = mf(tyre, 20.0, 0.0, 0.0);
    let p = &tyre.params().p;
    let cx = if o.cx > 0.0 {
        o.cx
    } else {
        p.longitudinal_stiffness
    };
    let cy = if o.cy > 0.0 {
        o.cy
    } else {
        p.lateral_stiffness
    };
    let sx = if o.sigmax > 0.0 {
        o.sigmax
    } else {
        o.kxk.abs() / cx
    };
    let sy = if o.sigmay > 0.0 {
        o.sigmay
    } else {
        o.kya.abs() / cy
    };
    (sx, sy)
}

/// Carcass stiffnesses (N/m) the MF implies at FZ.
pub fn carcass(tyre: &Tyre) -> (f64, f64) {
    let o = mf(tyre, 0.0, 0.0, 0.0);
    let p = &tyre.params().p;
    (
        if o.cx > 0.0 {
            o.cx
        } else {
            p.longitudinal_stiffness
        },
        if o.cy > 0.0 {
            o.cy
        } else {
            p.lateral_stiffness
        },
    )
}

/// Effective rolling radius the MF gives at FZ, speed vx.
pub fn re(tyre: &Tyre, vx: f64) -> f64 {
    let o = mf(tyre, vx, 0.0, 0.0);
    if o.re > 0.0 {
        o.re
    } else {
        tyre.params().p.unloaded_radius
    }
}

/// Spin rate Ω at which the wheel at speed vx (> 0) has slip ratio κ, i.e.
/// Ω·Re(Ω) = vx·(1 + κ), with the MF's Re at that Ω (fixed point; Re varies
/// weakly with Ω, so it converges in a few iterations).
pub fn omega_for(tyre: &Tyre, vx: f64, kappa: f64) -> f64 {
    let mut om = vx * (1.0 + kappa) / re(tyre, vx);
    for _ in 0..50 {
        let o = tyre.evaluate(
            &MfInput {
                fz: FZ,
                vx,
                omega: om,
                ..Default::default()
            },
            UseMode::default(),
        );
        om = vx * (1.0 + kappa) / o.re;
    }
    om
}

/// Least-squares amplitude and phase (rad) of `y` against sin(ωt): y ≈ a·sin(ωt + φ) + c.
pub fn fit_sine(t: &[f64], y: &[f64], w: f64) -> (f64, f64) {
    // Normal equations for [sin, cos, 1].
    let mut m = [[0.0f64; 3]; 3];
    let mut b = [0.0f64; 3];
    for (&ti, &yi) in t.iter().zip(y) {
        let f = [(w * ti).sin(), (w * ti).cos(), 1.0];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += f[i] * f[j];
            }
            b[i] += f[i] * yi;
        }
    }
    let a = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    let x = a
        .lu()
        .solve(&nalgebra::Vector3::new(b[0], b[1], b[2]))
        .expect("regular normal equations");
    (x[0].hypot(x[1]), x[1].atan2(x[0]))
}

/// The replay options of the diagnosis tests: the MF's limits, α* and turn
/// slip off (the rig's truth models run without them).
pub fn diagnose_opts() -> tyrekit::diagnose::replay::ReplayOptions {
    tyrekit::diagnose::replay::ReplayOptions {
        use_mode: tyrekit::mf::UseMode {
            limits: false,
            alpha_star: false,
            turn_slip: false,
        },
        ..Default::default()
    }
}

/// A rig run as a recording, with white Gaussian sensor noise of `sd_f` (N)
/// on Fx, Fy and `sd_mz` (N·m) on Mz drawn from `seed` (Box–Muller).
pub fn noisy_recording(
    run: tyrekit::rig::RigRun,
    source: &str,
    sd_f: f64,
    sd_mz: f64,
    seed: u64,
) -> tyrekit::data::Recording {
    noisy_samples(source, run.truth, run.plan, sd_f, sd_mz, seed)
}

/// Noise-free ISO-W samples and segments (e.g. several rig runs joined) as
/// a recording, with the rig's default sensor noise levels (12 N on Fx and
/// Fy, 0.4 N·m on Mz) from a fixed seed.
pub fn noisy_rig_recording(
    source: &str,
    samples: Vec<tyrekit::data::Sample>,
    segments: Vec<tyrekit::data::Segment>,
    seed: u64,
) -> tyrekit::data::Recording {
    noisy_samples(source, samples, segments, 12.0, 0.4, seed)
}

fn noisy_samples(
    source: &str,
    mut samples: Vec<tyrekit::data::Sample>,
    segments: Vec<tyrekit::data::Segment>,
    sd_f: f64,
    sd_mz: f64,
    seed: u64,
) -> tyrekit::data::Recording {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut g = || {
        let u1: f64 = rng.gen::<f64>().max(1e-300);
        let u2: f64 = rng.gen();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    for s in &mut samples {
        s.fx += sd_f * g();
        s.fy += sd_f * g();
        s.mz += sd_mz * g();
    }
    let (sweep_dir, t_in_segment) = tyrekit::data::structure::sweep_and_time(&samples, &segments);
    tyrekit::data::Recording {
        source: source.into(),
        samples,
        channels: tyrekit::data::SAMPLE_CHANNELS
            .iter()
            .map(|c| c.to_string())
            .collect(),
        extra: vec![],
        segments,
        sweep_dir,
        t_in_segment,
    }
}
