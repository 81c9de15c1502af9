//! The `.tir` syntax as found in the wild, warnings, refusals and the
//! custom-section API, with small inline fixtures.

use tyrekit::tir::{MfVersion, TyreParams, TyreSide, Value};

const COEFFS: &str = "[LATERAL_COEFFICIENTS]\nPDY1 = 0.9\n";

fn read(text: &str) -> TyreParams {
    TyreParams::from_tir_str(text, "fixture.tir").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn duplicate_key_warns_naming_both_lines_and_later_wins() {
    let t = read(&format!(
        "[MODEL]\nFITTYP = 61\n[VERTICAL]\nFNOMIN = 4000\nVERTICAL_DAMPING = 50\nFNOMIN = 4500\n{COEFFS}"
    ));
    assert_eq!(t.p.fnomin, 4500.0);
    let w: Vec<_> = t.warnings.iter().filter(|w| w.contains("FNOMIN")).collect();
    assert_eq!(w.len(), 1, "{:?}", t.warnings);
    assert!(
        w[0].contains("line 6") && w[0].contains("line 4"),
        "{}",
        w[0]
    );
}

#[test]
fn duplicate_unknown_key_and_section() {
    let t = read(&format!(
        "[MODEL]\nFITTYP = 62\n[VENDOR]\nA = 1\n[VENDOR]\nA = 2\nB = 'x'\n{COEFFS}"
    ));
    assert_eq!(t.extra_number("VENDOR", "A"), Some(2.0));
    assert_eq!(t.section("VENDOR").unwrap().entries.len(), 2);
    assert!(t
        .warnings
        .iter()
        .any(|w| w.contains("[VENDOR]") && w.contains("line 5") && w.contains("line 3")));
    assert!(t
        .warnings
        .iter()
        .any(|w| w.contains("A given again") && w.contains("line 4")));
}

#[test]
fn empty_and_non_numeric_values_are_defaults_with_warnings() {
    let t = read(&format!(
        "[MODEL]\nFITTYP = 61\n[DIMENSION]\nWIDTH =   \nUNLOADED_RADIUS = 0.3\n[INERTIA]\nMASS = kg\n{COEFFS}"
    ));
    assert_eq!(
        t.p.width,
        tyrekit::tir::keys::key_def("WIDTH").unwrap().default
    );
    assert!(t.defaulted.contains(&"WIDTH") && t.defaulted.contains(&"MASS"));
    assert!(!t.defaulted.contains(&"UNLOADED_RADIUS"));
    assert!(t
        .warnings
        .iter()
        .any(|w| w.starts_with("line 4:") && w.contains("WIDTH") && w.contains("empty")));
    assert!(t
        .warnings
        .iter()
        .any(|w| w.starts_with("line 7:") && w.contains("MASS") && w.contains("\"kg\"")));
    assert_eq!(t.invalid, vec![("WIDTH", 4), ("MASS", 7)]);
}

#[test]
fn dollar_inside_bang_comment_and_quotes_is_not_a_comment() {
    let t = read(&format!(
        "!$Revision: 1.15 $ = 3\n[MDI_HEADER]\n! FILE $ X = 1\nFILE_TYPE = 'tir'\n\
         [MODEL]\nFITTYP = 61 $ comment 'quoted'\nFUNCTION_NAME = 'a$b::TYR815' $ trailing\n\
         TITLE = 'has ! bang'\n{COEFFS}"
    ));
    assert_eq!(t.string("FUNCTION_NAME"), Some("a$b::TYR815"));
    assert_eq!(t.string("TITLE"), Some("has ! bang"));
    assert_eq!(t.doc.header_comments[0], "$Revision: 1.15 $ = 3");
    assert!(t.warnings.is_empty(), "{:?}", t.warnings);
    let back = read(&t.to_tir_string());
    assert_eq!(back.string("FUNCTION_NAME"), Some("a$b::TYR815"));
    assert_eq!(back.doc.header_comments, t.doc.header_comments);
}

#[test]
fn whitespace_line_ends_and_odd_layouts() {
    let text = "[MDI_HEADER]   \r\n\tFILE_TYPE\t \t= 'tir'\t \r\n[MODEL] \r\nFITTYP    =52\r\n\
                VXLOW = 6.7056            \r\n[VERTICAL]\r\nNOMPRES\t\t\t\t\t = 55158.06\t\t$Nominal\t\r\n\
                Q_V1 = 1.0D-3\r\n[SCALING_COEFFICIENTS]\r\n LFZ0 = 1.1\r\n\
                [SES_TIRE_PLOTTER]\r\nCONSTRUCTION = R25B 16 x 7.5 on 10x7 Rim\r\n";
    let t = read(text);
    assert_eq!(t.version, MfVersion::Mf52);
    assert_eq!(t.p.vxlow, 6.7056);
    assert_eq!(t.p.nompres, 55158.06);
    assert_eq!(t.p.q_v1, 1.0e-3);
    assert_eq!(t.p.lfzo, 1.1, "LFZ0 (zero) is LFZO");
    assert_eq!(
        t.extra("SES_TIRE_PLOTTER", "CONSTRUCTION"),
        Some(&Value::Word("R25B 16 x 7.5 on 10x7 Rim".into()))
    );
    let back = read(&t.to_tir_string());
    assert_eq!(back.p, t.p);
    assert_eq!(
        back.string("CONSTRUCTION"),
        Some("R25B 16 x 7.5 on 10x7 Rim")
    );
}

#[test]
fn legacy_spellings_are_kept_but_not_read() {
    let t = read(&format!(
        "[MODEL]\nFITTYP = 61\n[VERTICAL]\nQFZ2 = 15.4\nQV1 = 7e-4\n{COEFFS}"
    ));
    let q_fz2_default = tyrekit::tir::keys::key_def("Q_FZ2").unwrap().default;
    assert_eq!(t.p.q_fz2, q_fz2_default);
    assert!(t.defaulted.contains(&"Q_FZ2") && t.defaulted.contains(&"Q_V1"));
    assert_eq!(t.extra_number("VERTICAL", "QFZ2"), Some(15.4));
    assert!(t
        .warnings
        .iter()
        .any(|w| w.contains("QFZ2") && w.contains("legacy")));
    let back = read(&t.to_tir_string());
    assert_eq!(back.extra_number("VERTICAL", "QFZ2"), Some(15.4));
    assert_eq!(back.p, t.p);
}

#[test]
fn comments_block_and_non_utf8_bytes() {
    let mut bytes =
        b"[MDI_HEADER]\r\nFILE_TYPE = 'tir'\r\n(COMMENTS)\r\n{comment_string}\r\n'Tyre = test 20"
            .to_vec();
    bytes.push(0xB0); // Latin-1 degree sign: not valid UTF-8
    bytes.extend_from_slice(b"C'\r\n[MODEL]\r\nFITTYP = 61\r\nNOTE = '90");
    bytes.push(0xB0);
    bytes.extend_from_slice(b"'\r\n[LATERAL_COEFFICIENTS]\r\nPDY1 = 1\r\n");
    let t = TyreParams::from_bytes(&bytes, "latin1.tir").unwrap();
    assert_eq!(t.string("NOTE"), Some("90\u{b0}"));
    let raw = &t.section("MDI_HEADER").unwrap().raw;
    assert_eq!(raw.len(), 3, "{raw:?}");
    assert!(t.warnings.is_empty(), "{:?}", t.warnings);
    let back = read(&t.to_tir_string());
    assert_eq!(back.section("MDI_HEADER").unwrap().raw, *raw);
}

#[test]
fn tyreside_values() {
    for (s, side) in [
        ("'RIGHT'", TyreSide::Right),
        ("'symmetric'", TyreSide::Symmetric),
        ("'UNKNOWN'", TyreSide::Unknown),
    ] {
        let t = read(&format!("[MODEL]\nFITTYP = 61\nTYRESIDE = {s}\n{COEFFS}"));
        assert_eq!(t.side, side);
        assert_eq!(read(&t.to_tir_string()).side, side);
    }
    let t = read(&format!("[MODEL]\nFITTYP = 61\n{COEFFS}"));
    assert_eq!(t.side, TyreSide::Left, "LEFT when the file does not say");
}

#[test]
fn version_recognition() {
    let v = |model: &str| read(&format!("[MODEL]\n{model}\n{COEFFS}")).version;
    assert_eq!(v("FITTYP = 5"), MfVersion::Mf52);
    assert_eq!(v("FITTYP = 6"), MfVersion::Mf52);
    assert_eq!(v("FITTYP = 52"), MfVersion::Mf52);
    assert_eq!(v("FITTYP = 61"), MfVersion::Mf61);
    assert_eq!(v("FITTYP = 62"), MfVersion::Mf62);
    assert_eq!(v("PROPERTY_FILE_FORMAT = 'PAC2002'"), MfVersion::Pac2002);
    assert_eq!(v("PROPERTY_FILE_FORMAT = 'MF_05'"), MfVersion::Mf52);
    assert_eq!(v("PROPERTY_FILE_FORMAT = 'MF61'"), MfVersion::Mf61);
    let t = read(&format!(
        "! : TIRE_VERSION :      PAC2002\n[MODEL]\nPROPERTY_FILE_FORMAT = 'USER'\n{COEFFS}"
    ));
    assert_eq!(t.version, MfVersion::Pac2002);
    let t = read(&format!(
        "!TIRE_VERSION:        MF-TYRE 5.0 (W-axis system)\n[MODEL]\nUSE_MODE = 4\n{COEFFS}"
    ));
    assert_eq!(t.version, MfVersion::Mf52);
    // Nothing says: PAC2002 assumed, not silently.
    let t = read(&format!("[MODEL]\nUSE_MODE = 4\n{COEFFS}"));
    assert_eq!(t.version, MfVersion::Pac2002);
    assert!(t.warnings.iter().any(|w| w.contains("PAC2002 assumed")));
    // Versions survive the writer, including PAC2002 without FITTYP.
    for m in [
        "FITTYP = 5",
        "FITTYP = 62",
        "PROPERTY_FILE_FORMAT = 'PAC2002'",
        "PROPERTY_FILE_FORMAT = 'MF61'",
        "USE_MODE = 4",
    ] {
        let t = read(&format!("[MODEL]\n{m}\n{COEFFS}"));
        let back = read(&t.to_tir_string());
        assert_eq!(back.version, t.version, "{m}");
        assert_eq!(back.p, t.p, "{m}");
    }
}

#[test]
fn other_models_and_unknown_fittyp_are_refused() {
    let err = |text: &str| {
        TyreParams::from_tir_str(text, "x.tir")
            .unwrap_err()
            .to_string()
    };
    let e = err("[MODEL]\nPROPERTY_FILE_FORMAT = 'USER'\nFUNCTION_NAME = 'HTire501_2013::TYR501'\n[PARAMETER]\nVERTICAL_STIFFNESS = 146\n");
    assert!(
        e.contains("x.tir:3:") && e.contains("Harty") && e.contains("FUNCTION_NAME"),
        "{e}"
    );
    let e = err("[MODEL]\nPROPERTY_FILE_FORMAT = 'FIALA'\n[PARAMETER]\nCSLIP = 1\n");
    assert!(e.contains("Fiala") && e.contains("x.tir:2:"), "{e}");
    let e =
        err("[MODEL]\nUSE_MODE = 1\n[PARAMETER]\nCSLIP = 1\nCALPHA = 2\nUMIN = 0.9\nUMAX = 1\n");
    assert!(e.contains("Fiala") && e.contains("CSLIP"), "{e}");
    let e = err("[DIMENSION]\nUNLOADED_RADIUS = 0.3\n");
    assert!(e.contains("no Magic Formula coefficient"), "{e}");
    let e = err(&format!("[MODEL]\nFITTYP = 21\n{COEFFS}"));
    assert!(e.contains("x.tir:2: FITTYP") && e.contains("61"), "{e}");
    // FITTYP alone is enough to accept a file without coefficients (all defaulted).
    let t = read("[MODEL]\nFITTYP = 61\n");
    assert!(t.defaulted.contains(&"PDY1"));
}

#[test]
fn custom_sections_and_strings_round_trip() {
    let mut t = TyreParams::builtin();
    {
        let s = t.extra_section("LUGRE");
        s.set("SIGMA0", 500.0);
        s.set("SIGMA1", 1.5e-3);
        s.set("MODE", "distributed");
    }
    t.extra_section("THERMAL").set("T_REF", 293.15);
    t.set_string("MODEL", "FITTED_BY", "tyrekit fit");
    t.set("PDY1", 1.05).unwrap();
    assert!(t.set("NOT_A_KEY", 1.0).is_err());
    // A key of the table put in a custom section is not written twice.
    t.extra_section("LUGRE").set("FNOMIN", 1.0);
    let text = t.to_tir_string();
    let back = read(&text);
    assert!(back.warnings.is_empty(), "{:?}\n{text}", back.warnings);
    assert_eq!(back.p, t.p);
    assert_eq!(back.p.pdy1, 1.05);
    assert_eq!(back.extra_number("LUGRE", "SIGMA0"), Some(500.0));
    assert_eq!(back.extra_number("LUGRE", "SIGMA1"), Some(1.5e-3));
    assert_eq!(
        back.extra("LUGRE", "MODE").and_then(Value::as_str),
        Some("distributed")
    );
    assert_eq!(back.extra_number("THERMAL", "T_REF"), Some(293.15));
    assert_eq!(back.string("FITTED_BY"), Some("tyrekit fit"));
    assert_eq!(back.defaulted, t.defaulted);
}

#[test]
fn every_number_round_trips_bit_exactly() {
    // Awkward values: shortest round-trip formatting must reproduce each bit pattern.
    let values = [
        0.1,
        -0.0,
        1e-300,
        5e-324,
        1.7976931348623157e308,
        1.0 / 3.0,
        2.0f64.sqrt(),
        -7.742e-4,
        123_456_789.123_456_78,
    ];
    let mut t = TyreParams::builtin();
    for (i, &x) in values.iter().enumerate() {
        t.p.as_mut_slice()[10 + i] = x;
        t.extra_section("X").set(&format!("K{i}"), x);
    }
    let back = read(&t.to_tir_string());
    for (a, b) in t.p.as_slice().iter().zip(back.p.as_slice()) {
        assert_eq!(a.to_bits(), b.to_bits());
    }
    for (i, &x) in values.iter().enumerate() {
        assert_eq!(
            back.extra_number("X", &format!("K{i}")).map(f64::to_bits),
            Some(x.to_bits())
        );
    }
}

#[test]
fn api_cannot_make_the_writer_write_a_key_twice() {
    let mut t = TyreParams::builtin();
    t.extra_section("UNITS").set("LENGTH", "mm");
    t.extra_section("UNITS").set("NOTE", "kept");
    t.extra_section("MODEL").set("TYRESIDE", "RIGHT");
    t.extra_section("VERTICAL").set("FNOMIN", 1.0);
    let back = read(&t.to_tir_string());
    assert_eq!(back.p, t.p, "units stay SI, FNOMIN comes from p");
    assert_eq!(back.side, TyreSide::Left, "TYRESIDE comes from `side`");
    assert_eq!(
        back.extra("UNITS", "NOTE").and_then(Value::as_str),
        Some("kept")
    );
}

/// A value that starts like a number but is not one is a typo: refused with
/// file, line and key, never silently replaced by the default.
#[test]
fn malformed_number_is_an_error_naming_file_line_key() {
    for bad in ["0.3.1", "1,5", "-", "2e"] {
        let text = format!("[MODEL]\nFITTYP = 61\n[DIMENSION]\nUNLOADED_RADIUS = {bad}\n{COEFFS}");
        let e = TyreParams::from_tir_str(&text, "typo.tir")
            .expect_err(&format!("UNLOADED_RADIUS = {bad} accepted"))
            .to_string();
        assert!(
            e.contains("typo.tir") && e.contains(":4") && e.contains("UNLOADED_RADIUS"),
            "{bad}: {e}"
        );
    }
}
