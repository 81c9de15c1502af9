//! The real flat-belt lateral test `../shared/data/measurements/TyreData.csv`
//! (MFeval's fitting example: ISO-W, SI, MFeval column names with `[unit]`
//! suffixes): it loads, and its documented structure — 45 sweeps = 3
//! pressures × 3 inclinations × 5 loads — is found. Skipped when ../shared
//! is absent.

use std::path::PathBuf;
use tyrekit::data::{load, LoadOptions, SegmentKind};

fn data_file() -> Option<PathBuf> {
    shared_file("TyreData.csv")
}

fn shared_file(name: &str) -> Option<PathBuf> {
    // ../shared relative to the crate root (CI layout); TYREKIT_SHARED overrides.
    let shared = std::env::var("TYREKIT_SHARED")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../shared").into());
    let p = PathBuf::from(shared).join("data/measurements").join(name);
    if p.exists() {
        Some(p)
    } else {
        println!("SKIP: {} not found (../shared absent)", p.display());
        None
    }
}

fn distinct(mut v: Vec<f64>, tol: f64) -> Vec<f64> {
    v.sort_by(|a, b| a.total_cmp(b));
    let mut out: Vec<f64> = Vec::new();
    for x in v {
        if out.last().is_none_or(|l| (x - l).abs() > tol) {
            out.push(x);
        }
    }
    out
}

#[test]
fn tyredata_has_45_sweeps_3_pressures_3_cambers_5_loads() {
    let Some(p) = data_file() else { return };
    let l = load(&p, &LoadOptions::default()).expect("TyreData.csv loads");
    let rec = &l.recording;
    let rep = &l.report;
    println!("{:#?}", rep.dropped);
    println!("kappa: {}", rep.kappa);
    assert_eq!(rep.rows_read, 2805);
    // All 15 columns are finite and in range: nothing may be dropped.
    assert_eq!(rep.dropped_total, 0, "{:?}", rep.dropped);
    // The file has no My and these MFeval names map onto our channels.
    for c in [
        "time", "Vx", "omega", "Fz", "kappa", "alpha", "gamma", "phit", "P", "Fx", "Fy", "Mx", "Mz",
    ] {
        assert!(rec.has(c), "channel {c} not recognised");
    }
    assert_eq!(rep.missing, vec!["My".to_string()]);
    assert!(rec.extra("Rl").is_some() && rec.extra("Re").is_some());
    // No warm-up in a pre-processed file.
    assert!(rep.warmup.is_none(), "{:?}", rep.warmup);
    let segs = &rec.segments;
    for s in segs {
        println!(
            "{:5} {:5} {:?} Fz {:7.1} γ {:6.4} P {:7.0} V {:5.2}",
            s.start, s.end, s.kind, s.fz, s.gamma, s.p, s.vx
        );
    }
    assert_eq!(segs.len(), 45);
    assert!(segs.iter().all(|s| s.kind == SegmentKind::PureLateral));
    // Set points: loads ≈ 310/535/760/1200/1650 N (±60 N), γ 0/2/4° (±0.3°),
    // P ≈ 69.3/83.1/97.0 kPa (±1.5 kPa): values from SOURCES.md.
    let loads = distinct(segs.iter().map(|s| s.fz).collect(), 120.0);
    let cambers = distinct(segs.iter().map(|s| s.gamma.to_degrees()).collect(), 0.5);
    let press = distinct(segs.iter().map(|s| s.p).collect(), 5000.0);
    assert_eq!(loads.len(), 5, "{loads:?}");
    assert_eq!(cambers.len(), 3, "{cambers:?}");
    assert_eq!(press.len(), 3, "{press:?}");
    for (got, want) in loads.iter().zip([310.0, 535.0, 760.0, 1200.0, 1650.0]) {
        assert!((got - want).abs() < 60.0, "load {got} vs {want}");
    }
    for (got, want) in cambers.iter().zip([0.0, 2.0, 4.0]) {
        assert!((got - want).abs() < 0.3, "camber {got} vs {want}");
    }
    for (got, want) in press.iter().zip([69_300.0, 83_100.0, 97_000.0]) {
        assert!((got - want).abs() < 1500.0, "pressure {got} vs {want}");
    }
    // Every (P, γ, Fz) combination occurs exactly once.
    for p in &press {
        for g in &cambers {
            for f in &loads {
                let n = segs
                    .iter()
                    .filter(|s| {
                        (s.p - p).abs() < 5000.0
                            && (s.gamma.to_degrees() - g).abs() < 0.5
                            && (s.fz - f).abs() < 120.0
                    })
                    .count();
                assert_eq!(n, 1, "P {p} γ {g} Fz {f}");
            }
        }
    }
    // Sweeps are triangular 0 → −13° → +13° → 0: both directions occur in each.
    for s in segs {
        let d = &rec.sweep_dir[s.start..s.end];
        assert!(d.contains(&1) && d.contains(&-1));
        assert_eq!(rec.t_in_segment[s.start], 0.0);
    }
}

/// The same data as a MATLAB `table` object (MCOS): not decodable as
/// channels, and said so clearly instead of misread.
#[test]
fn tyredata_mat_table_object_is_refused_clearly() {
    let Some(p) = shared_file("TyreData.mat") else {
        return;
    };
    match load(&p, &LoadOptions::default()) {
        Err(tyrekit::Error::Recording {
            location, message, ..
        }) => {
            assert_eq!(location, "variables");
            assert!(
                message.contains("'TyreData'") && message.contains("table"),
                "{message}"
            );
        }
        other => panic!(
            "expected a clear refusal, got {:?}",
            other.map(|l| l.report)
        ),
    }
}
