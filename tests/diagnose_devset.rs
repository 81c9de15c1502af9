//! The diagnosis measured on the independent dev set
//! (`../shared/data/diagnose-dev`, issue #15 acceptance), as a user runs it:
//! `tyrekit diagnose REC --report DIR` (no `--tir`), then
//! `tyrekit replay REC --tir DIR/baseline.tir --out sim.csv` and the same
//! for `DIR/extended.tir`, no other flags. Per recording: the verdict
//! against `answers.json`'s effect, and for a right name the share of the
//! gap recovered — (NRMSE baseline.tir − NRMSE extended.tir) / (answer
//! baseline − answer truth) on the channel with the largest pure-slip
//! `baseline − truth`, its pure-slip rows of the last 30 % (the row groups
//! of the shared harness `common/devset.rs`, found from the signals alone).
//!
//! Beside it, the same two files replayed through the library with the
//! recorded slips prescribed (`ReplayOptions::wheel_speed` off, the file's
//! transient model): `replay` takes κ from the wheel speed and the tyre's
//! Re(Fz) as the FMU does, so a baseline whose Re(Fz) is not the rig's
//! replays worse there than the diagnosis scored it.
//!
//! The table's `reach%` column estimates what is recoverable at all: the
//! answer's truth carries no sensor noise, offsets or run-to-run scatter,
//! so even a model with the missing physics stays above it — by about as
//! much as the baseline stays above the truth on the three controls, where
//! nothing is missing ([`reach`]). A baseline that already comes near that
//! level leaves little of the answer's gap to recover.
//!
//! Run: `cargo test --release --test diagnose_devset -- --nocapture` (21
//! diagnoses, two at a time); the issue's figures:
//! `-- --ignored --nocapture`. Skips with a message without `../shared`.

#[path = "common/mod.rs"]
mod common;
#[path = "common/devset.rs"]
mod devset;

use devset::Answer;
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;
use tyrekit::mf::Tyre;
use tyrekit::residual::{write_csv, ReplayOptions};
use tyrekit::transient::TransientKind;

/// Issue #15's acceptance: effects named first, controls `none`, median gap.
const NAMED_MIN: usize = 17;
const CONTROLS_MIN: usize = 3;
const GAP_MEDIAN_MIN: f64 = 0.5;
/// The level measured on 28 Nov 2026 (README's dev-set table): 17 of 18
/// named (issue #15's text: 5; 16 before each channel's BIC charged only
/// the parameters acting on it), 3 of 3 controls `none` (issue: 2). A
/// regression guard, not the goal.
const NAMED_BEFORE: usize = 17;
const CONTROLS_BEFORE: usize = 3;
/// Effects named first on the recordings cut after 85 % of their rows
/// (measured 28 Nov 2026: 15 of 18), a regression guard.
const SHORTENED_NAMED_BEFORE: usize = 15;
/// The median gap recovered over the named, measured 36 % on 28 Nov 2026
/// after the re-estimation (30 % before it), with 3 points of margin: the
/// fits are deterministic on one machine, but another CPU or thread count
/// moves single gaps by a point or two.
const GAP_MEDIAN_BEFORE: f64 = 0.33;
/// Lowest gap recovered by any right name: `extended.tir` must not make
/// the gap channel worse than `baseline.tir` does (measured 28 Nov 2026:
/// lowest 1.1 %, r02; −15 % on r07 before the rolling-radius finding had
/// the MF fitted again beneath it), with the same margin for another CPU.
const GAP_MIN_BEFORE: f64 = -0.05;

/// Most that `baseline.tir`, replayed as a user replays it, may stand above
/// the answer's baseline in any pure-slip channel. Both are the MF 6.1
/// fitted to the recording — the answer's by plain least squares on the
/// pure-slip rows of the first 70 %, started from the generating file;
/// ours from the built-in tyre on every row, pressures pooled, with its own
/// radii — so ours may lose a little where the effect lives in that channel,
/// but not a tenth: highest 1.01 since the joint Fy polish of 1 Dec 2026
/// (`fit::mf_fit::gate`); before it r04's Fy stood at 1.16 and r18's at
/// 1.07 (pure Fy and the combined weights each at their best given the
/// other, not jointly), and before the geometry fix of the same day r07's
/// Fx at 2.6× (a rolling radius the thinned geometry fit had got wrong).
const BASELINE_OVER_ANSWER_MAX: f64 = 1.10;

struct Outcome {
    name: String,
    effect: String,
    verdict: String,
    /// Gap channel ("FY"), recovered share (NaN when not computable).
    channel: String,
    recovered: f64,
    /// NRMSE of baseline.tir and extended.tir on the gap rows.
    nrmse: (f64, f64),
    /// The answer's baseline and truth on the gap rows.
    answer: (f64, f64),
    /// NRMSE of both files and the recovered share with slips prescribed.
    slips: (f64, f64, f64),
    /// Per pure-slip channel: baseline.tir's NRMSE over the answer's truth
    /// (read on the controls: how near the truth a baseline gets where
    /// nothing is missing).
    to_truth: Vec<(String, f64)>,
    /// Per pure-slip channel: baseline.tir's NRMSE over the answer's
    /// least-squares baseline ([`BASELINE_OVER_ANSWER_MAX`]).
    to_answer: Vec<(String, f64)>,
    seconds: f64,
}

/// A recording's answer: its effect and, per pure-slip channel, (channel,
/// answer baseline, answer truth).
fn answer_of(dir: &Path, name: &str) -> (String, Vec<(String, f64, f64)>) {
    let text = std::fs::read_to_string(dir.join("answers.json")).expect("answers.json");
    let v: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let a = &v["recordings"][name];
    let effect = a["effect"].as_str().expect("effect").to_string();
    let pure = a["nrmse_last30"]["pure"]
        .as_object()
        .expect("pure group")
        .iter()
        .map(|(c, f)| {
            (
                c.clone(),
                f["baseline"].as_f64().expect("baseline"),
                f["truth"].as_f64().expect("truth"),
            )
        })
        .collect();
    (effect, pure)
}

