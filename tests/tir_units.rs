//! `[UNITS]` conversion on read, with small inline fixtures. Expected values
//! are computed here from the unit definitions (NIST SP 811: 1 in = 0.0254 m,
//! 1 lbf = 4.448 221 615 260 5 N, 1 psi = 6 894.757 Pa), not from the code.
//! Tolerance: 1e-12 relative, a few ulps of the one or two multiplications
//! the conversion does.

use tyrekit::tir::{MfVersion, TyreParams};

fn fixture(units: &str, body: &str) -> String {
    format!(
        "[MDI_HEADER]\nFILE_TYPE = 'tir'\n[UNITS]\n{units}\n[MODEL]\nFITTYP = 61\n{body}\n\
         [LATERAL_COEFFICIENTS]\nPDY1 = 1.0\nPKY1 = -15.0\n"
    )
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
}

#[track_caller]
fn check(got: f64, want: f64, what: &str) {
    assert!(close(got, want), "{what}: got {got}, want {want}");
}

#[test]
fn millimetre_kilonewton_degree() {
    let t = TyreParams::from_tir_str(
        &fixture(
            "LENGTH = 'mm'\nFORCE = 'kN'\nANGLE = 'deg'\nMASS = 'kg'\nTIME = 'sec'",
            "UNLOADED_RADIUS = 313.5\nFNOMIN = 4.0\nVERTICAL_STIFFNESS = 209.651\n\
             ALPMAX = 30\nCAMMIN = -6\nLONGVL = 16700\nYAW_STIFFNESS = 0.0836537\n\
             VERTICAL_DAMPING = 0.05\nNOMPRES = 0.00022\n",
        ),
        "mm.tir",
    )
    .unwrap();
    check(t.p.unloaded_radius, 0.3135, "R0 mm");
    check(t.p.fnomin, 4000.0, "FNOMIN kN");
    // kN/mm = 1e6 N/m
    check(t.p.vertical_stiffness, 209.651e6, "Cz kN/mm");
    check(
        t.p.alpmax,
        30.0 * std::f64::consts::PI / 180.0,
        "ALPMAX deg",
    );
    check(
        t.p.cammin,
        -6.0 * std::f64::consts::PI / 180.0,
        "CAMMIN deg",
    );
    // mm/s
    check(t.p.longvl, 16.7, "LONGVL mm/s");
    // kN*mm/deg = 1 N*m / (pi/180 rad)
    check(
        t.p.yaw_stiffness,
        0.0836537 * 180.0 / std::f64::consts::PI,
        "yaw stiffness",
    );
    // kN*s/mm = 1e6 N*s/m
    check(t.p.vertical_damping, 0.05e6, "damping");
    // No PRESSURE key: FORCE/LENGTH^2 = kN/mm^2 = 1e9 Pa.
    check(t.p.nompres, 0.00022e9, "pressure derived");
    // Dimensionless coefficients untouched, even per-radian ones.
    assert_eq!(t.p.pky1, -15.0);
    assert_eq!(t.p.pdy1, 1.0);
    assert_eq!(t.version, MfVersion::Mf61);
}

#[test]
fn inch_lbf_psi_bar_lbm() {
    let inch = 0.0254;
    let lbf = 4.448_221_615_260_5;
    let t = TyreParams::from_tir_str(
        &fixture(
            "LENGTH = 'inch'\nFORCE = 'lbf'\nANGLE = 'radians'\nMASS = 'lbm'\nTIME = 'second'\nPRESSURE = 'psi'",
            "UNLOADED_RADIUS = 12.0\nFNOMIN = 1000\nVERTICAL_STIFFNESS = 1500\nNOMPRES = 32\n\
             MASS = 20\nIYY = 10\nGRAVITY = -386.09\n",
        ),
        "imperial.tir",
    )
    .unwrap();
    check(t.p.unloaded_radius, 12.0 * inch, "R0 inch");
    check(t.p.fnomin, 1000.0 * lbf, "FNOMIN lbf");
    check(t.p.vertical_stiffness, 1500.0 * lbf / inch, "Cz lbf/in");
    check(t.p.nompres, 32.0 * lbf / (inch * inch), "psi");
    assert!(
        (t.p.nompres - 220_632.2).abs() < 0.1,
        "32 psi is about 220.6 kPa"
    );
    check(t.p.mass, 20.0 * 0.453_592_37, "lbm");
    check(t.p.iyy, 10.0 * 0.453_592_37 * inch * inch, "lbm in^2");
    check(t.p.gravity, -386.09 * inch, "in/s^2");

    let b = TyreParams::from_tir_str(
        &fixture(
            "LENGTH = 'ft'\nPRESSURE = 'bar'\nFORCE = 'kgf'\nTIME = 'ms'",
            "NOMPRES = 2.2\nWIDTH = 1\nFNOMIN = 400\nFREQ_LAT = 0.04\nLONGVL = 0.05",
        ),
        "bar.tir",
    )
    .unwrap();
    check(b.p.nompres, 2.2e5, "bar");
    check(b.p.width, 0.3048, "ft");
    check(b.p.fnomin, 400.0 * 9.806_65, "kgf");
    check(b.p.freq_lat, 40.0, "1/ms");
    check(b.p.longvl, 0.05 * 0.3048 / 1e-3, "ft/ms");
}

