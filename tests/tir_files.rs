//! Every file of the shared `.tir` folder: loads with the expected version
//! (or is refused for the stated reason), values agree with an independent
//! scan of the raw text, and the writer round-trips bit-exactly.

use crate::tir_common;

use tir_common::{file_name, scan_last_number, tir_files};
use tyrekit::tir::{MfVersion, TyreParams, KEYS};

/// Versions as declared by the files (SOURCES.md of the shared folder).
fn expected_version(name: &str) -> Option<MfVersion> {
    use MfVersion::*;
    let v = match name {
        "335_65R22_5_G275MSA_40psi.tir" | "335_65R22_5_G275MSA_60psi.tir" => Mf52,
        "MagicFormula52_Parameters.tir" | "obfuscated_v52.tir" => Mf52,
        "MF5.2 -BROKEN- Hoosier205x7x13R25B-ISO.TIR"
        | "MF5.2-Hoosier-R25B-43105-MX26-7in-rim.TIR" => Mf52,
        "CityBus_Pac02Tire.tir"
        | "Generic_Pac02Tire.tir"
        | "HMMWV_Pac02Tire.tir"
        | "HMMWV_pacejka.tir"
        | "Polaris_Pac02Tire.tir"
        | "Sedan_Pac02Tire.tir"
        | "UAZBUS_Pac02Tire.tir"
        | "suv_Pac02Tire.tir"
        | "mf_185_80R14.tir"
        | "Fr_tire.tir"
        | "Modified_Round_8_Hoosier_R25B_16x7p5_10_on_7in_12psi_PAC02_UM2.tir" => Pac2002,
        "FSAE_Defaults.tir"
        | "MagicFormula61_Parameters.tir"
        | "Model_Unstable.tir"
        | "PacejkaBook_Defaults.tir"
        | "reference_tire_tvd3.tir"
        | "obfuscated.tir"
        | "Hoosier-20.5x7x13R25B-ISO.TIR"
        | "HoosierR20.tir"
        | "sample.tir"
        | "TIR_template.tir" => Mf61,
        "MagicFormula62_Parameters.tir"
        | "TNO_car205_60R15.tir"
        | "KT_MF_Tool_245_60_R16.tir"
        | "car205_60R19.tir"
        | "Truck_430_50R38.tir"
        | "fsae190_50R10.tir" => Mf62,
        _ => return None,
    };
    Some(v)
}

fn is_harty(name: &str) -> bool {
    name.starts_with("dunlop_")
}

#[test]
fn every_file_loads_with_its_version_or_is_refused() {
    let files = tir_files();
    let mut loaded = 0;
    for path in &files {
        let name = file_name(path);
        let r = TyreParams::from_file(path);
        if is_harty(&name) {
            let e = r.expect_err(&format!("{name}: a Harty file must be refused"));
            let msg = e.to_string();
            assert!(msg.contains("Harty"), "{name}: {msg}");
            assert!(msg.contains("not a Magic Formula file"), "{name}: {msg}");
            assert!(msg.contains(&name), "error must name the file: {msg}");
            assert!(
                msg.contains("FUNCTION_NAME"),
                "error must name the key: {msg}"
            );
            continue;
        }
        let t = r.unwrap_or_else(|e| panic!("{name}: {e}"));
        loaded += 1;
        match expected_version(&name) {
            Some(v) => assert_eq!(t.version, v, "{name}"),
            None => eprintln!(
                "{name}: not in the expected-version list, read as {:?}",
                t.version
            ),
        }
    }
    if !files.is_empty() {
        assert!(loaded >= 27, "only {loaded} files loaded");
    }
}

/// Each numeric key of the table must equal the last `KEY = number` line of
/// the raw text (all shared files are SI); keys with no such line must be
/// defaulted (or given through the alias LFZ0).
#[test]
fn values_match_an_independent_scan() {
    for path in tir_files() {
        let name = file_name(&path);
        if is_harty(&name) {
            continue;
        }
        let bytes = std::fs::read(&path).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        let t = TyreParams::from_file(&path).unwrap();
        for k in KEYS.iter() {
            let got = t.get(k.name).unwrap();
            let scanned = scan_last_number(&text, k.name).or_else(|| {
                (k.name == "LFZO")
                    .then(|| scan_last_number(&text, "LFZ0"))
                    .flatten()
            });
            match scanned {
                Some(x) => {
                    assert_eq!(
                        got.to_bits(),
                        x.to_bits(),
                        "{name}: {} = {got}, file says {x}",
                        k.name
                    );
                    assert!(
                        !t.defaulted.contains(&k.name),
                        "{name}: {} given but listed as defaulted",
                        k.name
                    );
                }
                None => {
                    assert!(
                        t.defaulted.contains(&k.name),
                        "{name}: {} not in the file but not defaulted",
                        k.name
                    );
                    assert_eq!(got.to_bits(), k.default.to_bits(), "{name}: {}", k.name);
                }
            }
        }
    }
}