/// The gap channel of pure-slip answers: (channel, answer baseline, answer
/// truth) with the largest baseline − truth.
fn gap_channel(pure: &[(String, f64, f64)]) -> (String, f64, f64) {
    pure.iter()
        .max_by(|x, y| (x.1 - x.2).total_cmp(&(y.1 - y.2)))
        .cloned()
        .expect("a pure-slip channel")
}

/// The share of the gap an extension can recover at best if it brings the
/// gap channel as near the truth as the baseline comes on the controls
/// (median over them of baseline.tir NRMSE / truth in that channel): the
/// truth has no sensor noise, offsets or run-to-run scatter, so no fitted
/// model reaches it, and a baseline already near that level leaves little
/// to recover. An estimate, not a bound (scatter differs by recording).
fn reach(o: &Outcome, v: &[Outcome]) -> f64 {
    let r: Vec<f64> = v
        .iter()
        .filter(|c| c.effect == "none")
        .filter_map(|c| c.to_truth.iter().find(|(ch, _)| *ch == o.channel))
        .map(|(_, x)| *x)
        .collect();
    let floor = o.answer.1 * median(r);
    (o.nrmse.0 - floor) / (o.answer.0 - o.answer.1)
}

fn replay(exe: &str, rec: &Path, tir: &Path, out: &Path) {
    let o = Command::new(exe)
        .arg("replay")
        .arg(rec)
        .arg("--tir")
        .arg(tir)
        .arg("--out")
        .arg(out)
        .output()
        .expect("run tyrekit replay");
    assert!(
        o.status.success(),
        "tyrekit replay {} failed: {}",
        tir.display(),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// `tyrekit diagnose REC --report DIR` as a user runs it; the verdict.
fn diagnose_cli(name: &str, rec: &Path, report: &Path) -> String {
    verdict_of(&diagnose_json(name, rec, report))
}

/// The verdict of a `diagnosis.json`.
fn verdict_of(j: &serde_json::Value) -> String {
    j["verdict"].as_str().expect("verdict").to_string()
}

/// `tyrekit diagnose REC --report DIR` as a user runs it; its `diagnosis.json`.
fn diagnose_json(name: &str, rec: &Path, report: &Path) -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .arg("diagnose")
        .arg(rec)
        .arg("--report")
        .arg(report)
        .output()
        .expect("run tyrekit diagnose");
    assert!(
        o.status.success(),
        "{name}: tyrekit diagnose failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_str(
        &std::fs::read_to_string(report.join("diagnosis.json")).expect("diagnosis.json"),
    )
    .expect("diagnosis.json is JSON")
}

/// NRMSE of a replayed `sim.csv` on `channel`'s pure-slip rows of the last 30 %.
fn pure_nrmse(a: &Answer, raw: &devset::Raw, sim: &Path, channel: &str) -> f64 {
    let (figs, _) = devset::figures(a, raw, &devset::read_sim(sim));
    figs.iter()
        .find(|x| x.group == "pure" && x.channel == channel)
        .map_or(f64::NAN, |x| x.ours)
}

fn run(a: &Answer, dir: &Path, data: &Path) -> Outcome {
    let exe = env!("CARGO_BIN_EXE_tyrekit");
    let report = dir.join(&a.name);
    let t0 = std::time::Instant::now();
    let verdict = diagnose_cli(&a.name, &a.file, &report);
    let seconds = t0.elapsed().as_secs_f64();
    let (effect, pure) = answer_of(data, &a.name);
    let (channel, ab, at) = gap_channel(&pure);
    let raw = devset::read_raw(&a.file);
    let gap_nrmse = |sim: &Path| pure_nrmse(a, &raw, sim, &channel);
    let rec = tyrekit::data::Recording::from_file(&a.file).expect("recording");
    let mut nr = [f64::NAN; 2];
    let mut ns = [f64::NAN; 2];
    for (k, f) in ["baseline", "extended"].iter().enumerate() {
        let tir = report.join(format!("{f}.tir"));
        let sim = report.join(format!("{f}_sim.csv"));
        replay(exe, &a.file, &tir, &sim);
        nr[k] = gap_nrmse(&sim);
        let tyre = Tyre::from_file(&tir).expect("tyre file");
        let opts = ReplayOptions {
            kind: TransientKind::resolve(TransientKind::FROM_FILE, tyre.params()).expect("kind"),
            ..Default::default()
        };
        let rp = tyrekit::residual::replay(&rec, &tyre, &opts).expect("replay");
        let sim = report.join(format!("{f}_slips.csv"));
        write_csv(&rec, &rp, std::fs::File::create(&sim).expect("csv")).expect("write");
        ns[k] = gap_nrmse(&sim);
    }
    let (base_figs, _) =
        devset::figures(a, &raw, &devset::read_sim(&report.join("baseline_sim.csv")));
    let to_truth = pure
        .iter()
        .filter_map(|(c, _, t)| {
            base_figs
                .iter()
                .find(|x| x.group == "pure" && x.channel == *c)
                .map(|x| (c.clone(), x.ours / t))
        })
        .collect();
    let to_answer = base_figs
        .iter()
        .filter(|x| x.group == "pure")
        .map(|x| (x.channel.clone(), x.ratio()))
        .collect();
    Outcome {
        name: a.name.clone(),
        effect,
        verdict,
        to_truth,
        to_answer,
        channel,
        recovered: (nr[0] - nr[1]) / (ab - at),
        nrmse: (nr[0], nr[1]),
        answer: (ab, at),
        slips: (ns[0], ns[1], (ns[0] - ns[1]) / (ab - at)),
        seconds,
    }
}

fn outcomes() -> Option<&'static Vec<Outcome>> {
    static CELL: OnceLock<Option<Vec<Outcome>>> = OnceLock::new();
    CELL.get_or_init(|| {
        let v = devset::run_all("diagnose_devset", run)?;
        print_table(&v);
        Some(v)
    })
    .as_ref()
}

