//! mf_reference — the library's own answers for the FMU tests (tests/python):
//!
//! * `mf_reference eval USE_MODE [TIR]` reads CSV rows `Fz,kappa,alpha,gamma,phit,Vx,P,omega`
//!   (MFeval's input columns; header line required) on stdin and writes
//!   `Fx,Fy,Mx,My,Mz` of `Tyre::evaluate` on stdout, shortest round-trip decimals.
//!   Without TIR the built-in tyre (what `tyrekit package` ships) is used.
//! * `mf_reference check-tir FILE` exits 0 when the library's `.tir` reader accepts
//!   FILE, else prints the reader's message and exits 1.
//!
//! Must never: compute anything itself (it only calls the library).

use std::io::{BufRead, Write};
use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::tir::TyreParams;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let code = match args.get(1).map(String::as_str) {
        Some("eval") => eval(&args[2..]),
        Some("check-tir") => check(&args[2..]),
        _ => Err("usage: mf_reference eval USE_MODE [TIR] | check-tir FILE".into()),
    };
    if let Err(e) = code {
        eprintln!("mf_reference: {e}");
        std::process::exit(1);
    }
}

fn check(args: &[String]) -> Result<(), String> {
    let f = args.first().ok_or("check-tir needs a FILE")?;
    // The reader and the one validation, as the FMU and the CLI load a tyre.
    Tyre::from_file(std::path::Path::new(f))
        .map(|_| ())
        .map_err(|e| e.to_string())
}

fn eval(args: &[String]) -> Result<(), String> {
    let code: u32 = args
        .first()
        .and_then(|s| s.parse().ok())
        .ok_or("eval needs USE_MODE")?;
    let mode = UseMode::from_code(code).ok_or("bad USE_MODE")?;
    let tyre = match args.get(1) {
        Some(p) => Tyre::from_file(std::path::Path::new(p)).map_err(|e| e.to_string())?,
        None => Tyre::new(TyreParams::builtin()).map_err(|e| e.to_string())?,
    };
    let stdin = std::io::stdin();
    let mut out = std::io::BufWriter::new(std::io::stdout());
    writeln!(out, "Fx,Fy,Mx,My,Mz").map_err(|e| e.to_string())?;
    for (i, line) in stdin.lock().lines().enumerate() {
        let line = line.map_err(|e| e.to_string())?;
        if i == 0 || line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("line {}: {e}", i + 1))?;
        if v.len() != 8 {
            return Err(format!("line {}: expected 8 columns", i + 1));
        }
        let inp = MfInput {
            fz: v[0],
            kappa: v[1],
            alpha: v[2],
            gamma: v[3],
            phit: v[4],
            vx: v[5],
            p: v[6],
            omega: v[7],
        };
        let o = tyre.evaluate(&inp, mode);
        writeln!(
            out,
            "{:?},{:?},{:?},{:?},{:?}",
            o.fx, o.fy, o.mx, o.my, o.mz
        )
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}