#[test]
fn crlf_and_lf_twins_give_identical_params() {
    let files = tir_files();
    let find = |n: &str| files.iter().find(|p| file_name(p) == n).cloned();
    let (Some(a), Some(b)) = (find("Generic_Pac02Tire.tir"), find("HMMWV_Pac02Tire.tir")) else {
        return;
    };
    let ta = TyreParams::from_file(&a).unwrap();
    let tb = TyreParams::from_file(&b).unwrap();
    assert!(std::fs::read(&b).unwrap().windows(2).any(|w| w == b"\r\n"));
    assert!(!std::fs::read(&a).unwrap().windows(2).any(|w| w == b"\r\n"));
    let bits = |t: &TyreParams| {
        t.p.as_slice()
            .iter()
            .map(|x| x.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&ta), bits(&tb));
    assert_eq!(ta.version, tb.version);
    assert_eq!(ta.defaulted, tb.defaulted);
    assert_eq!(ta.doc.sections.len(), tb.doc.sections.len());
    // No CR survives in kept strings.
    for s in &tb.doc.sections {
        for e in &s.entries {
            assert!(!format!("{:?}", e.value).contains('\r'), "{}", e.key);
        }
    }
}

#[test]
fn round_trip_is_bit_exact_for_every_file() {
    for path in tir_files() {
        let name = file_name(&path);
        if is_harty(&name) {
            continue;
        }
        let t = TyreParams::from_file(&path).unwrap();
        let text = t.to_tir_string();
        let back = TyreParams::from_tir_str(&text, "round-trip")
            .unwrap_or_else(|e| panic!("{name}: written file does not read back: {e}\n{text}"));
        for (k, (a, b)) in KEYS
            .iter()
            .zip(t.p.as_slice().iter().zip(back.p.as_slice()))
        {
            assert_eq!(a.to_bits(), b.to_bits(), "{name}: {}: {a} -> {b}", k.name);
        }
        assert_eq!(t.version, back.version, "{name}");
        assert_eq!(t.side, back.side, "{name}");
        assert_eq!(t.defaulted, back.defaulted, "{name}");
        assert!(
            back.warnings.iter().all(|w| !w.contains("given again")),
            "{name}: {:?}",
            back.warnings
        );
        // Everything kept comes back: entries (key and value), tables, verbatim lines.
        for s in &t.doc.sections {
            let bs = back
                .section(&s.name)
                .unwrap_or_else(|| panic!("{name}: section [{}] lost", s.name));
            for e in &s.entries {
                assert_eq!(
                    bs.get(&e.key),
                    Some(&e.value),
                    "{name}: [{}] {}",
                    s.name,
                    e.key
                );
            }
            assert_eq!(
                s.table,
                bs.table.clone().map(|mut t| {
                    t.line = s.table.as_ref().map_or(0, |x| x.line);
                    t
                }),
                "{name}: [{}] table",
                s.name
            );
            for r in &s.raw {
                assert!(bs.raw.contains(r), "{name}: [{}] line {r:?} lost", s.name);
            }
        }
        // Writing the re-read file gives the same text (the writer is stable).
        assert_eq!(back.to_tir_string(), text, "{name}");
    }
}

