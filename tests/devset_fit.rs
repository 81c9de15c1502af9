//! The fit measured on the independent dev set
//! (`../shared/data/diagnose-dev`, issue #14 item 3), as a user runs it:
//! `tyrekit fit REC --holdout tail:0.3 --out F.tir`, then
//! `tyrekit replay REC --tir F.tir --out sim.csv`, no other flags, and the
//! NRMSE of `answers.json`'s `nrmse_definition` on the last 30 % beside the
//! answer's baseline (plain least squares on the first 70 %, started from the
//! generating `.tir`). Prints one table row per figure.
//!
//! Run: `cargo test --release --test suite devset_fit:: -- --nocapture` (21 fits,
//! two at a time). Skips with a message when `../shared` is absent.

use crate::devset;

use devset::{Answer, Figure};
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

/// Issue #14's acceptance: pure-slip figures ≤ 1.15 × baseline, all-row
/// figures ≤ 1.5 × (Fx of cornering-only programmes excepted: the answer's
/// baseline does not fit Fx on them either, and the Fx of a free-rolling
/// cornering run is the rolling resistance, ~0 ± noise).
const PURE_MAX: f64 = 1.15;
const ALL_MAX: f64 = 1.5;

struct Outcome {
    answer: Answer,
    figures: Vec<Figure>,
    missing: usize,
    seconds: f64,
}

fn run(a: &Answer, dir: &Path) -> Outcome {
    let exe = env!("CARGO_BIN_EXE_tyrekit");
    let tir = dir.join(format!("{}.tir", a.name));
    let sim = dir.join(format!("{}_sim.csv", a.name));
    let t0 = std::time::Instant::now();
    let out = Command::new(exe)
        .arg("fit")
        .arg(&a.file)
        .args(["--holdout", "tail:0.3", "--out"])
        .arg(&tir)
        .output()
        .expect("run tyrekit fit");
    assert!(
        out.status.success(),
        "{}: tyrekit fit failed: {}",
        a.name,
        String::from_utf8_lossy(&out.stderr)
    );
    let seconds = t0.elapsed().as_secs_f64();
    let out = Command::new(exe)
        .arg("replay")
        .arg(&a.file)
        .arg("--tir")
        .arg(&tir)
        .arg("--out")
        .arg(&sim)
        .output()
        .expect("run tyrekit replay");
    assert!(
        out.status.success(),
        "{}: tyrekit replay failed: {}",
        a.name,
        String::from_utf8_lossy(&out.stderr)
    );
    let raw = devset::read_raw(&a.file);
    assert_eq!(
        raw.et.len(),
        a.rows,
        "{}: rows read vs answers.json",
        a.name
    );
    let (figures, missing) = devset::figures(a, &raw, &devset::read_sim(&sim));
    Outcome {
        answer: a.clone(),
        figures,
        missing,
        seconds,
    }
}

/// Every recording fitted and replayed once per test process (both tests
/// share it), two processes at a time.
fn outcomes() -> Option<&'static Vec<Outcome>> {
    static CELL: OnceLock<Option<Vec<Outcome>>> = OnceLock::new();
    CELL.get_or_init(|| {
        let v = devset::run_all("devset_fit", |a, work, _dir| run(a, work))?;
        print_table(&v);
        Some(v)
    })
    .as_ref()
}

fn exempt(o: &Outcome, f: &Figure) -> bool {
    o.answer.programme == "lat" && f.channel == "FX"
}

fn limit(f: &Figure) -> f64 {
    if f.group == "pure" {
        PURE_MAX
    } else {
        ALL_MAX
    }
}

fn print_table(v: &[Outcome]) {
    println!(
        "{:<4} {:<6} {:<5} {:<3} {:>9} {:>9} {:>6} {:>7} {:>7}",
        "rec", "prog", "group", "ch", "ours %", "base %", "ratio", "rows", "answer"
    );
    for o in v {
        for f in &o.figures {
            let mark = if exempt(o, f) {
                "  (exempt)"
            } else if f.ratio() > limit(f) {
                "  > limit"
            } else {
                ""
            };
            println!(
                "{:<4} {:<6} {:<5} {:<3} {:>9.3} {:>9.3} {:>6.2} {:>7} {:>7}{mark}",
                o.answer.name,
                o.answer.programme,
                f.group,
                f.channel,
                100.0 * f.ours,
                100.0 * f.baseline,
                f.ratio(),
                f.rows,
                f.answer_rows
            );
        }
        if o.missing > 0 {
            println!(
                "{}: {} evaluated rows had no replayed value",
                o.answer.name, o.missing
            );
        }
    }
    for g in ["pure", "all"] {
        let mut r: Vec<f64> = v
            .iter()
            .flat_map(|o| o.figures.iter().filter(|f| !exempt(o, f)))
            .filter(|f| f.group == g)
            .map(Figure::ratio)
            .collect();
        r.sort_by(|a, b| a.total_cmp(b));
        let over = v
            .iter()
            .flat_map(|o| o.figures.iter().filter(|f| !exempt(o, f)))
            .filter(|f| f.group == g && f.ratio() > limit(f))
            .count();
        println!(
            "{g}: {} figures, median ratio {:.2}, max {:.2}, {over} over {:.2}×",
            r.len(),
            r.get(r.len() / 2).copied().unwrap_or(f64::NAN),
            r.last().copied().unwrap_or(f64::NAN),
            if g == "pure" { PURE_MAX } else { ALL_MAX }
        );
    }
    let secs: Vec<f64> = v.iter().map(|o| o.seconds).collect();
    println!(
        "fit wall time per recording: max {:.1} s, total {:.0} s",
        secs.iter().cloned().fold(0.0, f64::max),
        secs.iter().sum::<f64>()
    );
}