/// Median of the finite values (NaN when there are none).
fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[m],
        _ => 0.5 * (v[m - 1] + v[m]),
    }
}

/// (named right, effects, controls none, controls, median recovered over the named).
fn summary(v: &[Outcome]) -> (usize, usize, usize, usize, f64) {
    let effects: Vec<&Outcome> = v.iter().filter(|o| o.effect != "none").collect();
    let controls: Vec<&Outcome> = v.iter().filter(|o| o.effect == "none").collect();
    let named: Vec<&&Outcome> = effects.iter().filter(|o| o.verdict == o.effect).collect();
    let median = median(named.iter().map(|o| o.recovered).collect());
    (
        named.len(),
        effects.len(),
        controls.iter().filter(|o| o.verdict == "none").count(),
        controls.len(),
        median,
    )
}

fn print_table(v: &[Outcome]) {
    println!(
        "{:<4} {:<17} {:<17} {:<3} {:>9} {:>9} {:>9} {:>9} {:>8} {:>7} | {:>9} {:>9} {:>8} {:>4} {:>9}",
        "rec",
        "effect",
        "verdict",
        "ch",
        "base.tir",
        "ext.tir",
        "ans.base",
        "ans.trth",
        "gap %",
        "reach%",
        "base.slp",
        "ext.slp",
        "gap.slp%",
        "s",
        "worst base/ans"
    );
    for o in v {
        let worst = o
            .to_answer
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(String::new(), |(c, r)| format!("{c} {r:.2}"));
        println!(
            "{:<4} {:<17} {:<17} {:<3} {:>9.5} {:>9.5} {:>9.5} {:>9.5} {:>8.1} {:>7.0} | {:>9.5} {:>9.5} {:>8.1} {:>4.0} {:>9}{}",
            o.name,
            o.effect,
            o.verdict,
            o.channel,
            o.nrmse.0,
            o.nrmse.1,
            o.answer.0,
            o.answer.1,
            100.0 * o.recovered,
            100.0 * reach(o, v),
            o.slips.0,
            o.slips.1,
            100.0 * o.slips.2,
            o.seconds,
            worst,
            if o.verdict == o.effect { "  ok" } else { "" }
        );
    }
    let (n, ne, c, nc, m) = summary(v);
    let ms = median(
        v.iter()
            .filter(|o| o.effect != "none" && o.verdict == o.effect)
            .map(|o| o.slips.2)
            .collect(),
    );
    println!(
        "named first {n}/{ne}, controls none {c}/{nc}; median gap recovered over the named {:.0} % (replay as the FMU: kappa from wheel speed), {:.0} % with slips prescribed",
        100.0 * m,
        100.0 * ms
    );
    let rs: Vec<f64> = v
        .iter()
        .filter(|o| o.effect != "none")
        .map(|o| reach(o, v))
        .filter(|r| r.is_finite())
        .collect();
    println!(
        "reach% (the gap an extension recovers if it comes as near the truth as the baseline does on the controls): median {:.0} % over the {} effects, {} of them >= 50 %",
        100.0 * median(rs.clone()),
        rs.len(),
        rs.iter().filter(|r| **r >= 0.5).count()
    );
}

/// Live: no regression from the last measured level (17/18 named, 3/3
/// controls `none`, median gap [`GAP_MEDIAN_BEFORE`], no right name's
/// gap below [`GAP_MIN_BEFORE`], no baseline channel above
/// [`BASELINE_OVER_ANSWER_MAX`] × the answer's). A partial run (`TYREKIT_DEVSET_ONLY`) checks only
/// the gap floor and that every control in it stays `none`: the counts cover the
/// whole set.
#[test]
fn devset_diagnosis_does_not_regress() {
    let Some(v) = outcomes() else { return };
    let (n, ne, c, nc, _) = summary(v);
    for o in v
        .iter()
        .filter(|o| o.effect != "none" && o.verdict == o.effect)
    {
        assert!(
            o.recovered >= GAP_MIN_BEFORE,
            "{}: extended.tir makes {} worse than baseline.tir (gap recovered {:.1} %)",
            o.name,
            o.channel,
            100.0 * o.recovered
        );
    }
    for o in v {
        for (ch, r) in &o.to_answer {
            assert!(
                *r <= BASELINE_OVER_ANSWER_MAX,
                "{}: baseline.tir replays pure {ch} at {r:.2}× the answer's least-squares baseline (at most {BASELINE_OVER_ANSWER_MAX})",
                o.name
            );
        }
    }
    if ne + nc < 21 {
        eprintln!(
            "NOTE partial run ({} recordings): the named-count guard needs all 21",
            ne + nc
        );
        assert_eq!(c, nc, "a control was given a physical name");
        return;
    }
    assert!(n >= NAMED_BEFORE, "named first {n}, before {NAMED_BEFORE}");
    let m = summary(v).4;
    assert!(
        m >= GAP_MEDIAN_BEFORE,
        "median gap recovered {m:.3}, before {GAP_MEDIAN_BEFORE}"
    );
    assert!(
        c >= CONTROLS_BEFORE,
        "controls none {c}, before {CONTROLS_BEFORE}"
    );
}

/// The issue's acceptance figures.
#[test]
#[ignore = "issue #15's median gap >= 50 % is not met yet (38 %; 17/18 named and 3/3 controls are): see the README's dev-set table"]
fn devset_diagnosis_meets_the_issue_figures() {
    let Some(v) = outcomes() else { return };
    let (n, _, c, _, m) = summary(v);
    assert!(n >= NAMED_MIN, "named first {n} < {NAMED_MIN}");
    assert!(c >= CONTROLS_MIN, "controls none {c} < {CONTROLS_MIN}");
    assert!(m >= GAP_MEDIAN_MIN, "median gap {m:.2} < {GAP_MEDIAN_MIN}");
}

