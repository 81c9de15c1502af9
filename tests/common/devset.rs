//! devset — the independent diagnosis development set
//! (`../shared/data/diagnose-dev`, see its README) as a yardstick for the
//! fit: its answer file, its recordings read raw (SAE tyre axes, TTC text
//! layout, gzip'd), the row groups of `answers.json`'s `nrmse_definition`
//! and the NRMSE of a replayed `sim.csv` on them.
//!
//! The row groups are found from the recorded signals alone (no tyrekit
//! code): a lateral sweep is a stretch where |SA| > 0.3° whose SA reaches
//! both +2° and −2° (the programme sweeps 0 → −4 → +12 → −12 → +3 → 0°);
//! a drive/brake sweep at SA = 0 a stretch where |SR| > 0.03 whose median
//! |SA| < 1°. Stretches closer than the time the sweep needs to cross the
//! threshold band are merged, and each is widened by that time on both
//! sides (4°/s: 8 rows for 0.3°; 0.1/s: 30 rows for 0.03), so the counts
//! match the answer file's `rows` to a few rows (the test prints both).
//!
//! Must never: read tyrekit's own classification, or tune anything to one
//! recording.
#![allow(dead_code)]

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

/// One recording's entry of `answers.json`.
#[derive(Clone, Debug)]
pub struct Answer {
    pub name: String,
    pub file: PathBuf,
    pub programme: String,
    pub fz_ref: f64,
    pub split_et: f64,
    pub rows: usize,
    /// (group, channel) → (baseline NRMSE, rows).
    pub baseline: HashMap<(String, String), (f64, usize)>,
}