#[test]
fn truck_files_tables_and_duplicate_table_section() {
    let files = tir_files();
    let find = |n: &str| files.iter().find(|p| file_name(p) == n).cloned();
    let (Some(p40), Some(p60)) = (
        find("335_65R22_5_G275MSA_40psi.tir"),
        find("335_65R22_5_G275MSA_60psi.tir"),
    ) else {
        return;
    };
    let t40 = TyreParams::from_file(&p40).unwrap();
    let shape = t40.table("SHAPE").expect("[SHAPE] kept");
    assert!(
        shape.columns.is_empty(),
        "the 40 psi [SHAPE] has no {{}} header"
    );
    let text40 = String::from_utf8_lossy(&std::fs::read(&p40).unwrap()).into_owned();
    let raw_rows = rows_after_header(&text40, "[SHAPE]", 0);
    assert_eq!(shape.rows, raw_rows);
    assert_eq!(
        t40.table("DEFLECTION_LOAD_CURVE").unwrap().columns,
        vec!["pen", "fz"]
    );
    assert_eq!(
        t40.table("BOTTOMING_CURVE").unwrap().columns,
        vec!["pen", "fz"]
    );

    let t60 = TyreParams::from_file(&p60).unwrap();
    let text60 = String::from_utf8_lossy(&std::fs::read(&p60).unwrap()).into_owned();
    let n = text60.matches("[DEFLECTION_LOAD_CURVE]").count();
    assert_eq!(n, 2);
    // The later copy (tab-separated) wins.
    let last = rows_after_header(&text60, "[DEFLECTION_LOAD_CURVE]", n - 1);
    assert_eq!(t60.table("DEFLECTION_LOAD_CURVE").unwrap().rows, last);
    assert!(t60
        .warnings
        .iter()
        .any(|w| w.contains("DEFLECTION_LOAD_CURVE") && w.contains("again")));
    // FITTYP = 5 with PROPERTY_FILE_FORMAT = 'PAC2002': FITTYP wins, with a warning.
    assert_eq!(t60.version, MfVersion::Mf52);
    assert!(t60
        .warnings
        .iter()
        .any(|w| w.contains("PROPERTY_FILE_FORMAT") && w.contains("FITTYP")));
    assert_eq!(t60.string("FE_METHOD"), Some("YES"));
    assert_eq!(
        t60.extra("GOODYEAR", "CONSTRUCTION")
            .and_then(|v| v.as_str()),
        Some("0L5001")
    );
}

/// Numeric rows after the `which`-th occurrence of `header`, read naively
/// (lines of whitespace-separated numbers until the next non-row line).
fn rows_after_header(text: &str, header: &str, which: usize) -> Vec<Vec<f64>> {
    let mut rows = Vec::new();
    let mut seen = 0;
    let mut inside = false;
    for line in text.lines() {
        let l = line.trim();
        if l.starts_with(header) {
            inside = seen == which;
            seen += 1;
            continue;
        }
        if !inside || l.starts_with('{') {
            continue;
        }
        let nums: Result<Vec<f64>, _> = l.split_whitespace().map(str::parse::<f64>).collect();
        match nums {
            Ok(r) if !r.is_empty() => rows.push(r),
            _ => {
                if !rows.is_empty() {
                    break;
                }
            }
        }
    }
    rows
}

#[test]
fn broken_mf52_file_reads_dimension_keys_under_model() {
    let files = tir_files();
    let Some(p) = files.iter().find(|p| file_name(p).contains("BROKEN")) else {
        return;
    };
    let text = String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned();
    assert!(!text.contains("[DIMENSION]"));
    let t = TyreParams::from_file(p).unwrap();
    let r0 = scan_last_number(&text, "UNLOADED_RADIUS").unwrap();
    assert_eq!(t.p.unloaded_radius, r0);
    assert!(!t.defaulted.contains(&"UNLOADED_RADIUS"));
    assert_eq!(t.p.nompres, scan_last_number(&text, "NOMPRES").unwrap());
    assert_eq!(t.p.fittyp, 52.0);
}

#[test]
fn builtin_is_the_book_reference_tyre() {
    let b = TyreParams::builtin();
    assert_eq!(b.version, MfVersion::Mf61);
    assert!(b.warnings.is_empty(), "{:?}", b.warnings);
    // Against the raw text of builtin.tir, scanned independently.
    let text = tyrekit::tir::BUILTIN_TIR;
    for k in KEYS.iter() {
        match scan_last_number(text, k.name) {
            Some(x) => assert_eq!(b.get(k.name).unwrap(), x, "{}", k.name),
            None => assert!(b.defaulted.contains(&k.name), "{}", k.name),
        }
    }
    // And against the independent transcription of the same book table in
    // the shared folder (reference_tire_tvd3.tir), when present.
    let files = tir_files();
    if let Some(p) = files
        .iter()
        .find(|p| file_name(p) == "reference_tire_tvd3.tir")
    {
        let r = TyreParams::from_file(p).unwrap();
        for (k, (a, c)) in KEYS.iter().zip(b.p.as_slice().iter().zip(r.p.as_slice())) {
            assert_eq!(a, c, "{}", k.name);
        }
    }
}