/// Right names on the recordings cut at the answer's split (measured
/// 4 Dec 2026: 10 of 18; the whole recordings' guard is [`NAMED_BEFORE`]).
const FIT_ROWS_NAMED_BEFORE: usize = 10;
/// Most that the median over the 21 of baseline.tir / the answer's baseline
/// on the gap rows may stand from 1 when both are fitted on the same rows:
/// the figures below compare like with like only if it holds (measured
/// 4 Dec 2026: median 1.00, r02's rolling-radius Mz 0.73 the lowest).
const FIT_ROWS_BASELINE_MATCH: f64 = 0.05;

/// Where the acceptance's median gap stands when `baseline.tir` is fitted as
/// the answer's baseline was — on the rows before the answer's split, so
/// that neither file sees the rows it is judged on. The diagnosis of the
/// whole recording fits its baseline on every row, the last 30 % too: a
/// time-dependent or condition-level effect there is partly taken up by the
/// baseline itself (r14 thermal: 44 % of the answer's gap, r02 rolling
/// radius 94 %), and what is left for the extension to recover is that much
/// smaller ([`reach`]). Here every recording is cut at `eval_split_ET_s`,
/// diagnosed as a user would, and both files are replayed over the whole
/// recording: baseline.tir then lands on the answer's baseline
/// ([`FIT_ROWS_BASELINE_MATCH`]) and the gap recovered measures the
/// extension alone, out of sample in time.
///
/// Measured 4 Dec 2026 (the code of 3cbb5b3): right names 10 of 18 (less
/// data: speed friction and thermal fall under their evidence), median gap
/// over them 65 % (r16 thermal 62 % against 26 % from the whole recording,
/// r04 pressure 33 % against 2 %), controls 3/3 `none`; one wrong name,
/// r09 (pressure) → thermal on a 3.3 % Mz gain with a Mz BIC of −0.6 (the
/// whole recording names pressure), which is why no wrong name is not
/// asserted here (see the README). Asserted instead (since the verdicts
/// carry their evidence's grade, 4 Dec 2026): a wrong name says its
/// evidence is weak (`verdict_evidence` in `diagnosis.json`, "The evidence
/// is weak" in the words).
#[test]
#[ignore = "on demand (≈ 6 min): the gap with both files fitted on the answer's fit rows only"]
fn devset_extensions_recover_half_the_gap_fitted_where_the_answer_was() {
    use std::io::Write;
    let exe = env!("CARGO_BIN_EXE_tyrekit");
    let Some(v) = devset::run_all("diagnose_devset_fit_rows", |a, work, data| {
        let lines = devset::read_lines(&a.file);
        let et = lines[0]
            .split('\t')
            .position(|n| n == "ET")
            .expect("ET column");
        let path = work.join(format!("{}.dat", a.name));
        let mut out = std::io::BufWriter::new(std::fs::File::create(&path).expect("cut"));
        for (i, l) in lines.iter().enumerate() {
            let keep = i < 2
                || l.split('\t')
                    .nth(et)
                    .and_then(|x| x.trim().parse::<f64>().ok())
                    .is_some_and(|t| t < a.split_et);
            if keep {
                writeln!(out, "{l}").expect("write");
            }
        }
        drop(out);
        let report = work.join(&a.name);
        let j = diagnose_json(&a.name, &path, &report);
        let verdict = verdict_of(&j);
        let weak = j["verdict_evidence"]["grade"] == "weak"
            && j["explanation"]
                .as_str()
                .is_some_and(|w| w.contains("The evidence is weak"));
        let (effect, pure) = answer_of(data, &a.name);
        let (channel, ab, at) = gap_channel(&pure);
        let raw = devset::read_raw(&a.file);
        let mut nr = [f64::NAN; 2];
        for (k, f) in ["baseline", "extended"].iter().enumerate() {
            let sim = report.join(format!("{f}_whole.csv"));
            replay(exe, &a.file, &report.join(format!("{f}.tir")), &sim);
            nr[k] = pure_nrmse(a, &raw, &sim, &channel);
        }
        (a.name.clone(), effect, verdict, channel, nr, ab, at, weak)
    }) else {
        return;
    };
    let mut gaps = Vec::new();
    let mut ratios = Vec::new();
    for (name, effect, verdict, ch, nr, ab, at, weak) in &v {
        let gap = (nr[0] - nr[1]) / (ab - at);
        ratios.push(nr[0] / ab);
        let right = verdict == effect;
        if right && effect != "none" {
            gaps.push(gap);
        }
        println!(
            "fit rows {name} {effect:<17} {verdict:<17} {ch} base.tir {:.5} ext.tir {:.5} ans.base {ab:.5} ans.trth {at:.5} base/ans {:.2} gap {:>6.1} %{}{}",
            nr[0],
            nr[1],
            nr[0] / ab,
            100.0 * gap,
            if right { "  ok" } else { "" },
            if *weak { "  (evidence weak)" } else { "" }
        );
    }
    let m = median(gaps.clone());
    let r = median(ratios);
    let wrong: Vec<&String> = v
        .iter()
        .filter(|o| o.2 != "none" && o.2 != o.1)
        .map(|o| &o.0)
        .collect();
    let wrong_not_weak: Vec<&String> = v
        .iter()
        .filter(|o| o.2 != "none" && o.2 != o.1 && !o.7)
        .map(|o| &o.0)
        .collect();
    println!(
        "fit rows: right names {} (controls none: {} of 3), wrong {wrong:?}; median gap over the right names {:.0} %, median baseline.tir / answer baseline {r:.3}",
        gaps.len(),
        v.iter().filter(|o| o.1 == "none" && o.2 == "none").count(),
        100.0 * m
    );
    assert!(
        wrong_not_weak.is_empty(),
        "a wrong name without the words that its evidence is weak: {wrong_not_weak:?}"
    );
    if v.len() < 21 {
        eprintln!("NOTE partial run: only the per-recording lines are meaningful");
        return;
    }
    assert!(
        (r - 1.0).abs() <= FIT_ROWS_BASELINE_MATCH,
        "baseline.tir fitted on the answer's rows replays at {r:.3} × the answer's baseline (median): not a like-for-like comparison"
    );
    assert!(
        gaps.len() >= FIT_ROWS_NAMED_BEFORE,
        "right names on the fit rows {}, before {FIT_ROWS_NAMED_BEFORE}",
        gaps.len()
    );
    assert!(
        m >= GAP_MEDIAN_MIN,
        "median gap over the right names {m:.2} < {GAP_MEDIAN_MIN}"
    );
}

