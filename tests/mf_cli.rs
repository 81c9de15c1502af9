//! `tyrekit eval` end to end: the binary fed a reference CSV (its `in_*`
//! columns) writes MFeval's 30 columns that match the reference.

use crate::common;
use common::{num, scratch, shared};
use std::process::Command;

#[test]
fn eval_reproduces_a_reference_csv() {
    let sh = shared();
    let reference = sh.join("data/reference/mfeval/MagicFormula61_Parameters__mode211.csv");
    let tir = sh.join("data/tir/MagicFormula61_Parameters.tir");
    if !reference.exists() || !tir.exists() {
        println!("SKIPPED: shared reference data absent");
        return;
    }
    let d = scratch("eval-test");
    let out = d.path().join("eval-test.csv");
    let st = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(["eval", "--tir"])
        .arg(&tir)
        .arg("--input")
        .arg(&reference)
        .arg("--output")
        .arg(&out)
        .args(["--use-mode", "211"])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let ours = std::fs::read_to_string(&out).unwrap();
    let theirs = std::fs::read_to_string(&reference).unwrap();
    let mut ol = ours.lines();
    let header: Vec<&str> = ol.next().unwrap().split(',').collect();
    assert_eq!(header, tyrekit::mf::OUTPUT_COLUMNS.to_vec());
    let mut tl = theirs.lines();
    let th: Vec<&str> = tl.next().unwrap().split(',').collect();
    let first = th.iter().position(|h| *h == "Fx").unwrap();
    let mut n = 0;
    for (o, t) in ol.zip(tl) {
        let o: Vec<f64> = o.split(',').map(num).collect();
        let t: Vec<&str> = t.split(',').collect();
        for (k, name) in header.iter().enumerate() {
            // instKya is a difference along the whole batch (here: all rows of
            // the file in one call), not along each sweep as in the reference.
            if *name == "instKya" {
                continue;
            }
            let r = num(t[first + k]);
            let ok = if r.is_finite() {
                (o[k] - r).abs() <= 1e-6 * r.abs().max(1.0)
            } else {
                o[k].to_bits() == r.to_bits() || (r.is_nan() && o[k].is_nan())
            };
            assert!(ok, "row {n} {name}: {} vs {r}", o[k]);
        }
        n += 1;
    }
    assert_eq!(
        n,
        theirs.lines().count() - 1,
        "one output row per input row"
    );
}

#[test]
fn eval_reports_bad_input_with_file_line_and_column() {
    let d = scratch("eval-bad");
    let dir = d.path();
    let input = dir.join("in.csv");
    std::fs::write(
        &input,
        "Fz,kappa,alpha,gamma,phit,Vx,P,omega\n4000,0,0.1,0,0,10,,\n4000,0,abc,0,0,10,,\n",
    )
    .unwrap();
    let st = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(["eval", "--input"])
        .arg(&input)
        .arg("--output")
        .arg(dir.join("out.csv"))
        .output()
        .unwrap();
    let msg = String::from_utf8_lossy(&st.stderr).to_string();
    assert!(!st.status.success());
    assert!(
        msg.contains("in.csv") && msg.contains("line 3") && msg.contains("alpha"),
        "message: {msg}"
    );
}
