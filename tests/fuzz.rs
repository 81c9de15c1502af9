//! The repository's seeded mutation fuzzer (issue 16), on the stable
//! toolchain: the `.tir` reader + validation + Magic Formula, the CSV, TTC
//! `.dat`/`.mat` and TYDEX readers + recording interpretation, and FMU call
//! sequences and inputs through the C ABI.
//!
//! CI: 500 mutants per reader with a fixed seed (release mode, a few minutes
//! in all). On demand: `TYREKIT_FUZZ_LONG=1` runs 3000 per reader
//! (`TYREKIT_FUZZ_N=…` any count, `TYREKIT_FUZZ_SEED=…` another seed).
//! A mutant fails the run on: a panic, a hang (one mutant over
//! [`HANG_SECONDS`]), a silent non-finite output, an absurd output without a
//! validation warning (|F| > 10·Fz·max(1, μ) or |M| > 10·Fz·R0), or the
//! process's peak memory above [`MEMORY_BOUND`]. Failing inputs are saved to
//! the temp folder and named in the message.
//!
//! Seeds are our own fixtures (the built-in tyre, a recording the test
//! synthesises from the Magic Formula and writes with the crate's writers)
//! plus the shared `.tir` files when present.

use crate::common::scratch;
use crate::tir_common;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;
use tyrekit::data::{self, Format, LoadOptions, RawColumn, RawTable, SAMPLE_CHANNELS};
use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::tir::TyreParams;

/// One mutant taking longer than this is a hang.
const HANG_SECONDS: f64 = 20.0;
/// Peak resident memory of the fuzzing process (bytes).
const MEMORY_BOUND: u64 = 1 << 30;

fn count() -> usize {
    if let Some(n) = std::env::var("TYREKIT_FUZZ_N")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        return n;
    }
    if std::env::var("TYREKIT_FUZZ_LONG").is_ok_and(|v| v == "1") {
        3000
    } else {
        500
    }
}

