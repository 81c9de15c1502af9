//! Provenance: the `.tir` that `tyrekit fit` writes names the tyrekit
//! version, the command, every input file with its SHA-256 (computed here
//! independently), the fitted stages and σ / NRMSE per channel exactly as
//! `fit.json` reports them; the header survives a read-back, and the fit's
//! geometry keys carry their `$` marks. Runs the binary on TyreData.csv
//! (skips with a message when ../shared is absent).

use crate::common::scratch;
use sha2::{Digest, Sha256};
use std::path::Path;
use std::process::Command;

const TYREDATA: &str = "../shared/data/measurements/TyreData.csv";

#[test]
fn fitted_file_names_its_origin() {
    if !Path::new(TYREDATA).exists() {
        eprintln!("SKIP: {TYREDATA} not found (the shared data are not at hand)");
        return;
    }
    let tmp = scratch("prov");
    let dir = tmp.path();
    let out = dir.join("fitted.tir");
    let rep = dir.join("report");
    let o = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(["fit", TYREDATA, "--only", "fy", "--out"])
        .arg(&out)
        .arg("--report")
        .arg(&rep)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('!')).collect();
    let has = |needle: &str| header.iter().any(|l| l.contains(needle));
    assert!(
        has(&format!("Written by tyrekit {}", env!("CARGO_PKG_VERSION"))),
        "{header:#?}"
    );
    assert!(
        has(&format!("command: tyrekit fit {TYREDATA} --only fy --out")),
        "{header:#?}"
    );
    let sha: String = Sha256::digest(std::fs::read(TYREDATA).unwrap())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert!(
        has(&format!("input: {TYREDATA}  sha256 {sha}")),
        "{header:#?}"
    );
    // Stages and figures as the fit report computed them.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("fit.json")).unwrap()).unwrap();
    let stages: Vec<&str> = json["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["stage"].as_str().unwrap())
        .collect();
    assert!(!stages.is_empty());
    assert!(
        has(&format!("fitted stages: {}", stages.join(", "))),
        "{header:#?}"
    );
    let fy = json["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["channel"] == "Fy" && m["condition"].is_null())
        .unwrap();
    let figure = format!(
        "Fy σ {:.2} % NRMSE {:.2} %",
        100.0 * fy["sigma"].as_f64().unwrap(),
        100.0 * fy["nrmse"].as_f64().unwrap()
    );
    assert!(has(&figure), "{figure} not in {header:#?}");
    // Geometry: set keys say how, undetermined keys say so.
    assert!(text
        .lines()
        .any(|l| l.starts_with("UNLOADED_RADIUS") && l.contains("$ from the data")));
    assert!(text
        .lines()
        .any(|l| l.starts_with("WIDTH") && l.contains("$ NOT DETERMINED")));
    // The header survives the reader and a second write (no pile-up).
    let t = tyrekit::tir::TyreParams::from_file(&out).unwrap();
    assert!(t.doc.header_comments.iter().any(|c| c.contains(&sha)));
    let again = t.to_tir_string();
    assert_eq!(again.matches("Written by tyrekit").count(), 1);
}
