//! Bounded readers (issue 16): hostile inputs of every reader, each read by
//! the real command in a child process whose peak memory is taken from
//! wait4's rusage. Every one must end with a clear error or a normal result,
//! within MEMORY_BOUND, and nothing may crash (stack overflow = SIGABRT).
//! The figures are printed (`--nocapture`) and stated in the README.

use crate::common::scratch;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

const MEMORY_BOUND: u64 = 1 << 30;
const MB50: usize = 50 << 20;

/// Run `tyrekit ARGS`, its stderr kept in the test's folder `d`; (exit code,
/// peak RSS bytes, stderr).
fn run(d: &Path, args: &[&str]) -> (i32, u64, String) {
    let err = d.join("stderr.txt");
    let child = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .unwrap();
    let mut status = 0i32;
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = child.id() as libc::pid_t;
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut ru) };
    assert_eq!(r, pid, "wait4");
    std::mem::forget(child);
    let stderr = std::fs::read_to_string(&err).unwrap_or_default();
    assert!(
        !libc::WIFSIGNALED(status),
        "tyrekit {args:?} was killed by signal {} (crash); stderr: {stderr}",
        libc::WTERMSIG(status)
    );
    (
        libc::WEXITSTATUS(status),
        ru.ru_maxrss as u64 * 1024,
        stderr,
    )
}

fn check(d: &Path, what: &str, args: &[&str], must_fail: bool) -> u64 {
    let (code, rss, err) = run(d, args);
    eprintln!(
        "{what}: exit {code}, peak RSS {} MiB; {}",
        rss >> 20,
        err.lines().last().unwrap_or("")
    );
    assert!(
        rss <= MEMORY_BOUND,
        "{what}: peak memory {} MiB above the bound",
        rss >> 20
    );
    if must_fail {
        assert!(
            code != 0 && err.contains("error"),
            "{what}: expected a clear error, got exit {code}: {err}"
        );
    }
    rss
}

fn write(d: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = d.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

// MAT level 5 building blocks.
fn tag(out: &mut Vec<u8>, ty: u32, n: usize) {
    out.extend_from_slice(&ty.to_le_bytes());
    out.extend_from_slice(&(n as u32).to_le_bytes());
}
fn header() -> Vec<u8> {
    let mut h = vec![b' '; 128];
    h[..20].copy_from_slice(b"MATLAB 5.0 MAT-file ");
    h[124..126].copy_from_slice(&0x0100u16.to_le_bytes());
    h[126..128].copy_from_slice(b"IM");
    h
}
/// miMATRIX of class `class` (1 = cell, 6 = double) with 1x1 dims, no name,
/// body `inner` (already-encoded elements).
fn matrix(class: u8, inner: &[u8]) -> Vec<u8> {
    let mut b = Vec::new();
    tag(&mut b, 6, 8); // flags miUINT32
    b.extend_from_slice(&[class, 0, 0, 0, 0, 0, 0, 0]);
    tag(&mut b, 5, 8); // dims miINT32
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(&1i32.to_le_bytes());
    tag(&mut b, 1, 0); // name miINT8, empty
    b.extend_from_slice(inner);
    let mut out = Vec::new();
    tag(&mut out, 14, b.len());
    out.extend(b);
    out
}

#[test]
fn mat_nested_10000_deep_is_an_error_not_a_stack_overflow() {
    let tmp = scratch("bounds");
    let d = tmp.path();
    let mut el = {
        let mut d = Vec::new();
        tag(&mut d, 9, 8);
        d.extend_from_slice(&1.0f64.to_le_bytes());
        matrix(6, &d)
    };
    for _ in 0..10_000 {
        el = matrix(1, &el);
    }
    // Name the top variable so it looks like a TTC export, compress it.
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    z.write_all(&el).unwrap();
    let zb = z.finish().unwrap();
    let mut f = header();
    tag(&mut f, 15, zb.len());
    f.extend(zb);
    eprintln!("nested .mat: {} bytes", f.len());
    let p = write(d, "nested.mat", &f);
    check(
        d,
        "mat nested 10000 deep",
        &["data", "summary", s(&p)],
        true,
    );
    let (_, _, err) = run(d, &["data", "summary", s(&p)]);
    assert!(err.contains("nested"), "{err}");
}

#[test]
fn mat_decompression_bomb_is_refused_early() {
    let tmp = scratch("bounds");
    let d = tmp.path();
    // A double array declared as 1.2e8 values (960 MB), zeros, compressed: ~1 MB.
    let n: usize = 120_000_000;
    let mut inner = Vec::new();
    tag(&mut inner, 9, n * 8);
    let mut b = Vec::new();
    tag(&mut b, 6, 8);
    b.extend_from_slice(&[6, 0, 0, 0, 0, 0, 0, 0]);
    tag(&mut b, 5, 8);
    b.extend_from_slice(&(n as i32).to_le_bytes());
    b.extend_from_slice(&1i32.to_le_bytes());
    tag(&mut b, 1, 2);
    b.extend_from_slice(b"FY\0\0\0\0\0\0");
    let total = b.len() + inner.len() + n * 8;
    let mut el = Vec::new();
    tag(&mut el, 14, total);
    el.extend(b);
    el.extend(inner);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&el).unwrap();
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..((n * 8) >> 20) {
        z.write_all(&zeros).unwrap();
    }
    let zb = z.finish().unwrap();
    let mut f = header();
    tag(&mut f, 15, zb.len());
    f.extend(zb);
    eprintln!(
        "bomb .mat: {} bytes, inflates to {} MB",
        f.len(),
        (n * 8) >> 20
    );
    let p = write(d, "bomb.mat", &f);
    let rss = check(d, "mat bomb", &["data", "summary", s(&p)], true);
    // Refused at 64 x the file size: far below the 960 MB it declares.
    assert!(rss < 400 << 20, "bomb took {} MiB", rss >> 20);
}

