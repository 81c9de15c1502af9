//! The diagnosis report end to end: `tyrekit diagnose` without `--tir` (the
//! baseline fitted from the recording) on a rig recording and on the real
//! flat-belt test `../shared/data/measurements/TyreData.csv`; every output
//! written and consistent; the explanation's wording.

use crate::common::scratch;
use std::path::Path;
use std::process::Command;
use tyrekit::diagnose::locate::Finding;
use tyrekit::diagnose::report::{caution, findings_in_words, QualityRow};
use tyrekit::mf::Tyre;
use tyrekit::residual::Channel;
use tyrekit::rig::{effects, simulate, RigConfig};

const NAMES: [&str; 9] = [
    "none",
    "relaxation",
    "lugre",
    "thermal",
    "load_sensitivity",
    "pressure",
    "speed_friction",
    "rolling_radius",
    "camber",
];

fn run_diagnose(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .arg("diagnose")
        .args(args)
        .output()
        .unwrap()
}

/// Every output of a report directory exists and is consistent; returns
/// the diagnosis.json.
fn check_outputs(rep: &Path) -> serde_json::Value {
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("diagnosis.json")).unwrap())
            .unwrap();
    let verdict = j["verdict"].as_str().unwrap();
    assert!(NAMES.contains(&verdict), "verdict {verdict}");
    let effects = j["effects"].as_array().unwrap();
    assert_eq!(effects[0]["name"], verdict, "verdict first");
    for e in effects {
        for k in [
            "name",
            "score",
            "evidence",
            "parameters",
            "nrmse_before",
            "nrmse_after",
        ] {
            assert!(!e[k].is_null(), "effect key {k}");
        }
        assert!(NAMES.contains(&e["name"].as_str().unwrap()));
    }
    assert!(j["explanation"].as_str().unwrap().len() > 40);
    // The other qualifying findings: each an evaluated effect whose own
    // evidence says it qualifies, never the verdict, each named in the
    // explanation; none listed when nothing is named.
    let also = j["also_qualifying"].as_array().unwrap();
    if verdict == "none" {
        assert!(also.is_empty(), "{also:?}");
    }
    for a in also {
        let a = a.as_str().unwrap();
        assert_ne!(a, verdict);
        let e = effects.iter().find(|e| e["name"] == a).unwrap();
        assert!(
            e["evidence"]
                .as_str()
                .unwrap()
                .contains("Qualifies as a verdict"),
            "{a}: {}",
            e["evidence"]
        );
        assert!(j["explanation"]
            .as_str()
            .unwrap()
            .contains(&format!("{a} (")));
    }
    for e in effects.iter().skip(1) {
        if e["evidence"]
            .as_str()
            .unwrap()
            .contains("Qualifies as a verdict")
        {
            assert!(
                also.iter().any(|a| a == &e["name"]),
                "{} unlisted",
                e["name"]
            );
        }
    }
    // Quality: an overall row per diagnosed channel, in and out of sample.
    for part in ["in_sample", "out_of_sample"] {
        let rows = j["quality"][part].as_array().unwrap();
        assert!(rows
            .iter()
            .any(|r| r["condition"] == "all" && r["channel"] == "FY"));
    }
    // The page links only files that exist.
    let html = std::fs::read_to_string(rep.join("report.html")).unwrap();
    assert!(html.contains(verdict));
    let mut n = 0;
    for part in html.split("src=\"").skip(1) {
        let f = &part[..part.find('"').unwrap()];
        assert!(rep.join(f).is_file(), "report.html links missing {f}");
        n += 1;
    }
    assert!(n >= 5, "{n} images");
    // Plots first, tables after (issue #15, item 4), and the first plot is
    // the evidence against the verdict's own variable: rising against
    // falling sweeps for a lag, the residual against recorded pressure for
    // `pressure`, against frictional energy for `thermal`.
    let first_img = html.find("<img").unwrap();
    let first_table = html.find("<table").unwrap();
    assert!(first_img < first_table, "a table comes before the plots");
    let first = &html[first_img..];
    let first = &first[first.find("src=\"").unwrap() + 5..];
    let first = &first[..first.find('"').unwrap()];
    let expected = match verdict {
        "relaxation" | "lugre" => Some("hysteresis_"),
        "pressure" => Some("residual_pressure_"),
        "thermal" => Some("drift_"),
        "load_sensitivity" => Some("residual_load_"),
        _ => None,
    };
    if let Some(e) = expected {
        assert!(first.starts_with(e), "{verdict}: first plot {first}");
    }
    // Both tyre files load in the library.
    Tyre::from_file(&rep.join("baseline.tir")).unwrap();
    Tyre::from_file(&rep.join("extended.tir")).unwrap();
    j
}