/// Every dev-set recording — or, with a `sample` and without
/// `TYREKIT_DEVSET_VARIATIONS=all`, only the sample's — rewritten by
/// `rewrite` (it gets the recording's name and its lines — names, units,
/// data rows — and returns the lines to write), diagnosed as a user would
/// (`tyrekit diagnose REC --report DIR`): (recording, answer's effect,
/// verdict). None without the shared dev set.
fn variant_verdicts(
    test: &str,
    sample: Option<&Sample>,
    rewrite: fn(&str, Vec<String>) -> Vec<String>,
) -> Option<Vec<(String, String, String)>> {
    use std::io::Write;
    let all = full_variations();
    if let (Some(s), false) = (sample, all) {
        eprintln!(
            "NOTE {test}: CI's sample {:?} (TYREKIT_DEVSET_VARIATIONS=all runs all 21)",
            s.names
        );
    }
    devset::run_all(test, |a, work, data| {
        if sample.is_some_and(|s| !all && !s.names.contains(&a.name.as_str())) {
            return None;
        }
        let path = work.join(format!("{}.dat", a.name));
        let lines = rewrite(&a.name, devset::read_lines(&a.file));
        // A rewrite that keeps no data row: the recording has nothing of
        // the variation (a drive/brake cut of a cornering-only programme).
        if lines.len() <= 2 {
            return None;
        }
        let mut out = std::io::BufWriter::new(std::fs::File::create(&path).expect("variant"));
        for l in lines {
            writeln!(out, "{l}").expect("write");
        }
        drop(out);
        let verdict = diagnose_cli(&a.name, &path, &work.join(&a.name));
        Some((a.name.clone(), answer_of(data, &a.name).0, verdict))
    })
    .map(|v| v.into_iter().flatten().collect())
}

/// The lines with only the data rows `keep(row, rows)` keeps (names and
/// units as they are).
fn keep_rows(lines: Vec<String>, keep: impl Fn(usize, usize) -> bool) -> Vec<String> {
    let rows = lines.len().saturating_sub(2);
    lines
        .into_iter()
        .enumerate()
        .filter(|(i, _)| *i < 2 || keep(i - 2, rows))
        .map(|(_, l)| l)
        .collect()
}

/// The verdicts do not hang on the sample rate: every recording thinned to
/// 50 Hz (every second row, as a rig logging at half the rate would write
/// it) and diagnosed as a user would (`tyrekit diagnose REC --report DIR`).
/// The evidence counts recorded seconds, not samples
/// (`diagnose::candidate::DECORRELATION_TIME`), so the same effects must be
/// named and the controls stay `none`: the level of the 100 Hz guard
/// (measured 28 Nov 2026: all 21 verdicts as at 100 Hz, 161 s).
/// On demand since 29 Nov 2026 (it passed unchanged in every run since 28
/// Nov; the drive/brake variation took its place in CI's hour). Run alone on
/// 1 Dec 2026 (4cb311a): passed, 566 s — too long to put back into CI's hour
/// even with the ≈ 10 minutes the merged test binaries saved.
#[test]
#[ignore = "on demand (≈ 570 s alone on 1 Dec's VM): the 50 Hz variation; CI runs the drive/brake variation in its place"]
fn devset_verdicts_hold_at_half_the_sample_rate() {
    let Some(v) = variant_verdicts("diagnose_devset_50hz", None, |_, l| {
        keep_rows(l, |i, _| i % 2 == 0)
    }) else {
        return;
    };
    no_wrong_name(&v, "at 50 Hz", NAMED_BEFORE, None);
}

/// A shorter programme names no wrong effect: every recording cut after
/// 85 % of its rows (a test stopped early; the hidden set's programmes
/// differ) and diagnosed as a user would. With less data an effect may
/// fall under the evidence it needs — `none` is an honest answer — but a
/// verdict must be the answer's effect or `none`, and the controls stay
/// `none`. Measured 28 Nov 2026 (the first 85 %): 15 of 18 named, r09 and
/// r20 `none` (a pressure drift that the cut leaves confounded with time),
/// controls 3/3; before the overshadow rule
/// (`diagnose::candidate::OVERSHADOW`) r14 (thermal) was named
/// `load_sensitivity` on a 3.7 % Mz gain where the thermal candidate, which
/// spoils that recording's Fx, removed 25 %. On demand since 30 Nov 2026
/// (it passed unchanged in every run since 28 Nov): a clean clone's CI run
/// took 63 minutes on that day's machine, over the project's 60-minute aim,
/// and of the four live variations this one perturbs the recordings least —
/// the dev set's own `short` programme already holds a shorter test.
#[test]
#[ignore = "on demand: every recording cut after 85 % of its rows (15 of 18 named since 28 Nov); off CI since 30 Nov to keep it inside the hour"]
fn devset_shortened_programmes_name_no_wrong_effect() {
    let Some(v) = variant_verdicts("diagnose_devset_cut", None, |_, l| {
        keep_rows(l, |i, rows| 100 * i < 85 * rows)
    }) else {
        return;
    };
    no_wrong_name(&v, "cut after 85 %", SHORTENED_NAMED_BEFORE, None);
}