fn rng(salt: u64) -> ChaCha8Rng {
    let seed = std::env::var("TYREKIT_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x16_2026u64);
    ChaCha8Rng::seed_from_u64(seed ^ salt)
}

fn peak_rss() -> u64 {
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    u.ru_maxrss as u64 * 1024
}

fn save(kind: &str, i: usize, b: &[u8]) -> String {
    let p = std::env::temp_dir().join(format!("tyrekit_fuzz_{kind}_{i}"));
    let _ = std::fs::write(&p, b);
    p.display().to_string()
}

const TOKENS: &[&[u8]] = &[
    b"0",
    b"-1",
    b"1e308",
    b"-1e308",
    b"NaN",
    b"inf",
    b"1e-320",
    b"=",
    b"\n",
    b",",
    b";",
    b"\t",
    b" ",
    b"'",
    b"[",
    b"]",
    b"{",
    b"}",
    b"$",
    b"!",
    b"\xff",
    b"\0",
    b"99999999999",
    b"\nFNOMIN = 0\n",
    b"\nLONGVL = 0\n",
    b"\nNOMPRES = -1\n",
    b"\nQSX1 = 1e6\n",
    b"\nPDX1 = 1e3\n",
    b"\nLFZO = 0\n",
    b"\n[UNITS]\nLENGTH = 'mm'\n",
    b"\nTIME = 'hour'\n",
    b"\nPRESMAX = 0\n",
    b"\nFZMAX = -1\n",
    b"\nVXLOW = 0\n",
    b"\nUNLOADED_RADIUS = 1e-9\n",
];

/// Byte-level mutations (flip, insert token, delete, duplicate, truncate,
/// junk, and a numeric-field rewrite that keeps the structure).
fn mutate(r: &mut ChaCha8Rng, b: &mut Vec<u8>) {
    // Half the mutants carry one mutation (most get past the first checks
    // and exercise the interpretation), the rest 2–6.
    let k = if r.gen_bool(0.5) {
        1
    } else {
        r.gen_range(2..=6)
    };
    for _ in 0..k {
        let len = b.len();
        match r.gen_range(0..8) {
            0 if len > 0 => {
                let i = r.gen_range(0..len);
                b[i] = r.gen();
            }
            1 => {
                let t = TOKENS[r.gen_range(0..TOKENS.len())];
                let i = r.gen_range(0..=len);
                b.splice(i..i, t.iter().copied());
            }
            2 if len > 0 => {
                let i = r.gen_range(0..len);
                let j = (i + r.gen_range(0..300)).min(len);
                b.drain(i..j);
            }
            3 if len > 0 => {
                let i = r.gen_range(0..len);
                let j = (i + r.gen_range(0..600)).min(len);
                let piece = b[i..j].to_vec();
                let k = r.gen_range(0..=len);
                b.splice(k..k, piece);
            }
            4 if len > 16 && r.gen_bool(0.3) => {
                let i = r.gen_range(len / 2..len);
                b.truncate(i);
            }
            5 if len > 8 => {
                // Rewrite a digit run as a wild number of the same kind.
                let i = r.gen_range(0..len);
                if let Some(s) = (i..len).find(|&k| b[k].is_ascii_digit()) {
                    let e = (s..len).find(|&k| !b[k].is_ascii_digit()).unwrap_or(len);
                    let w: &[u8] =
                        [b"0".as_slice(), b"1e300", b"7", b"-3", b"123456789"][r.gen_range(0..5)];
                    b.splice(s..e, w.iter().copied());
                }
            }
            6 if len > 4 => {
                // Overwrite a 4-byte word (binary lengths and tags of .mat).
                let i = r.gen_range(0..len - 3);
                let w: u32 =
                    [0, 1, 0xffff_ffff, 0x7fff_ffff, 14, 15, 1 << 20, r.gen()][r.gen_range(0..8)];
                b[i..i + 4].copy_from_slice(&w.to_le_bytes());
            }
            _ => {
                let i = r.gen_range(0..=len);
                let junk: Vec<u8> = (0..r.gen_range(0..32)).map(|_| r.gen()).collect();
                b.splice(i..i, junk);
            }
        }
    }
}

/// Run `f` on `n` mutants of `seeds`; panics and hangs fail with the input saved.
fn fuzz(
    kind: &str,
    salt: u64,
    seeds: &[Vec<u8>],
    mut f: impl FnMut(&[u8]) -> Result<(), String>,
) -> (usize, usize) {
    let mut r = rng(salt);
    let n = count();
    let mut accepted = 0;
    let mut slowest = 0.0f64;
    for i in 0..n {
        let mut b = seeds[r.gen_range(0..seeds.len())].clone();
        mutate(&mut r, &mut b);
        let t0 = Instant::now();
        let out = catch_unwind(AssertUnwindSafe(|| f(&b)));
        let dt = t0.elapsed().as_secs_f64();
        slowest = slowest.max(dt);
        match out {
            Err(_) => panic!(
                "{kind} mutant {i}: panic; input saved to {}",
                save(kind, i, &b)
            ),
            Ok(Err(why)) => panic!(
                "{kind} mutant {i}: {why}; input saved to {}",
                save(kind, i, &b)
            ),
            Ok(Ok(())) => {}
        }
        if dt > HANG_SECONDS {
            panic!(
                "{kind} mutant {i}: took {dt:.1} s (hang); input saved to {}",
                save(kind, i, &b)
            );
        }
        accepted += 1;
    }
    let rss = peak_rss();
    eprintln!(
        "fuzz {kind}: {n} mutants, 0 failures, slowest {:.3} s, peak RSS {} MiB",
        slowest,
        rss >> 20
    );
    assert!(
        rss <= MEMORY_BOUND,
        "{kind}: peak memory {} MiB above the bound",
        rss >> 20
    );
    (n, accepted)
}

// ------------------------------------------------------------------ .tir

/// The oracle for a tyre that loaded: random points inside the file's own
/// range (not the validator's grid) must give finite forces within
/// 10·Fz·max(1, μ) and moments within 10·Fz·R0 — unless the tyre carries a
/// validation warning, which every command prints.
fn check_tyre(t: &Tyre, r: &mut ChaCha8Rng) -> Result<(), String> {
    let warned = t.warnings().iter().any(|w| w.starts_with("validation"));
    let p = &t.params().p;
    let (r0, fnom) = (p.unloaded_radius, p.fnomin);
    let within = |lo: f64, hi: f64, fb: f64, r: &mut ChaCha8Rng| {
        if lo.is_finite() && hi.is_finite() && lo < hi && hi - lo < 20.0 {
            r.gen_range(lo..=hi)
        } else {
            r.gen_range(-fb..=fb)
        }
    };
    for _ in 0..20 {
        let x = MfInput {
            fz: fnom * r.gen_range(0.25..2.0),
            kappa: within(p.kpumin, p.kpumax, 1.0, r),
            alpha: within(p.alpmin, p.alpmax, 0.5, r),
            gamma: within(p.cammin, p.cammax, 0.0, r),
            vx: r.gen_range(1.0..60.0),
            p: p.inflpres,
            ..Default::default()
        };
        let o = t.evaluate(&x, UseMode::default());
        let mu = 1f64.max(o.mux.abs()).max(o.muy.abs());
        let f = [o.fx, o.fy, o.mx, o.my, o.mz];
        let bad = if f.iter().any(|v| !v.is_finite()) {
            Some("non-finite output")
        } else if o.fx.abs().max(o.fy.abs()) > 10.0 * x.fz * mu {
            Some("absurd force")
        } else if o.mx.abs().max(o.my.abs()).max(o.mz.abs()) > 10.0 * x.fz * r0 {
            Some("absurd moment")
        } else {
            None
        };
        if let (Some(what), false) = (bad, warned) {
            return Err(format!(
                "{what} without a validation warning at {x:?}: {f:?}"
            ));
        }
    }
    Ok(())
}

#[test]
fn fuzz_tir() {
    let mut seeds: Vec<Vec<u8>> = tir_common::tir_files()
        .iter()
        .filter_map(|p| std::fs::read(p).ok())
        .collect();
    seeds.push(tyrekit::tir::BUILTIN_TIR.as_bytes().to_vec());
    let mut r = rng(99);
    let (mut loaded, mut refused) = (0, 0);
    fuzz("tir", 1, &seeds, |b| {
        match TyreParams::from_bytes(b, "fuzz.tir").and_then(Tyre::checked) {
            Ok(t) => {
                loaded += 1;
                check_tyre(&t, &mut r)
            }
            Err(e) => {
                refused += 1;
                // A refusal must say why (file/line/key or the validation's reason).
                if e.to_string().len() < 10 {
                    return Err(format!("terse refusal: {e}"));
                }
                Ok(())
            }
        }
    });
    eprintln!("fuzz tir: {loaded} loaded and checked, {refused} refused with a reason");
}

// ------------------------------------------------------------------ recordings

/// A small synthetic TTC-style table (cornering sweep at two loads) from the
/// built-in tyre's Magic Formula.
fn seed_table() -> RawTable {
    let t = Tyre::builtin();
    let mut cols: Vec<(&str, &str, Vec<f64>)> = vec![
        ("ET", "s", vec![]),
        ("V", "kph", vec![]),
        ("N", "rpm", vec![]),
        ("SA", "deg", vec![]),
        ("IA", "deg", vec![]),
        ("P", "kPa", vec![]),
        ("FX", "N", vec![]),
        ("FY", "N", vec![]),
        ("FZ", "N", vec![]),
        ("MX", "N-m", vec![]),
        ("MZ", "N-m", vec![]),
        ("RL", "cm", vec![]),
        ("SR", "none", vec![]),
    ];
    let mut i = 0;
    for fz in [2000.0, 4000.0] {
        for k in 0..150 {
            let a = (k as f64 / 149.0 * 2.0 - 1.0) * 0.2;
            let o = t.evaluate(
                &MfInput {
                    fz,
                    alpha: a,
                    vx: 11.1,
                    ..Default::default()
                },
                UseMode::default(),
            );
            // SAE/TTC signs: FY, FZ, MZ, SA flip.
            let v = [
                i as f64 * 0.01,
                40.0,
                11.1 / o.re * 60.0 / (2.0 * std::f64::consts::PI),
                -a.to_degrees(),
                0.0,
                220.0,
                o.fx,
                -o.fy,
                -fz,
                o.mx,
                -o.mz,
                o.rl * 100.0,
                0.0,
            ];
            for (c, x) in cols.iter_mut().zip(v) {
                c.2.push(x);
            }
            i += 1;
        }
    }
    RawTable {
        columns: cols
            .into_iter()
            .map(|(n, u, d)| RawColumn {
                name: n.into(),
                unit: Some(u.into()),
                data: d,
            })
            .collect(),
        ..Default::default()
    }
}

/// Oracle for a recording that loaded: every value of a channel it claims
/// is finite (no silent NaN), sample counts agree.
fn check_recording(l: &data::Loaded) -> Result<(), String> {
    let r = &l.recording;
    for (i, s) in r.samples.iter().enumerate() {
        for (c, v) in SAMPLE_CHANNELS.iter().zip(s.values()) {
            if r.has(c) && !v.is_finite() {
                return Err(format!("sample {i}: channel {c} = {v} (claimed present)"));
            }
        }
    }
    if r.sweep_dir.len() != r.samples.len() {
        return Err("sweep_dir length differs from the samples".into());
    }
    Ok(())
}

fn fuzz_format(kind: &str, salt: u64, format: Format, seeds: Vec<Vec<u8>>) {
    let read = |b: &[u8]| -> tyrekit::Result<RawTable> {
        match format {
            Format::TtcMat => data::ttc::read_mat(b, "fuzz"),
            Format::TtcDat => data::ttc::read_dat(b, "fuzz"),
            Format::Tydex => data::tdx::read(b, "fuzz"),
            Format::Csv => data::csvio::read(b, "fuzz"),
        }
    };
    let (mut ok, mut refused) = (0, 0);
    fuzz(kind, salt, &seeds, |b| {
        match read(b).and_then(|raw| data::from_raw(raw, format, "fuzz", &LoadOptions::default())) {
            Ok(l) => {
                ok += 1;
                check_recording(&l)
            }
            Err(e) => {
                refused += 1;
                if std::env::var_os("TYREKIT_FUZZ_VERBOSE").is_some() {
                    eprintln!("refused: {e}");
                }
                Ok(())
            }
        }
    });
    eprintln!("fuzz {kind}: {ok} loaded and checked, {refused} refused");
}

fn loaded_seed() -> data::Loaded {
    data::from_raw(
        seed_table(),
        Format::TtcDat,
        "seed",
        &LoadOptions::default(),
    )
    .expect("seed loads")
}

#[test]
fn fuzz_ttc_mat() {
    let t = seed_table();
    fuzz_format(
        "mat",
        2,
        Format::TtcMat,
        vec![
            data::ttc::write_mat(&t, true),
            data::ttc::write_mat(&t, false),
        ],
    );
}

#[test]
fn fuzz_ttc_dat() {
    fuzz_format(
        "dat",
        3,
        Format::TtcDat,
        vec![data::ttc::write_dat(&seed_table()).into_bytes()],
    );
}

#[test]
fn fuzz_tydex() {
    fuzz_format(
        "tdx",
        4,
        Format::Tydex,
        vec![data::tdx::write(&loaded_seed().recording).into_bytes()],
    );
}

#[test]
fn fuzz_csv() {
    fuzz_format(
        "csv",
        5,
        Format::Csv,
        vec![data::csvio::write(&loaded_seed().recording).into_bytes()],
    );
}

// ------------------------------------------------------------------ FMU call sequences

/// Random FMI call sequences through the exported C functions: inputs from
/// a pool of ordinary, extreme-but-legal and illegal values, steps of random
/// size, FMU states got/set/serialized/deserialized/freed, resets, parameter
/// changes. Oracle: no panic (fmi2Fatal), and after every fmi2OK step the
/// outputs are finite with |F| ≤ 10·Fz·max(1, μ), |M| ≤ 10·Fz·R0.
#[test]
fn fuzz_fmu_calls() {
    use std::ffi::CString;
    use tyrekit::fmi::exports::*;
    use tyrekit::fmi::types::{Fmi2Status, FMI2_CO_SIMULATION};
    use tyrekit::fmi::vars::vr;
    let d = scratch("fuzz-fmu");
    let dir = d.path();
    TyreParams::builtin().write(&dir.join("tyre.tir")).unwrap();
    let r0 = TyreParams::builtin().p.unloaded_radius;
    let name = CString::new("fuzz").unwrap();
    let guid = CString::new(tyrekit::fmi::GUID).unwrap();
    let res = CString::new(format!("file://{}", dir.display())).unwrap();
    let kinds = [c"steady", c"relaxation", c"lugre"];
    let modes = [c"velocities", c"slips"];
    let inputs = [
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
    let pool = [
        0.0,
        1.0,
        -1.0,
        0.3,
        -0.3,
        10.0,
        30.0,
        100.0,
        150.0,
        -150.0,
        4000.0,
        8000.0,
        20000.0,
        1.5,
        -1.5,
        5.0,
        2000.0,
        -2000.0,
        2e5,
        1e6,
        1e300,
        -1e300,
        f64::NAN,
        1e-300,
        3.0,
    ];
    let outs = [vr::FX, vr::FY, vr::MX, vr::MY, vr::MZ, vr::MUX, vr::MUY];
    let mut seq = 0usize;
    let n = count();
    let mut steps_ok = 0usize;
    let seeds = vec![vec![0u8]];
    // Each "mutant" is one random sequence of 60 calls on a fresh instance.
    fuzz("fmu", 6, &seeds, |_| unsafe {
        let mut r = rng(1000 + seq as u64);
        seq += 1;
        let c = fmi2Instantiate(
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            guid.as_ptr(),
            res.as_ptr(),
            std::ptr::null(),
            0,
            0,
        );
        if c.is_null() {
            return Err("instantiate failed".into());
        }
        let ki = r.gen_range(0..3);
        let k = [kinds[ki].as_ptr()];
        fmi2SetString(c, [vr::TRANSIENT].as_ptr(), 1, k.as_ptr());
        let mi = r.gen_range(0..2);
        let m = [modes[mi].as_ptr()];
        fmi2SetString(c, [vr::INPUT_MODE].as_ptr(), 1, m.as_ptr());
        let um = [[111, 211, 112, 121, 212][r.gen_range(0..5)]];
        fmi2SetInteger(c, [vr::USE_MODE].as_ptr(), 1, um.as_ptr());
        fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0);
        fmi2EnterInitializationMode(c);
        fmi2ExitInitializationMode(c);
        let mut t = 0.0;
        let mut states: Vec<*mut std::ffi::c_void> = Vec::new();
        let mut fz = 4000.0;
        let mut result = Ok(());
        let mut last = [0.0f64; 10];
        fmi2GetReal(c, inputs.as_ptr(), inputs.len(), last.as_mut_ptr());
        for _ in 0..60 {
            match r.gen_range(0..10) {
                0..=3 => {
                    let i = r.gen_range(0..inputs.len());
                    let x = pool[r.gen_range(0..pool.len())]
                        * if r.gen_bool(0.3) {
                            r.gen_range(0.5..1.5)
                        } else {
                            1.0
                        };
                    fmi2SetReal(c, [inputs[i]].as_ptr(), 1, [x].as_ptr());
                }
                4..=6 => {
                    let h = [1e-5, 1e-4, 1e-3, 1e-2][r.gen_range(0..4)];
                    let st = fmi2DoStep(c, t, h, 1);
                    if st == Fmi2Status::Fatal {
                        result = Err("fmi2Fatal (a panic) in fmi2DoStep".to_string());
                        break;
                    }
                    if st == Fmi2Status::Ok {
                        t += h;
                        steps_ok += 1;
                        let mut y = [0.0; 7];
                        fmi2GetReal(c, outs.as_ptr(), outs.len(), y.as_mut_ptr());
                        let [fx, fy, mx, my, mz, mux, muy] = y;
                        // The load in force now (a restored FMU state restores inputs too).
                        fmi2GetReal(c, [vr::FZ].as_ptr(), 1, &mut fz);
                        let f = fz.max(0.0);
                        let mu = 1f64.max(mux.abs()).max(muy.abs());
                        if y.iter().any(|v| !v.is_finite())
                            || fx.abs().max(fy.abs()) > 10.0 * f * mu + 1e-9
                            || mx.abs().max(my.abs()).max(mz.abs()) > 10.0 * f * r0 + 1e-9
                        {
                            fmi2GetReal(c, inputs.as_ptr(), inputs.len(), last.as_mut_ptr());
                            result = Err(format!(
                                "accepted step ({:?}, {:?}, use_mode {}) gave Fx Fy Mx My Mz mux muy = {y:?} \
                                 for inputs vx vy omega Fz gamma p phit mu kappa alpha = {last:?}",
                                kinds[ki], modes[mi], um[0]
                            ));
                            break;
                        }
                    }
                }
                7 => {
                    let mut s: *mut std::ffi::c_void = std::ptr::null_mut();
                    if fmi2GetFMUstate(c, &mut s as *mut _ as _) == Fmi2Status::Ok {
                        let mut size = 0usize;
                        fmi2SerializedFMUstateSize(c, s as _, &mut size);
                        let mut buf = vec![0u8; size];
                        fmi2SerializeFMUstate(c, s as _, buf.as_mut_ptr() as _, size);
                        if !buf.is_empty() && r.gen_bool(0.5) {
                            let i = r.gen_range(0..buf.len());
                            buf[i] ^= 1 << r.gen_range(0..8);
                        }
                        let mut d: *mut std::ffi::c_void = std::ptr::null_mut();
                        fmi2DeSerializeFMUstate(c, buf.as_ptr() as _, size, &mut d as *mut _ as _);
                        states.push(s);
                        if !d.is_null() {
                            states.push(d);
                        }
                    }
                }
                8 if !states.is_empty() => {
                    let i = r.gen_range(0..states.len());
                    if r.gen_bool(0.5) {
                        if fmi2SetFMUstate(c, states[i] as _) == Fmi2Status::Fatal {
                            result = Err("fmi2Fatal in fmi2SetFMUstate".into());
                            break;
                        }
                    } else {
                        let mut s = states.swap_remove(i);
                        fmi2FreeFMUstate(c, &mut s as *mut _ as _);
                    }
                }
                _ => {
                    if r.gen_bool(0.2) {
                        fmi2Reset(c);
                        fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0);
                        fmi2EnterInitializationMode(c);
                        fmi2ExitInitializationMode(c);
                        t = 0.0;
                    }
                }
            }
        }
        // Half the states are left to fmi2FreeInstance (it frees them).
        fmi2FreeInstance(c);
        result
    });
    eprintln!("fuzz fmu: {n} sequences, {steps_ok} accepted steps checked");
}