/// Without --tir on a rig recording of the built-in tyre with a concealed
/// lag: the baseline is fitted from the data (MF 6.1, relaxation held), the
/// report is complete, and the held-out FY σ of the fitted baseline is that
/// of a good steady fit (< 10 %: the concealed effect is a few % of the
/// force, the rig noise ~1 %).
#[test]
fn no_tir_on_rig_recording() {
    // Removed when the test ends; kept (path on stderr) with TYREKIT_KEEP set.
    let tmp = scratch("diag-report-rig");
    let dir = tmp.path();
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 3);
    cfg.programme.pressures.truncate(1);
    cfg.programme.inclinations.truncate(1);
    cfg.programme.loads.truncate(3);
    cfg.programme.db_alphas.truncate(1);
    let mut m = effects::concealed("relaxation", tyre.clone(), 1.5).unwrap();
    let rec = dir.join("rig.mat");
    simulate(&cfg, m.as_mut()).write_mat(&rec, true).unwrap();
    let rep = dir.join("report");
    let o = run_diagnose(&[rec.to_str().unwrap(), "--report", rep.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = check_outputs(&rep);
    let fy = j["quality"]["out_of_sample"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["condition"] == "all" && r["channel"] == "FY")
        .unwrap()["sigma_before"]
        .as_f64()
        .unwrap();
    assert!(fy < 0.10, "fitted baseline FY σ {fy}");
    // Fy–α per load (issue #15, item 4): one overlay panel per load level of
    // the programme, lightest first, titled in kN.
    let svg = std::fs::read_to_string(rep.join("overlay_fy.svg")).unwrap();
    let loads: Vec<f64> = svg
        .split("Fz ")
        .skip(1)
        .filter_map(|t| t.split(" kN").next()?.parse().ok())
        .collect();
    assert_eq!(loads.len(), cfg.programme.loads.len(), "panels {loads:?}");
    assert!(loads.windows(2).all(|w| w[0] < w[1]), "{loads:?}");
    let mut want: Vec<f64> = cfg.programme.loads.iter().map(|f| f / 1e3).collect();
    want.sort_by(f64::total_cmp);
    for (got, want) in loads.iter().zip(&want) {
        assert!(
            (got - want).abs() < 0.05 * want,
            "{loads:?} against {want:?}"
        );
    }
    // Before/after per condition, once something is named.
    if j["verdict"] != "none" {
        assert!(rep.join("before_after_fy.svg").is_file());
    }
    // The baseline holds what the candidates own: no pressure terms.
    let base = Tyre::from_file(&rep.join("baseline.tir")).unwrap();
    assert_eq!(base.params().p.ppy1, 0.0);
    assert_eq!(base.params().p.ppx1, 0.0);
}

/// A recording without the slip ratio channel cannot show a rolling radius
/// that is not the tyre's (the radius check reads the recorded SR): when
/// nothing is named, the explanation says that check could not run. The
/// dev set's control r06 with SR, SL and RE left out (skipped without
/// ../shared); with them, the sentence is absent.
#[test]
fn a_recording_without_sr_says_the_radius_was_not_checked() {
    use std::io::{BufRead, Write};
    let gz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/diagnose-dev/r06.dat.gz");
    if !gz.is_file() {
        eprintln!("skipped: {} absent", gz.display());
        return;
    }
    let tmp = scratch("diag-report-nosr");
    let dir = tmp.path();
    let lines: Vec<String> = std::io::BufReader::new(flate2::read::GzDecoder::new(
        std::fs::File::open(&gz).unwrap(),
    ))
    .lines()
    .map(|l| l.unwrap())
    .collect();
    let names: Vec<&str> = lines[0].split('\t').collect();
    let keep: Vec<usize> = (0..names.len())
        .filter(|&i| !["SR", "SL", "RE"].contains(&names[i]))
        .collect();
    assert_eq!(keep.len() + 3, names.len(), "r06 has SR, SL and RE");
    let rec = dir.join("r06_nosr.dat");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&rec).unwrap());
    for l in &lines {
        let f: Vec<&str> = l.split('\t').collect();
        writeln!(
            out,
            "{}",
            keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join("\t")
        )
        .unwrap();
    }
    drop(out);
    let says = |rec: &Path, tag: &str| {
        let rep = dir.join(tag);
        let o = run_diagnose(&[rec.to_str().unwrap(), "--report", rep.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(rep.join("diagnosis.json")).unwrap())
                .unwrap();
        assert_eq!(j["verdict"], "none", "{tag}: {}", j["explanation"]);
        j["explanation"]
            .as_str()
            .unwrap()
            .contains("no slip ratio channel (SR)")
    };
    assert!(
        says(&rec, "without"),
        "the missing radius check is not mentioned"
    );
    assert!(
        !says(&gz, "with"),
        "the sentence appears though SR is recorded"
    );
}