/// Median ratio to the answer's baseline per group: the level the fit has
/// reached must not get worse (a regression guard while the issue's figures
/// were not all met; the strict test below is the goal). Complete run of
/// 2026-11-27 16:42 UTC: pure median 1.00 (none of 60 over 1.15×, worst
/// 1.07), all rows 1.02 (none of 60 over 1.5×; 01:00 UTC: 1.01 with 3
/// over; 26 Nov: 1.02 and 1.08 with 5 and 10 over; 25 Nov: 1.04 and
/// 1.12); the bounds leave room
/// for another machine's rounding in the multi-start picks, not for a lost
/// stage.
const MEDIAN_MAX: [(&str, f64); 2] = [("pure", 1.05), ("all", 1.10)];

/// No single figure far off: the 26 Nov runs' worst was 3.56× (r12 all-row
/// Fx: the combined weight's slip-angle offset RHX1, fitted at one slip
/// angle, extrapolated to a held-out angle); with RHX1 held where the
/// drive/brake runs cover one sign of α the worst was 2.61× (27 Nov: r18
/// all-row Fx, the FSAE tyre whose Gxα shape differs from the start file's),
/// 1.40× with the neutral shape.
/// A lost geometry once gave 19.6× (r03: the built-in radius kept, κ ≈ 0.5
/// in the velocity-input replay) with the medians still inside their bounds.
const ANY_MAX: f64 = 3.0;

#[test]
fn devset_fit_does_not_get_worse() {
    let Some(v) = outcomes() else { return };
    for (g, max) in MEDIAN_MAX {
        let mut r: Vec<f64> = v
            .iter()
            .flat_map(|o| o.figures.iter().filter(|f| !exempt(o, f)))
            .filter(|f| f.group == g)
            .map(Figure::ratio)
            .collect();
        r.sort_by(|a, b| a.total_cmp(b));
        let med = r[r.len() / 2];
        assert!(med <= max, "{g}: median ratio {med:.2} > {max:.2}");
    }
    for o in v {
        for f in o.figures.iter().filter(|f| !exempt(o, f)) {
            assert!(
                f.ratio() <= ANY_MAX,
                "{} {} {}: {:.2}× the answer's baseline (> {ANY_MAX})",
                o.answer.name,
                f.group,
                f.channel,
                f.ratio()
            );
        }
    }
}

/// The row groups found from the signals agree with the answer file's row
/// counts (within 0.5 % + 10 rows: the sweep edges are found to a few rows),
/// and every evaluated row was replayed.
#[test]
fn devset_rows_match_the_answer_file() {
    let Some(v) = outcomes() else { return };
    for o in v {
        assert_eq!(
            o.missing, 0,
            "{}: rows without a replayed value",
            o.answer.name
        );
        for f in &o.figures {
            let tol = 10.0 + 0.005 * f.answer_rows as f64;
            assert!(
                (f.rows as f64 - f.answer_rows as f64).abs() <= tol,
                "{} {} {}: {} rows, answers.json {}",
                o.answer.name,
                f.group,
                f.channel,
                f.rows,
                f.answer_rows
            );
        }
    }
}

/// Issue #14's acceptance figures on all 21 recordings. Met since the
/// combined stage holds Gxα's unidentified shape at the neutral Cxα = 1,
/// Exα = 0 and fits its load trend REX2 (run of 2026-11-27 16:42 UTC: pure
/// worst 1.07×, all rows worst 1.40×, r18 Fx; before, r04, r14, r18 all-row
/// Fx 2.03–2.61× with the built-in car tyre's shape).
#[test]
fn devset_fit_meets_the_issue_figures() {
    let Some(v) = outcomes() else { return };
    let mut fails = Vec::new();
    for o in v {
        for f in o.figures.iter().filter(|f| !exempt(o, f)) {
            if !(f.ratio() <= limit(f)) {
                fails.push(format!(
                    "{} {} {} {:.2}×",
                    o.answer.name,
                    f.group,
                    f.channel,
                    f.ratio()
                ));
            }
        }
    }
    assert!(fails.is_empty(), "over the limit: {}", fails.join(", "));
}