/// The answer file's recordings, sorted by name; `None` when absent.
pub fn answers(dir: &Path) -> Option<Vec<Answer>> {
    let text = std::fs::read_to_string(dir.join("answers.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).expect("answers.json is JSON");
    let recs = v["recordings"]
        .as_object()
        .expect("answers.json: recordings");
    let mut out: Vec<Answer> = recs
        .iter()
        .map(|(name, a)| {
            let mut baseline = HashMap::new();
            for (g, chans) in a["nrmse_last30"].as_object().expect("nrmse_last30") {
                for (c, fig) in chans.as_object().expect("group") {
                    baseline.insert(
                        (g.clone(), c.clone()),
                        (
                            fig["baseline"].as_f64().expect("baseline"),
                            fig["rows"].as_u64().expect("rows") as usize,
                        ),
                    );
                }
            }
            Answer {
                name: name.clone(),
                file: dir.join(a["file"].as_str().expect("file")),
                programme: a["programme"].as_str().expect("programme").into(),
                fz_ref: a["Fz_ref_N"].as_f64().expect("Fz_ref_N"),
                split_et: a["eval_split_ET_s"].as_f64().expect("eval_split_ET_s"),
                rows: a["rows"].as_u64().expect("rows") as usize,
                baseline,
            }
        })
        .collect();
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Some(out)
}

/// The raw channels the NRMSE needs (SAE axes, file units).
#[derive(Default, Debug)]
pub struct Raw {
    pub et: Vec<f64>,
    pub sa: Vec<f64>,
    pub sr: Vec<f64>,
    pub fz: Vec<f64>,
    pub fx: Vec<f64>,
    pub fy: Vec<f64>,
    pub mz: Vec<f64>,
}

/// The lines of a gzip'd TTC text recording (names, units, data rows).
pub fn read_lines(path: &Path) -> Vec<String> {
    let f = std::fs::File::open(path).expect("recording");
    let mut text = String::new();
    flate2::read::GzDecoder::new(f)
        .read_to_string(&mut text)
        .expect("gzip text");
    text.lines().map(str::to_string).collect()
}

/// Read a gzip'd TTC text recording (row 1 names, row 2 units).
pub fn read_raw(path: &Path) -> Raw {
    let text = read_lines(path);
    let mut lines = text.iter();
    let names: Vec<&str> = lines.next().expect("header").split_whitespace().collect();
    let col = |n: &str| names.iter().position(|x| *x == n).expect(n);
    let (et, sa, sr, fz, fx, fy, mz) = (
        col("ET"),
        col("SA"),
        col("SR"),
        col("FZ"),
        col("FX"),
        col("FY"),
        col("MZ"),
    );
    lines.next();
    let mut r = Raw::default();
    for l in lines {
        let v: Vec<f64> = l
            .split_whitespace()
            .map(|x| x.parse().expect("number"))
            .collect();
        if v.is_empty() {
            continue;
        }
        r.et.push(v[et]);
        r.sa.push(v[sa]);
        r.sr.push(v[sr]);
        r.fz.push(v[fz]);
        r.fx.push(v[fx]);
        r.fy.push(v[fy]);
        r.mz.push(v[mz]);
    }
    r
}

/// Runs of `mask`, merged across gaps shorter than `gap` rows, each widened
/// by `ext` rows on both sides.
fn runs(mask: &[bool], gap: usize, ext: usize) -> Vec<(usize, usize)> {
    let n = mask.len();
    let mut out: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < n {
        if !mask[i] {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < n && mask[j] {
            j += 1;
        }
        match out.last_mut() {
            Some(last) if i - last.1 < gap => last.1 = j,
            _ => out.push((i, j)),
        }
        i = j;
    }
    out.into_iter()
        .map(|(a, b)| (a.saturating_sub(ext), (b + ext).min(n)))
        .collect()
}

/// Per row: (in a free-rolling lateral sweep, in a drive/brake sweep at SA = 0).
pub fn classify(r: &Raw) -> (Vec<bool>, Vec<bool>) {
    let n = r.et.len();
    let mut lat = vec![false; n];
    let mut lon = vec![false; n];
    let m: Vec<bool> = r.sa.iter().map(|s| s.abs() > 0.3).collect();
    for (a, b) in runs(&m, 20, 8) {
        let seg = &r.sa[a..b];
        let hi = seg.iter().cloned().fold(f64::MIN, f64::max);
        let lo = seg.iter().cloned().fold(f64::MAX, f64::min);
        if hi > 2.0 && lo < -2.0 {
            lat[a..b].iter_mut().for_each(|x| *x = true);
        }
    }
    let m: Vec<bool> = r.sr.iter().map(|s| s.abs() > 0.03).collect();
    for (a, b) in runs(&m, 50, 30) {
        let mut sa: Vec<f64> = r.sa[a..b].to_vec();
        sa.sort_by(|x, y| x.total_cmp(y));
        if sa[sa.len() / 2].abs() < 1.0 {
            lon[a..b].iter_mut().for_each(|x| *x = true);
        }
    }
    (lat, lon)
}

/// A replayed `sim.csv` (ISO-W, SI) keyed by time in centiseconds:
/// (Fx, Fy, Mz) simulated, mapped back to SAE tyre axes (Fx = Fx_W,
/// Fy = −Fy_W, Mz = −Mz_W; newtons and newton-metres in both).
pub fn read_sim(path: &Path) -> HashMap<i64, [f64; 3]> {
    let text = std::fs::read_to_string(path).expect("sim.csv");
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |n: &str| head.iter().position(|x| *x == n).expect(n);
    let (t, fx, fy, mz) = (col("time"), col("Fx_sim"), col("Fy_sim"), col("Mz_sim"));
    let mut out = HashMap::new();
    for l in lines {
        let v: Vec<f64> = l
            .split(',')
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        out.insert((v[t] * 100.0).round() as i64, [v[fx], -v[fy], -v[mz]]);
    }
    out
}

/// One NRMSE figure: ours, the answer's baseline, rows (ours, answer's).
#[derive(Clone, Debug)]
pub struct Figure {
    pub group: String,
    pub channel: String,
    pub ours: f64,
    pub baseline: f64,
    pub rows: usize,
    pub answer_rows: usize,
}

impl Figure {
    pub fn ratio(&self) -> f64 {
        self.ours / self.baseline
    }
}

/// The NRMSE figures of `sim` against the raw recording on the answer's
/// groups; second value: evaluated rows without a simulated value.
pub fn figures(a: &Answer, raw: &Raw, sim: &HashMap<i64, [f64; 3]>) -> (Vec<Figure>, usize) {
    let (lat, lon) = classify(raw);
    let n = raw.et.len();
    let eval: Vec<usize> = (0..n)
        .filter(|&i| raw.et[i] >= a.split_et && raw.fz[i].abs() > 0.1 * a.fz_ref)
        .collect();
    let missing = eval
        .iter()
        .filter(|&&i| !sim.contains_key(&((raw.et[i] * 100.0).round() as i64)))
        .count();
    let mut out = Vec::new();
    for ((g, c), &(baseline, answer_rows)) in &a.baseline {
        let (meas, k): (&[f64], usize) = match c.as_str() {
            "FX" => (&raw.fx, 0),
            "FY" => (&raw.fy, 1),
            "MZ" => (&raw.mz, 2),
            _ => continue,
        };
        let rows: Vec<usize> = eval
            .iter()
            .copied()
            .filter(|&i| match (g.as_str(), c.as_str()) {
                ("pure", "FX") => lon[i],
                ("pure", _) => lat[i],
                _ => true,
            })
            .collect();
        let (mut lo, mut hi, mut ss, mut m) = (f64::MAX, f64::MIN, 0.0, 0usize);
        for &i in &rows {
            lo = lo.min(meas[i]);
            hi = hi.max(meas[i]);
            if let Some(s) = sim.get(&((raw.et[i] * 100.0).round() as i64)) {
                let d = s[k] - meas[i];
                if d.is_finite() {
                    ss += d * d;
                    m += 1;
                }
            }
        }
        let ours = if m > 0 && hi > lo {
            (ss / m as f64).sqrt() / (hi - lo)
        } else {
            f64::NAN
        };
        out.push(Figure {
            group: g.clone(),
            channel: c.clone(),
            ours,
            baseline,
            rows: rows.len(),
            answer_rows,
        });
    }
    out.sort_by(|x, y| (x.group != "pure", &x.channel).cmp(&(y.group != "pure", &y.channel)));
    (out, missing)
}

/// Run `job(answer, work dir, dev-set dir)` over every dev-set recording, two
/// at a time (the CI machine's cores), results sorted by recording name. None,
/// after a SKIP line naming `test`, when the shared dev set is absent.
pub fn run_all<T: Send>(
    test: &str,
    job: impl Fn(&Answer, &Path, &Path) -> T + Sync,
) -> Option<Vec<T>> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;
    let dir = super::common::shared().join("data/diagnose-dev");
    let Some(mut answers) = answers(&dir) else {
        eprintln!(
            "SKIP {test}: {} not found (the shared dev set)",
            dir.display()
        );
        return None;
    };
    // A developer's partial run: TYREKIT_DEVSET_ONLY=r04,r15 (the table's
    // counts then cover only those; CI never sets it).
    if let Ok(only) = std::env::var("TYREKIT_DEVSET_ONLY") {
        let keep: Vec<&str> = only.split(',').map(str::trim).collect();
        answers.retain(|a| keep.contains(&a.name.as_str()));
        eprintln!(
            "NOTE {test}: partial run over {:?} (TYREKIT_DEVSET_ONLY)",
            keep
        );
    }
    let work = Path::new(env!("CARGO_TARGET_TMPDIR")).join(test);
    std::fs::create_dir_all(&work).expect("work dir");
    let next = AtomicUsize::new(0);
    let done = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(a) = answers.get(i) else { break };
                let o = job(a, &work, &dir);
                done.lock().unwrap().push((a.name.clone(), o));
            });
        }
    });
    let mut v = done.into_inner().unwrap();
    v.sort_by(|a, b| a.0.cmp(&b.0));
    Some(v.into_iter().map(|(_, o)| o).collect())
}