/// The real flat-belt lateral test (MFeval's fitting example): runs end to
/// end without --tir and writes every output; Fx (crosstalk in a pure
/// lateral test, no stage fits it) is not diagnosed. Skipped without ../shared.
#[test]
fn real_tyre_data_end_to_end() {
    let csv =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/measurements/TyreData.csv");
    if !csv.is_file() {
        eprintln!("skipped: {} absent", csv.display());
        return;
    }
    let tmp = scratch("diag-report-real");
    let dir = tmp.path();
    let rep = dir.join("report");
    let o = run_diagnose(&[csv.to_str().unwrap(), "--report", rep.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = check_outputs(&rep);
    assert!(j["effects"][0]["nrmse_before"]["FX"].is_null());
    // The fitted baseline is a reasonable steady fit of Fy (`tyrekit fit`
    // reaches σ ≈ 4 % on this file; the held-out segments are scored here).
    let fy = j["quality"]["out_of_sample"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["condition"] == "all" && r["channel"] == "FY")
        .unwrap()["sigma_before"]
        .as_f64()
        .unwrap();
    assert!(fy < 0.08, "baseline FY σ {fy}");
    // The file has no drive/brake data: Fx is not diagnosed, so no
    // candidate fits a parameter that acts on Fx only (PPX*, the
    // longitudinal relaxation length, SIGMA0X, the rolling radius).
    for e in j["effects"].as_array().unwrap() {
        for k in ["PPX1", "PPX3", "LONGITUDINAL_STIFFNESS", "SIGMA0X", "Q_RE0"] {
            assert!(e["parameters"][k].is_null(), "{} fits {k}", e["name"]);
        }
    }
    // No word describes a value nobody computed: a candidate that acts
    // only on Fx has nothing to fit here, a slip region without samples has
    // no mean, and neither may print as "NaN" in the words or the page.
    let page = std::fs::read_to_string(rep.join("report.html")).unwrap();
    let text = std::fs::read_to_string(rep.join("diagnosis.json")).unwrap();
    for (what, s) in [("report.html", &page), ("diagnosis.json", &text)] {
        let at = s.find("NaN");
        assert!(
            at.is_none(),
            "{what} prints NaN: …{}…",
            &s[at.unwrap().saturating_sub(200)..at.unwrap()]
        );
    }
    // The recorded Mz lags the slip angle by 0.125 s while Fy does not
    // (the best delay of a per-sweep curve, `fit_validity`'s
    // `tyredata_mz_lags_the_slip_angle_which_no_steady_model_can_follow`):
    // locate's first-order delay on the fitted model lands within 0.025 s
    // of it, Fy's within 0.03 s of none, and the words call it the
    // measurement's, not the tyre's.
    let delay = |ch: &str| {
        j["locate"][ch]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == "force_rate")
            .and_then(|f| {
                f["groups"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|g| g[0] == "delay_s")
                    .and_then(|g| g[1].as_f64())
            })
            .unwrap()
    };
    let (mz, fy) = (delay("MZ"), delay("FY"));
    assert!((mz - 0.125).abs() < 0.025, "Mz delay {mz} s");
    assert!(fy.abs() < 0.03, "Fy delay {fy} s");
    let words = j["explanation"].as_str().unwrap();
    assert!(
        words.contains("Only Mz lags") && words.contains("points at the measurement"),
        "{words}"
    );
    // Whatever the verdict, it makes no channel's held-out squared error
    // worse by more than the rule's 5 % (the old rule named a 2.7 m
    // relaxation length that halved Fy's accuracy to gain on Mz).
    if j["verdict"] != "none" {
        for c in j["effects"][0]["channels"].as_array().unwrap() {
            let g = c["oos_gain"].as_f64().unwrap();
            assert!(g >= -0.05, "verdict worsens {}: {g}", c["channel"]);
        }
    }
}

fn finding(name: &'static str, groups: &[(&str, f64)]) -> Finding {
    Finding {
        name,
        statistic: 0.3,
        z: 8.0,
        p_value: 0.001,
        p_adjusted: 0.005,
        significant: true,
        detail: String::new(),
        groups: groups.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        share: 0.3,
    }
}

/// Significant findings are named with their figures, units and size (the
/// share of the squares); the rest are not mentioned; nothing significant
/// gives None.
#[test]
fn findings_in_words_names_the_signatures() {
    let mut f = vec![
        finding("sweep_direction", &[("rising_minus_falling", 41.26)]),
        finding("force_rate", &[]),
        finding(
            "load",
            &[
                ("x_min", 2000.0),
                ("x_max", 6000.0),
                ("scale_at_min", 0.021),
                ("scale_at_max", -0.034),
            ],
        ),
    ];
    let mut quiet = finding("time_in_run", &[("slope_per_s", 1.0)]);
    quiet.significant = false;
    f.push(quiet);
    let w = findings_in_words(&f, "N").unwrap();
    assert!(
        w.contains("sweep direction (rising − falling +41.3 N"),
        "{w}"
    );
    assert!(w.contains("force rate"), "{w}");
    assert!(w.contains("+2.1 % at 2000 N, -3.4 % at 6000 N"), "{w}");
    assert!(w.contains("at 6000 N) [30 % of its squares]"), "{w}");
    assert!(!w.contains("time in the run"), "{w}");
    assert!(findings_in_words(&f[3..], "N").is_none());
}

fn row(channel: &str, before: f64, after: f64) -> QualityRow {
    QualityRow {
        channel: Channel::parse(channel).expect("a channel name"),
        condition: "all".into(),
        fz: None,
        n: 1000,
        sigma_before: before,
        sigma_after: after,
        nrmse_before: before / 3.0,
        nrmse_after: after / 3.0,
    }
}

/// A verdict that makes one channel's held-out σ worse by more than 10 %
/// while another gains is flagged; small changes are not.
#[test]
fn caution_when_a_channel_gets_worse() {
    let c = caution(&[row("FY", 0.047, 0.063), row("MZ", 0.22, 0.19)]).unwrap();
    assert!(c.contains("Fy (held-out σ 4.70 % → 6.30 %)"), "{c}");
    assert!(c.contains("from Mz alone"), "{c}");
    // 5 % worse is within the scatter between halves: no caution.
    assert!(caution(&[row("FY", 0.040, 0.042), row("MZ", 0.22, 0.10)]).is_none());
}
