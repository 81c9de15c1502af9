//! holdout — split a recording's segments into the part a fit sees and the
//! part it is judged on (`--holdout run`, `--holdout condition` or
//! `--holdout tail:F`).
//!
//! `tail:F` is the honest split of a time series: the last fraction F of the
//! recording's time is held out (`tail:0.3` fits the first 70 %), measured
//! from the recording's first row — before any warm-up cut when the caller
//! passes that time ([`Holdout::split_from`]) — to its last sample.
//!
//! Deterministic: every k-th run (segment, in time order) or every k-th
//! distinct condition (sorted by load, inclination, pressure) is held out,
//! counting from the k-th, so `run:5` holds out runs 5, 10, 15 … (1-based).
//! When that would hold out nothing but there are at least two runs
//! (conditions), the last one is held out instead.
//!
//! Must never: put one sample in both halves, or choose at random.

use super::metrics::condition_groups;
use crate::data::Recording;
use std::ops::Range;

/// How to hold data out of a fit.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Holdout {
    /// Nothing held out: the fit sees every segment.
    None,
    /// Every `every`-th segment.
    ByRun {
        /// Period k (`run:K`, ≥ 2 when parsed): runs k, 2k, 3k … (1-based,
        /// time order) are held out.
        every: usize,
    },
    /// Every `every`-th distinct test condition (all its segments).
    ByCondition {
        /// Period k (`condition:K`, ≥ 2 when parsed) over the conditions
        /// sorted by load, inclination, pressure.
        every: usize,
    },
    /// The last `frac` (0 < frac < 1) of the recording's time.
    Tail {
        /// Held-out fraction of the recording's duration (0 < frac < 1).
        frac: f64,
    },
}

/// The two halves, as sample ranges in time order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Split {
    /// Sample ranges the fit sees (including samples outside every segment).
    pub train: Vec<Range<usize>>,
    /// Sample ranges held out to judge the fit on.
    pub test: Vec<Range<usize>>,
}

impl Split {
    fn indices(r: &[Range<usize>]) -> Vec<usize> {
        r.iter().flat_map(|r| r.clone()).collect()
    }
    /// Sample indices of the training half.
    pub fn train_indices(&self) -> Vec<usize> {
        Self::indices(&self.train)
    }
    /// Sample indices of the held-out half.
    pub fn test_indices(&self) -> Vec<usize> {
        Self::indices(&self.test)
    }
}

impl Holdout {
    /// Parse `none`, `run`, `run:K`, `condition`, `condition:K` (default K
    /// = 5) or `tail:F` (0 < F < 1).
    pub fn parse(s: &str) -> crate::Result<Holdout> {
        if let Some((a, b)) = s.split_once(':') {
            if a.trim().eq_ignore_ascii_case("tail") {
                return b
                    .trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|f| *f > 0.0 && *f < 1.0)
                    .map(|frac| Holdout::Tail { frac })
                    .ok_or_else(|| {
                        crate::Error::Input(format!(
                            "--holdout '{s}': after 'tail:' expected the held-out fraction of the recording's time, between 0 and 1 (e.g. tail:0.3)"
                        ))
                    });
            }
        }
        let (kind, k) = match s.split_once(':') {
            Some((a, b)) => (
                a,
                b.trim().parse::<usize>().ok().filter(|&k| k >= 2).ok_or_else(|| {
                    crate::Error::Input(format!(
                        "--holdout '{s}': after ':' expected a whole number ≥ 2 (hold out every K-th)"
                    ))
                })?,
            ),
            None => (s, 5),
        };
        match kind.trim().to_ascii_lowercase().as_str() {
            "none" => Ok(Holdout::None),
            "run" | "runs" => Ok(Holdout::ByRun { every: k }),
            "condition" | "conditions" => Ok(Holdout::ByCondition { every: k }),
            _ => Err(crate::Error::Input(format!(
                "--holdout '{s}': expected none, run, run:K, condition, condition:K or tail:F"
            ))),
        }
    }

    /// Split the segments of `rec`. Samples outside every segment go to the
    /// training half (they are fit data only if the caller uses them).
    pub fn split(&self, rec: &Recording) -> Split {
        self.split_from(rec, None)
    }

    /// As [`Holdout::split`], with the time the recording began (its first
    /// row, before a warm-up cut) for `tail:F`; `None`: the first sample's.
    pub fn split_from(&self, rec: &Recording, t_origin: Option<f64>) -> Split {
        let n = rec.samples.len();
        let segs = &rec.segments;
        let held: Vec<bool> = match *self {
            Holdout::None | Holdout::Tail { .. } => vec![false; segs.len()],
            Holdout::ByRun { every } => {
                let mut h: Vec<bool> = (0..segs.len()).map(|i| (i + 1) % every == 0).collect();
                if !h.iter().any(|&x| x) && segs.len() >= 2 {
                    h[segs.len() - 1] = true;
                }
                h
            }
            Holdout::ByCondition { every } => {
                let groups = condition_groups(rec);
                let mut out: Vec<bool> = (0..groups.len()).map(|i| (i + 1) % every == 0).collect();
                if !out.iter().any(|&x| x) && groups.len() >= 2 {
                    let l = groups.len() - 1;
                    out[l] = true;
                }
                let mut held = vec![false; segs.len()];
                for (g, &h) in groups.iter().zip(&out) {
                    for &k in &g.segments {
                        held[k] = h;
                    }
                }
                held
            }
        };
        // Mark samples, then turn the marks into ranges.
        let mut mark = vec![false; n];
        if let Holdout::Tail { frac } = *self {
            // Last time, not last sample: time may go backwards in a file.
            let t_last = rec.samples.iter().map(|s| s.time).fold(f64::MIN, f64::max);
            let first = rec.samples.first().map_or(0.0, |s| s.time);
            let cut = t_last - frac * (t_last - t_origin.unwrap_or(first).min(first));
            for (m, s) in mark.iter_mut().zip(&rec.samples) {
                *m = s.time >= cut;
            }
        }
        for (s, &h) in segs.iter().zip(&held) {
            // A malformed segment (start ≥ end, or past the samples) marks nothing.
            let (a, b) = (s.start.min(n), s.end.min(n));
            if h && a < b {
                for m in &mut mark[a..b] {
                    *m = true;
                }
            }
        }
        let mut split = Split::default();
        let mut i = 0;
        while i < n {
            let j = (i..n).find(|&j| mark[j] != mark[i]).unwrap_or(n);
            if mark[i] {
                split.test.push(i..j);
            } else {
                split.train.push(i..j);
            }
            i = j;
        }
        split
    }
}