#[test]
fn unit_names_are_case_insensitive_and_si_is_bit_exact() {
    let t = TyreParams::from_tir_str(
        &fixture(
            "LENGTH = 'Meter'\nFORCE = 'Newton'\nANGLE = 'radian'\nMASS = 'KG'\nTIME = 'Second'\nPRESSURE = 'Pascal'",
            "UNLOADED_RADIUS = 0.3135\nNOMPRES = 220000\n",
        ),
        "si.tir",
    )
    .unwrap();
    assert_eq!(t.p.unloaded_radius.to_bits(), 0.3135f64.to_bits());
    assert_eq!(t.p.nompres, 220000.0);
}

#[test]
fn unknown_unit_is_an_error_naming_file_line_and_key() {
    let e = TyreParams::from_tir_str(
        &fixture("LENGTH = 'meter'\nFORCE = 'furlong_force'", ""),
        "odd.tir",
    )
    .unwrap_err();
    match &e {
        tyrekit::Error::Tir {
            file,
            line,
            key,
            message,
        } => {
            assert_eq!(file, "odd.tir");
            assert_eq!(*line, 5);
            assert_eq!(key, "FORCE");
            assert!(
                message.contains("furlong_force") && message.contains("newton"),
                "{message}"
            );
        }
        other => panic!("wrong error kind: {other:?}"),
    }
}

#[test]
fn tables_are_converted_and_written_back_in_si() {
    let text = fixture(
        "LENGTH = 'mm'\nFORCE = 'kN'",
        "[DEFLECTION_LOAD_CURVE]\n{pen fz}\n0 0\n10 2.5\n[BOTTOMING_CURVE]\n0.0 0.0\n100 500\n[SHAPE]\n{radial width}\n1.0 0.0\n0.9 1.0\n",
    );
    let t = TyreParams::from_tir_str(&text, "tables.tir").unwrap();
    assert_eq!(
        t.table("DEFLECTION_LOAD_CURVE").unwrap().rows[1],
        vec![0.01, 2500.0]
    );
    assert_eq!(
        t.table("BOTTOMING_CURVE").unwrap().rows[1],
        vec![0.1, 500000.0]
    );
    assert_eq!(t.table("SHAPE").unwrap().rows[1], vec![0.9, 1.0]);
    let back = TyreParams::from_tir_str(&t.to_tir_string(), "back").unwrap();
    assert_eq!(
        back.table("BOTTOMING_CURVE").unwrap().rows,
        t.table("BOTTOMING_CURVE").unwrap().rows
    );
    assert_eq!(
        back.table("DEFLECTION_LOAD_CURVE").unwrap().rows,
        t.table("DEFLECTION_LOAD_CURVE").unwrap().rows
    );
}

#[test]
fn non_si_file_round_trips_through_si() {
    let t = TyreParams::from_tir_str(
        &fixture(
            "LENGTH = 'mm'\nFORCE = 'kN'\nANGLE = 'deg'",
            "UNLOADED_RADIUS = 313.5\nALPMAX = 30\n[CUSTOM]\nFOO = 3\n",
        ),
        "mm.tir",
    )
    .unwrap();
    assert!(
        t.warnings
            .iter()
            .any(|w| w.contains("FOO") && w.contains("not converted")),
        "{:?}",
        t.warnings
    );
    let text = t.to_tir_string();
    assert!(text.contains("'meter'") && text.contains("'newton'") && text.contains("'radians'"));
    let back = TyreParams::from_tir_str(&text, "si").unwrap();
    assert_eq!(back.p, t.p);
    assert_eq!(back.extra_number("CUSTOM", "FOO"), Some(3.0));
}

#[test]
fn implausible_converted_values_are_reported() {
    // NOMPRES written in Pa in a millimetre file without PRESSURE key: read
    // as N/mm^2 (ADAMS convention), which gives 2.2e11 Pa: warned, not refused.
    let t = TyreParams::from_tir_str(
        &fixture(
            "LENGTH = 'mm'\nFORCE = 'newton'",
            "NOMPRES = 220000\nUNLOADED_RADIUS = 313.5",
        ),
        "mm.tir",
    )
    .unwrap();
    check(t.p.nompres, 2.2e11, "N/mm^2");
    let w: Vec<_> = t
        .warnings
        .iter()
        .filter(|w| w.contains("NOMPRES") && w.contains("outside"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", t.warnings);
    assert!(
        w[0].starts_with("line 8:") && w[0].contains("no PRESSURE key"),
        "{}",
        w[0]
    );
    assert!(
        !t.warnings
            .iter()
            .any(|w| w.contains("UNLOADED_RADIUS") && w.contains("outside")),
        "{:?}",
        t.warnings
    );
}