#[test]
fn tir_of_50mb_duplicated_keys() {
    let tmp = scratch("bounds");
    let d = tmp.path();
    let mut t = b"[MODEL]\nFITTYP = 61\n".to_vec();
    while t.len() < MB50 {
        t.extend_from_slice(b"PDX1 = 1\nXKEY = 2\n");
    }
    let p = write(d, "dup.tir", &t);
    let input = write(
        d,
        "in.csv",
        b"Fz,kappa,alpha,gamma,phit,Vx,P,omega\n4000,0,0,0,0,10,,\n",
    );
    let out = d.join("out.csv");
    check(
        d,
        "tir 50 MB duplicated keys",
        &[
            "eval",
            "--tir",
            s(&p),
            "--input",
            s(&input),
            "--output",
            s(&out),
        ],
        true,
    );
    // At the reader's size limit: read in linear time with capped warnings.
    let t2 = &t[..tyrekit::tir::MAX_TIR_BYTES - 100];
    let t0 = std::time::Instant::now();
    let r = tyrekit::tir::TyreParams::from_bytes(t2, "dup2");
    let secs = t0.elapsed().as_secs_f64();
    eprintln!(
        "tir {} MiB of duplicates: read in {secs:.2} s",
        t2.len() >> 20
    );
    let w = r.expect("duplicates read").warnings;
    assert!(
        w.len() <= tyrekit::tir::read::MAX_WARNINGS + 5,
        "{} warnings kept",
        w.len()
    );
    assert!(secs < 10.0, "{secs} s");
}

fn numbers_file(d: &Path, name: &str, head: &str, line: &str) -> PathBuf {
    let mut t = head.as_bytes().to_vec();
    while t.len() < MB50 {
        t.extend_from_slice(line.as_bytes());
    }
    write(d, name, &t)
}

#[test]
fn recordings_of_50mb() {
    let tmp = scratch("bounds");
    let d = tmp.path();
    let csv = numbers_file(
        d,
        "big.csv",
        "time,Vx,omega,Fz,kappa,alpha,gamma,phit,P,Fx,Fy,Mx,My,Mz\n",
        "0,1,2,3,0,0,0,0,1,2,3,4,5,6\n",
    );
    check(d, "csv 50 MB", &["data", "summary", s(&csv)], false);
    let garbage = numbers_file(
        d,
        "garbage.csv",
        "a,b\n",
        "1,2,3,4,5,6,7,8,9,0,1,2,3,4,5,6,7\n",
    );
    check(
        d,
        "csv 50 MB ragged rows",
        &["data", "summary", s(&garbage)],
        true,
    );
    let dat = numbers_file(
        d,
        "big.dat",
        "ET V N SA IA RL RE P FX FY FZ MX MZ SR\ns kph rpm deg deg cm cm kPa N N N N-m N-m none\n",
        "0 40 300 1 0 30 31 80 10 20 -1000 1 2 0\n",
    );
    check(d, "dat 50 MB", &["data", "summary", s(&dat)], false);
    let tdx = numbers_file(
        d,
        "big.tdx",
        "**HEADER\nRELEASE 1.3\n**MEASURCHANNELS\nRUNTIME  time  s  1 0\nLONGVEL  Vx  m/s 1 0\nFZW  Fz  N 1 0\n**MEASURDATA\n",
        "0 10 4000\n",
    );
    // 5 million rows of 10 bytes: refused by the row limit.
    check(
        d,
        "tdx 50 MB (5.2 M short rows)",
        &["data", "summary", s(&tdx)],
        true,
    );
    // A TTC .mat of 14 double channels, 450 000 rows (50 MB, uncompressed).
    let n = 450_000;
    let names = [
        "ET", "V", "N", "SA", "IA", "RL", "RE", "P", "FX", "FY", "FZ", "MX", "MZ", "SR",
    ];
    let units = [
        "s", "kph", "rpm", "deg", "deg", "cm", "cm", "kPa", "N", "N", "N", "N-m", "N-m", "none",
    ];
    let t = tyrekit::data::RawTable {
        columns: names
            .iter()
            .enumerate()
            .map(|(k, c)| tyrekit::data::RawColumn {
                name: c.to_string(),
                unit: Some(units[k].to_string()),
                data: (0..n)
                    .map(|i| {
                        if *c == "FZ" {
                            -1000.0
                        } else {
                            (i % 100) as f64 + k as f64
                        }
                    })
                    .collect(),
            })
            .collect(),
        ..Default::default()
    };
    let mat = write(d, "big.mat", &tyrekit::data::ttc::write_mat(&t, false));
    check(d, "mat 50 MB", &["data", "summary", s(&mat)], false);
}