/// A drive/brake run names no wrong effect: every recording cut to its
/// pure and combined drive/brake blocks (the rows within 3 s of a slip ratio
/// above 3 %; the cornering sweeps and the warm-up gone, the recorded
/// times kept), as a TTC drive/brake run file comes without cornering
/// sweeps; the three cornering-only programmes have no such rows and are
/// left out. The baseline reads Fy0 from the rows near free rolling and
/// leaves Mz to the start tyre (`fit::mf_fit::FREE_ROLLING_KAPPA`; Mz is
/// then not diagnosed), a gain on a channel the baseline misfits is no
/// evidence (`ChannelScore::baseline_misfit`), and the rolling radius is
/// read where the sweeps' Fx crosses zero (`diagnose::slip_channel`).
/// Measured 29 Nov 2026: 9 of 15 named (r02, r05, r07, r10, r12, r13, r17,
/// r18, r19), controls `none`, none wrong (166 s), with a baseline that
/// fitted Fy at 7–17× the noise floor (σ_Fy 48 %, Fy0 the start tyre's);
/// with Fy0 fitted (σ_Fy 2.6–4.4 %) again 9 — r11 named, r12 `none` (its
/// load law gains 7 % in Fx and loses 8 % in Fy) —, none wrong. Before the
/// misfit and radius rules r04 (pressure) and r18 (relaxation) were named
/// `lugre` on Fy gains the baseline's misfit offered, and r02, r07, r10
/// (rolling radius) `none`, `none` and `speed_friction`.
#[test]
fn devset_drive_brake_runs_name_no_wrong_effect() {
    let Some(v) = variant_verdicts(
        "diagnose_devset_drive_brake",
        Some(&DRIVE_BRAKE_SAMPLE),
        drive_brake_only,
    ) else {
        return;
    };
    no_wrong_name(
        &v,
        "drive/brake only",
        DRIVE_BRAKE_NAMED_BEFORE,
        Some(&DRIVE_BRAKE_SAMPLE),
    );
}

/// A recording shared without its wheel speed and slip channels (N, RE, SR,
/// SL taken out): the loader keeps κ = 0 where the tyre rolls freely (the
/// whole of a cornering-only programme, the cornering blocks of the
/// others) and drops the drive/brake rows whose slip nothing tells. Every
/// recording is still diagnosed — before 30 Nov 2026 a programme that also
/// drives and brakes was refused ("no usable data in any stage") — and
/// none gets a wrong name. Fewer are named than with the wheel speed
/// (measured 30 Nov 2026: 7 of 18, 148 s; none of the rolling-radius,
/// speed-friction and thermal effects, whose evidence is in the drive/brake
/// blocks or the history across them): a `none` on a recording with
/// dropped rows says that a history across the gaps may hide an effect
/// (`diagnose::factor::missing_time`).
#[test]
fn devset_without_wheel_speed_is_diagnosed_on_what_rolls_freely() {
    let Some(v) = variant_verdicts(
        "diagnose_devset_no_wheel_speed",
        Some(&NO_WHEEL_SPEED_SAMPLE),
        without_wheel_speed,
    ) else {
        return;
    };
    no_wrong_name(
        &v,
        "without wheel speed",
        NO_WHEEL_SPEED_NAMED_BEFORE,
        Some(&NO_WHEEL_SPEED_SAMPLE),
    );
}

/// Effects named first without wheel speed (30 Nov 2026).
const NO_WHEEL_SPEED_NAMED_BEFORE: usize = 7;

/// CI's sample without wheel speed: the three controls (one per programme
/// kind: cornering-only, speed, full) and the effects whose evidence is in
/// the free-rolling rows on three tyre files — r01 relaxation (cornering
/// only), r09 pressure and r12 load sensitivity (full programmes, whose
/// drive/brake rows are dropped: the refusal this test was written for).
const NO_WHEEL_SPEED_SAMPLE: Sample = Sample {
    names: &["r01", "r06", "r08", "r09", "r12", "r15"],
    named: &["r01", "r09", "r12"],
};

/// A data logger's drop-outs: every 20th row missing (a single missing row
/// is a longer time step, not a gap) and three bursts of 30 rows (0.3 s)
/// at a quarter, half and three quarters of the recording — three gaps at
/// which the replay restarts (`diagnose::replay`). The rows' times stay
/// as recorded.
fn drop_outs(_: &str, lines: Vec<String>) -> Vec<String> {
    let rows = lines.len().saturating_sub(2);
    let bursts = [rows / 4, rows / 2, 3 * rows / 4];
    keep_rows(lines, |i, _| {
        i % 20 != 7 && !bursts.iter().any(|&b| (b..b + 30).contains(&i))
    })
}

/// A recording whose evidence is a history across the whole run (the
/// tread temperature) and a control: the drop-out variation CI runs (one
/// round of the two diagnoses run at a time; the other thermal recordings,
/// r14 and r21, in the on-demand run of all 21).
const HISTORY: [&str; 2] = ["r08", "r16"];

/// A history survives logger drop-outs: a thermal recording and a control
/// with [`drop_outs`], diagnosed as a user would. The effect is named as
/// on the recording itself and the control stays `none`. Found 1
/// Dec 2026: every gap reset the replay's tread temperature to ambient, and
/// r16 with drop-outs got `none` (its thermal candidate gained 0.3 % of
/// the held-out error instead of 12 %); the temperature now carries over a
/// gap, cooled by its own time constant
/// (`transient::TransientModel::reset_after_gap`). Relaxation and LuGre
/// states restart at a gap, as before. All 21 recordings: the on-demand
/// test below.
#[test]
fn devset_history_verdicts_survive_logger_drop_outs() {
    let Some(v) = variant_verdicts("diagnose_devset_drop_outs", None, |name, lines| {
        if HISTORY.contains(&name) {
            drop_outs(name, lines)
        } else {
            lines.into_iter().take(2).collect()
        }
    }) else {
        return;
    };
    for (name, effect, verdict) in &v {
        println!("drop-outs {name}  {effect:<18} {verdict}");
    }
    assert_eq!(v.len(), HISTORY.len(), "{v:?}");
    let wrong: Vec<_> = v.iter().filter(|(_, e, x)| e != x).collect();
    assert!(wrong.is_empty(), "with logger drop-outs: {wrong:?}");
}

