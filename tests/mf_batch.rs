//! `Tyre::evaluate_batch` reproduces MFeval's instKya: the finite difference
//! ΔFy/Δα along one batch call, the last row repeating the previous value.
//! The MFeval example files hold every pure-slip row, so their pure lateral
//! sweeps (kind 1) are complete in the reference and can be replayed as the
//! same batches MFeval was called with.

use crate::common;
use common::{num, reference_input, shared};
use std::collections::BTreeMap;
use tyrekit::mf::{MfInput, MfOutput, Tyre, UseMode};

#[test]
fn batch_inst_kya_matches_mfeval_on_complete_sweeps() {
    let dir = shared().join("data/reference/mfeval");
    let tir = shared().join("data/tir/MagicFormula61_Parameters.tir");
    if !dir.exists() || !tir.exists() {
        println!("SKIPPED: shared reference data absent");
        return;
    }
    let tyre = Tyre::from_file(&tir).unwrap();
    let text = std::fs::read_to_string(dir.join("MagicFormula61_Parameters__mode111.csv")).unwrap();
    let mut lines = text.lines();
    let h: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| h.iter().position(|x| *x == n).unwrap();
    let mut sweeps: BTreeMap<i64, Vec<Vec<f64>>> = BTreeMap::new();
    for l in lines {
        let r: Vec<f64> = l.split(',').map(num).collect();
        if r[col("kind")] == 1.0 {
            sweeps.entry(r[col("sweep")] as i64).or_default().push(r);
        }
    }
    assert!(sweeps.len() >= 10, "expected the complete kind-1 sweeps");
    let mut compared = 0;
    for rows in sweeps.values() {
        // Complete sweep: consecutive grid rows.
        let first = rows[0][col("row")] as i64;
        if rows
            .iter()
            .enumerate()
            .any(|(i, r)| r[col("row")] as i64 != first + i as i64)
        {
            continue;
        }
        let inp: Vec<MfInput> = rows.iter().map(|r| reference_input(r, col)).collect();
        let mut out = vec![MfOutput::default(); inp.len()];
        tyre.evaluate_batch(&inp, UseMode::default(), &mut out);
        for (o, r) in out.iter().zip(rows) {
            let reference = r[col("instKya")];
            assert!(
                (o.inst_kya - reference).abs() <= 1e-6 * reference.abs().max(1.0),
                "row {}: instKya {} vs {reference}",
                r[col("row")],
                o.inst_kya
            );
            compared += 1;
        }
    }
    assert!(compared > 500, "only {compared} rows compared");
}