/// [`drop_outs`] on all 21 recordings: no wrong name, as many named as on
/// the recordings themselves. Measured 1 Dec 2026 (with the temperature
/// carried over the gaps): all 21 verdicts as on the recordings, 621 s.
#[test]
#[ignore = "on demand (621 s on 1 Dec): the drop-out variation over all 21 recordings; CI runs r16 and r08"]
fn devset_verdicts_hold_across_logger_drop_outs() {
    let Some(v) = variant_verdicts("diagnose_devset_drop_outs_all", None, drop_outs) else {
        return;
    };
    no_wrong_name(&v, "with drop-outs", NAMED_BEFORE, None);
}

/// The lines without the columns N, RE, SR and SL.
fn without_wheel_speed(_: &str, lines: Vec<String>) -> Vec<String> {
    let drop: Vec<bool> = lines[0]
        .split('\t')
        .map(|c| ["N", "RE", "SR", "SL"].contains(&c.trim()))
        .collect();
    lines
        .into_iter()
        .map(|l| {
            l.split('\t')
                .zip(&drop)
                .filter(|(_, d)| !**d)
                .map(|(x, _)| x)
                .collect::<Vec<_>>()
                .join("\t")
        })
        .collect()
}

/// Effects named first on the drive/brake variation (29 Nov 2026).
const DRIVE_BRAKE_NAMED_BEFORE: usize = 9;

/// CI's drive/brake sample: the two controls that have drive/brake blocks
/// (r06 is cornering-only), the two recordings once named `lugre` on the
/// baseline's Fy misfit (r04 pressure, r18 relaxation), and the effects the
/// drive/brake blocks carry on three tyre files and three programmes (r02,
/// r10 rolling radius; r19 speed friction).
const DRIVE_BRAKE_SAMPLE: Sample = Sample {
    names: &["r02", "r04", "r08", "r10", "r15", "r18", "r19"],
    named: &["r02", "r10", "r18", "r19"],
};

/// The lines with only the rows within 3 s (300 rows at the dev set's
/// 100 Hz) of a slip ratio |SR| > 3 %; only the header when fewer than 5 %
/// of the rows are left.
fn drive_brake_only(_: &str, lines: Vec<String>) -> Vec<String> {
    let col = lines[0]
        .split('\t')
        .position(|c| c.trim() == "SR")
        .expect("an SR column");
    let sliding: Vec<bool> = lines[2..]
        .iter()
        .map(|l| {
            l.split('\t')
                .nth(col)
                .and_then(|x| x.trim().parse::<f64>().ok())
                .is_some_and(|x| x.abs() > 0.03)
        })
        .collect();
    // Rows since the last / until the next sliding row.
    let n = sliding.len();
    let (mut before, mut after) = (vec![usize::MAX; n], vec![usize::MAX; n]);
    for i in 0..n {
        before[i] = if sliding[i] {
            0
        } else if i > 0 {
            before[i - 1].saturating_add(1)
        } else {
            usize::MAX
        };
    }
    for i in (0..n).rev() {
        after[i] = if sliding[i] {
            0
        } else if i + 1 < n {
            after[i + 1].saturating_add(1)
        } else {
            usize::MAX
        };
    }
    let keep: Vec<bool> = (0..n).map(|i| before[i].min(after[i]) <= 300).collect();
    if 20 * keep.iter().filter(|k| **k).count() < n {
        return lines.into_iter().take(2).collect();
    }
    keep_rows(lines, |i, _| keep[i])
}

/// Another rig's sensors: every recording with its force and load channels'
/// noise doubled in variance (Gaussian, of the σ the channel's own
/// first differences show, seeded per recording) and a constant zero error
/// added — FX +12.5 N, FY −20 N, MZ +0.75 N m, FZ +7.5 N (about 1 % of an
/// FSAE-size tyre's force range) —, diagnosed as a user would. The
/// hidden recordings come from other seeds: their noise and offsets are
/// other draws, and the verdict must not hang on them. The same effects are
/// named and the controls stay `none`. Measured 29 Nov 2026: all 21 verdicts
/// as on the recordings themselves, before (292 s) and after the baseline
/// estimated the sensor zeros (`diagnose::sensor_zero`; 316 s). With
/// twice these zeros and this noise together 15 of 18 are named (r03, r14
/// → `none`, weak findings under more noise), none wrong.
#[test]
fn devset_verdicts_hold_with_other_sensor_noise_and_offsets() {
    let Some(v) = variant_verdicts(
        "diagnose_devset_sensors",
        Some(&SENSOR_SAMPLE),
        other_sensors,
    ) else {
        return;
    };
    no_wrong_name(&v, "with other sensors", NAMED_BEFORE, Some(&SENSOR_SAMPLE));
}

/// Twice the sensor variation's zero errors (FX +25 N, FY −40 N, MZ
/// +1.5 N m, FZ +15 N), no added noise. Measured 29 Nov 2026: before the
/// baseline estimated the sensor zeros, r03 (load sensitivity) was named
/// `camber` and control r08 `load_sensitivity` (316 s) — the MF's
/// load-proportional shifts absorb a constant only in part and leave a
/// load-shaped residual (README, "Diagnosis", variation 5); since, all 21
/// verdicts as on the recordings (317 s). On demand (`--include-ignored`):
/// with the sensor zeros' second fit the dev-set binary's live tests take
/// about 30 % longer, and this one would put CI near its hour.
#[test]
#[ignore = "on demand (≈ 320 s): twice the sensor zero errors; passes since the baseline estimates sensor zeros (README, Diagnosis, variation 5)"]
fn devset_verdicts_hold_with_twice_the_zero_errors() {
    let Some(v) = variant_verdicts("diagnose_devset_zeros", None, |n, l| {
        sensors(n, l, 2.0, false)
    }) else {
        return;
    };
    no_wrong_name(&v, "with twice the zero errors", NAMED_BEFORE, None);
}

/// Prints a variation's verdicts and asserts that none is wrong (each is
/// the answer's effect or `none`, so every control stays `none`) and that
/// no fewer effects are named than before: over the whole set (all 21, or
/// those the rewrite leaves rows in) at least `named_before`, over a
/// [`Sample`] at least as many of the sample's recordings as were named
/// when it was last measured ([`Sample::named`]). A developer's partial run
/// (`TYREKIT_DEVSET_ONLY`) checks only the names.
fn no_wrong_name(
    v: &[(String, String, String)],
    what: &str,
    named_before: usize,
    sample: Option<&Sample>,
) {
    for (name, effect, verdict) in v {
        println!("{what} {name}  {effect:<18} {verdict}");
    }
    let wrong: Vec<_> = v.iter().filter(|(_, e, x)| x != "none" && x != e).collect();
    assert!(wrong.is_empty(), "wrong names {what}: {wrong:?}");
    let named = v.iter().filter(|(_, e, x)| e != "none" && e == x).count();
    let partial = std::env::var_os("TYREKIT_DEVSET_ONLY").is_some();
    if !partial && (sample.is_none() || full_variations()) {
        assert!(
            named >= named_before,
            "named first {what}: {named}, before {named_before}"
        );
    } else if let Some(s) = sample {
        let before = v
            .iter()
            .filter(|(n, _, _)| s.named.contains(&n.as_str()))
            .count();
        assert!(
            named >= before,
            "named first {what} over CI's sample: {named}, before {before} ({:?})",
            s.named
        );
    }
}

/// The recordings a live variation runs in CI, and those of them that the
/// variation named when last measured (2 Dec 2026, on the sample: as in the
/// last runs over all 21 — drive/brake 29 Nov, sensors 29 Nov; without wheel
/// speed r01, r09, r12 of that run's 7). The whole set runs with
/// `TYREKIT_DEVSET_VARIATIONS=all` (on demand; each variation takes 5–10
/// minutes over all 21, and three of them put CI's clean-clone run over its
/// 90 minutes on a slow machine on 2 Dec 2026). A sample is chosen by what
/// the variation can break — the controls, where a wrong name would
/// appear, and one recording per tyre file and programme with an effect the
/// variation leaves visible — never by how a recording fared.
struct Sample {
    names: &'static [&'static str],
    named: &'static [&'static str],
}

/// `TYREKIT_DEVSET_VARIATIONS=all`: every live variation over all 21.
fn full_variations() -> bool {
    std::env::var("TYREKIT_DEVSET_VARIATIONS").is_ok_and(|v| v == "all")
}

/// CI's sample of the sensor variation: the three controls (offsets that
/// a baseline cannot absorb would show there as a wrong name), the two
/// weakest findings under sensor variation (r03 load sensitivity and r14
/// thermal, `none` with twice the noise and zeros), r05 (speed friction,
/// whose evidence is Fx's level against sliding speed, where an Fx zero
/// error lands) and r10 (rolling radius, the fourth tyre file, the short
/// programme).
const SENSOR_SAMPLE: Sample = Sample {
    names: &["r03", "r05", "r06", "r08", "r10", "r14", "r15"],
    named: &["r03", "r05", "r10", "r14"],
};

/// The zero errors of a sensor variation (ISO names as the recording's
/// columns, SAE signs as recorded): FX, FY (N), MZ (N m), FZ (N).
const ZEROS: [(&str, f64); 4] = [("FX", 12.5), ("FY", -20.0), ("MZ", 0.75), ("FZ", 7.5)];

/// The rewrite of [`devset_verdicts_hold_with_other_sensor_noise_and_offsets`].
fn other_sensors(name: &str, lines: Vec<String>) -> Vec<String> {
    sensors(name, lines, 1.0, true)
}

/// The lines with `scale` × [`ZEROS`] added to the force and load channels
/// and, with `noise`, the channels' own noise doubled in variance (seeded
/// per recording).
fn sensors(name: &str, mut lines: Vec<String>, scale: f64, noise: bool) -> Vec<String> {
    use rand::{Rng, SeedableRng};
    let names: Vec<String> = lines[0].split('\t').map(str::to_string).collect();
    let seed = name.bytes().fold(20261129u64, |h, b| h * 31 + b as u64);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for (ch, zero) in ZEROS {
        let offset = scale * zero;
        let j = names.iter().position(|n| n == ch).expect("channel");
        let x: Vec<f64> = lines[2..]
            .iter()
            .map(|l| {
                l.split('\t')
                    .nth(j)
                    .expect("column")
                    .parse()
                    .expect("number")
            })
            .collect();
        // White noise of σ has first differences of σ·√2; the median
        // absolute difference over 0.6745 is their σ, robust to the sweeps.
        let mut d: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        d.sort_by(f64::total_cmp);
        let sigma = d[d.len() / 2] / 0.6745 / 2f64.sqrt();
        for (l, v) in lines[2..].iter_mut().zip(&x) {
            // Box–Muller: one standard normal from two uniforms.
            let z = if noise {
                let (u1, u2): (f64, f64) = (rng.gen_range(f64::EPSILON..1.0), rng.gen());
                (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            } else {
                0.0
            };
            let mut cells: Vec<String> = l.split('\t').map(str::to_string).collect();
            cells[j] = format!("{:.3}", v + offset + sigma * z);
            *l = cells.join("\t");
        }
    }
    lines
}
