//! locate — where do the residuals (measured − simulated) of one channel
//! concentrate? Each grouping gets a statistic and a permutation
//! significance, so that structure is told apart from noise.
//!
//! # Groupings
//! Segment level (one value per test segment; the unit of independence is
//! the segment, so within-run autocorrelation does not matter):
//! * `load`, `inclination`, `pressure`, `speed`, `energy` — per segment the
//!   mean residual `m_k` and the relative scale error
//!   `b_k = Σ r·F / Σ F²` (a friction/stiffness change shows as a scale error
//!   of the odd force curve, which averages out of `m_k`); the statistic is
//!   r²(x, b) + r²(x, m) against the segment's set point `x` (for `energy`:
//!   the accumulated frictional energy at the segment's middle). Null: the
//!   segment values exchanged among segments (permutation test).
//!   `pressure` takes each segment's mean *recorded* pressure, not its
//!   binned set point, so that a drifting, leaking or saw-tooth pressure is
//!   a continuous factor (the scale errors reported are then those of the
//!   least-squares line over the segments, at its lowest and highest
//!   pressure, not two single noisy segments). A factor whose values span
//!   no more than [`factor::MIN_SPAN_NOISE`] times its recorded noise
//!   ([`factor::noise`]) is not tested: two binned "levels" of one belt
//!   speed are not a dependence on speed.
//!
//! Sample level (within segments; residuals demeaned per segment; at most
//! [`MAX_WITHIN`] samples, longer recordings thinned by a constant stride):
//! * `slip_region` — between-region share (R²) of `u = r·sign(F_sim)`
//!   ("measured stronger than the model") over the linear
//!   (|K·s|/F_peak < 0.8), peak and sliding (|s| beyond 1.15 × the slip of
//!   the model's peak on that side) regions;
//! * `sweep_direction` — r²(r, sweep direction); the paired difference
//!   (rising − falling residual at the same slip, 20 slip bins) is reported
//!   as the hysteresis amplitude;
//! * `force_rate` — r²(r, −dF_sim/dt): a lag makes the measurement late, so
//!   the residual follows minus the force rate; the slope is the delay
//!   (seconds, and metres rolled), reported beside it;
//! * `time_in_run` — r²(u, time since the segment began): drift.
//!
//! Null for sample-level statistics: each segment's residual series is
//! **circularly shifted** by a random offset against its covariates (the
//! "toroidal shift" test). This keeps the residual's autocorrelation (rig
//! noise is filtered, model error is smooth) — a naive sample permutation
//! would treat 10 000 correlated samples as independent and call noise
//! structure — while breaking any alignment with slip, direction or time.
//!
//! p = (1 + #{null ≥ observed}) / (1 + N), N = [`LocateOptions::permutations`],
//! fixed seed. Significance: Holm's step-down correction over the groupings
//! tested, family-wise false-alarm rate [`LocateOptions::alpha`] (5 %).
//! Ranking: significant findings first, by z = (observed − null mean)/null sd.
//!
//! Must never: call a grouping significant without its null distribution,
//! or use an unseeded random source.

use super::factor;
use crate::data::{Recording, Sample, Segment};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The residual data of one channel, aligned per sample.
#[derive(Clone, Copy, Debug)]
pub struct Residuals<'a> {
    /// Measured − simulated.
    pub r: &'a [f64],
    /// Simulated force of the channel.
    pub sim: &'a [f64],
    /// The slip driving the channel (α for Fy/Mz, κ for Fx).
    pub slip: &'a [f64],
    /// +1 rising slip, −1 falling, 0 unknown.
    pub sweep_dir: &'a [i8],
    /// Time since the segment began (s).
    pub t_in_segment: &'a [f64],
    /// Accumulated frictional energy since the recording began (J).
    pub energy: &'a [f64],
    /// The test segments (with their set points).
    pub segments: &'a [Segment],
    /// The recording's samples, for the recorded conditions (pressure,
    /// speed, load, inclination) and their noise; empty: set points only,
    /// no noise rule.
    pub samples: &'a [Sample],
}

/// Settings.
#[derive(Clone, Copy, Debug)]
pub struct LocateOptions {
    /// Permutations (or circular shifts) N of each null distribution.
    pub permutations: usize,
    /// Seed of the ChaCha8 random source (fixed: reproducible p-values).
    pub seed: u64,
    /// Family-wise false-alarm rate.
    pub alpha: f64,
}

impl Default for LocateOptions {
    fn default() -> Self {
        LocateOptions {
            permutations: 999,
            seed: 0x7e5_1d0a1,
            alpha: 0.05,
        }
    }
}

/// One grouping's result.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Finding {
    /// `load`, `inclination`, `pressure`, `speed`, `energy`, `slip_region`,
    /// `sweep_direction`, `force_rate`, `time_in_run`.
    pub name: &'static str,
    /// The observed statistic (r² or R²; see the module docs).
    pub statistic: f64,
    /// (observed − null mean) / null sd.
    pub z: f64,
    /// Permutation p-value.
    pub p_value: f64,
    /// Holm-adjusted p-value.
    pub p_adjusted: f64,
    /// Holm-adjusted p-value ≤ [`LocateOptions::alpha`]: structure, not noise.
    pub significant: bool,
    /// Plain-words detail (group means, hysteresis amplitude …).
    pub detail: String,
    /// The same figures by name, for the explanation: segment groupings
    /// `x_min`, `x_max` (set points) and `scale_at_min`, `scale_at_max`
    /// (relative force scale errors there); `slip_region` the mean signed
    /// residual per region `linear`, `peak`, `sliding` (channel unit);
    /// `sweep_direction` the paired `rising_minus_falling` residual;
    /// `force_rate` the delay it amounts to, `delay_s` (s, + = measured
    /// late) and `delay_m` (m rolled).
    pub groups: Vec<(String, f64)>,
    /// The share of the channel's residual sum of squares (over the
    /// segments analysed) that the grouping's structure accounts for — its
    /// size, where `significant` says only that it is not noise: segment
    /// groupings the part of the per-segment mean and scale error on the
    /// least-squares line in the set point, sample groupings the statistic
    /// (r², R²) times the within-segment share of the squares.
    pub share: f64,
}

impl Finding {
    /// A finding from its observed statistic and null distribution (not yet adjusted).
    fn new(name: &'static str, obs: f64, null: &[f64], detail: String) -> Finding {
        let (z, p) = significance(obs, null);
        Finding {
            name,
            statistic: obs,
            z,
            p_value: p,
            p_adjusted: p,
            significant: false,
            detail,
            groups: Vec::new(),
            share: f64::NAN,
        }
    }

    /// With its size (see [`Finding::share`]).
    fn with_share(mut self, share: f64) -> Finding {
        self.share = share;
        self
    }

    /// With named figures (see [`Finding::groups`]).
    fn with_groups(mut self, g: &[(&str, f64)]) -> Finding {
        self.groups = g.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        self
    }

    /// A named figure of [`Finding::groups`] (NaN when absent).
    pub fn group(&self, key: &str) -> f64 {
        self.groups
            .iter()
            .find(|(k, _)| k == key)
            .map_or(f64::NAN, |g| g.1)
    }
}

/// Accumulated frictional energy (J) per sample from measured forces and slip
/// speeds: E = ∫ |Fx·Vsx| + |Fy·Vsy| dt, Vsx = κ·|Vx|, Vsy = tan α·|Vx|
/// (NaN terms and gaps contribute nothing).
pub fn frictional_energy(rec: &Recording) -> Vec<f64> {
    let mut e = 0.0;
    let mut out = Vec::with_capacity(rec.samples.len());
    let mut prev_t = f64::NAN;
    for s in &rec.samples {
        let dt = s.time - prev_t;
        prev_t = s.time;
        let v = s.vx.abs();
        let p = (s.fx * s.kappa * v).abs() + (s.fy * s.alpha.tan() * v).abs();
        if dt.is_finite() && dt > 0.0 && dt < 1.0 && p.is_finite() {
            e += p * dt;
        }
        out.push(e);
    }
    out
}

/// Pearson r² of (x, y) (0 when either is constant).
fn r2(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len()) as f64;
    if n < 3.0 {
        return 0.0;
    }
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    if sxx <= 0.0 || syy <= 0.0 {
        0.0
    } else {
        sxy * sxy / (sxx * syy)
    }
}

/// Least-squares slope of y on x (0 when x is constant).
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len()) as f64;
    if n < 2.0 {
        return 0.0;
    }
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
    }
    if sxx > 0.0 {
        sxy / sxx
    } else {
        0.0
    }
}

/// Observed value and null distribution → (z, p).
fn significance(obs: f64, null: &[f64]) -> (f64, f64) {
    let n = null.len() as f64;
    let mean = null.iter().sum::<f64>() / n.max(1.0);
    let sd =
        (null.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    let ge = null.iter().filter(|&&x| x >= obs).count() as f64;
    let z = if sd > 0.0 { (obs - mean) / sd } else { 0.0 };
    (z, (1.0 + ge) / (1.0 + n))
}

/// Per-segment summary of the residual.
struct SegmentValue {
    /// Index into the segments.
    k: usize,
    /// Mean residual.
    mean: f64,
    /// Relative scale error Σ r·F / Σ F².
    scale: f64,
    /// Samples used.
    n: usize,
    /// Σ F² of the model's force.
    sff: f64,
    /// Σ r².
    srr: f64,
}

/// Per-segment summaries (segments with at least 10 finite samples).
fn segment_values(d: &Residuals) -> Vec<SegmentValue> {
    let mut v = Vec::new();
    for (k, g) in d.segments.iter().enumerate() {
        let (mut sr, mut srf, mut sff, mut srr, mut n) = (0.0, 0.0, 0.0, 0.0, 0usize);
        for i in g.start..g.end.min(d.r.len()) {
            let (r, f) = (d.r[i], d.sim[i]);
            if r.is_finite() && f.is_finite() {
                sr += r;
                srf += r * f;
                sff += f * f;
                srr += r * r;
                n += 1;
            }
        }
        if n >= 10 {
            let scale = if sff > 0.0 { srf / sff } else { 0.0 };
            v.push(SegmentValue {
                k,
                mean: sr / n as f64,
                scale,
                n,
                sff,
                srr,
            });
        }
    }
    v
}

/// The share of the residual's squares (Σ r² over `sv`) on the
/// least-squares lines of the segments' mean residuals `m` and scale errors
/// `b` in their set point `x`: Σ n·(m̂ − m̄)² + Σ F²·(b̂ − b̄)².
fn segment_share(sv: &[SegmentValue], m: &[f64], b: &[f64], x: &[f64]) -> f64 {
    let (km, kb) = (slope(x, m), slope(x, b));
    let mx = x.iter().sum::<f64>() / x.len().max(1) as f64;
    let explained: f64 = sv
        .iter()
        .zip(x)
        .map(|(v, &xi)| {
            let dx = xi - mx;
            v.n as f64 * (km * dx).powi(2) + v.sff * (kb * dx).powi(2)
        })
        .sum();
    let total: f64 = sv.iter().map(|v| v.srr).sum();
    if total > 0.0 {
        explained / total
    } else {
        0.0
    }
}

/// Most samples the sample-level tests use: longer recordings are thinned by
/// a constant stride (each test costs `permutations` passes over them). A
/// circular shift keeps the thinned series' autocorrelation as it keeps the
/// full one's, so the null stays right; rig channels at 100 Hz and more are
/// smooth over many samples, so little information is lost.
pub const MAX_WITHIN: usize = 30_000;

/// Sample-level working arrays (within segments, finite samples only).
struct Within {
    /// Segment ranges into the arrays below.
    ranges: Vec<(usize, usize)>,
    /// Residual, demeaned per segment.
    r: Vec<f64>,
    /// u = r·sign(F_sim), demeaned per segment.
    u: Vec<f64>,
    dir: Vec<f64>,
    rate: Vec<f64>,
    /// Minus the model's force rate per second, −ΔF_sim/Δt (0 where Δt is
    /// unknown), for the delay estimate of [`delay`].
    rate_per_s: Vec<f64>,
    /// Mean wheel-centre speed |Vx| of the samples taken (m/s; NaN
    /// without samples).
    speed: f64,
    time: Vec<f64>,
    /// 0 linear, 1 peak, 2 sliding.
    region: Vec<u8>,
    /// Slip value (for the paired hysteresis difference).
    slip: Vec<f64>,
    /// Σ r² of the samples taken, before the per-segment demeaning.
    raw_ss: f64,
}

fn within(d: &Residuals) -> Within {
    let mut w = Within {
        ranges: vec![],
        r: vec![],
        u: vec![],
        dir: vec![],
        rate: vec![],
        rate_per_s: vec![],
        speed: f64::NAN,
        time: vec![],
        region: vec![],
        slip: vec![],
        raw_ss: 0.0,
    };
    let total: usize = d.segments.iter().map(|g| g.len()).sum();
    let stride = total.div_ceil(MAX_WITHIN).max(1);
    let mut speed = (0.0, 0usize);
    for g in d.segments {
        let idx: Vec<usize> = (g.start..g.end.min(d.r.len()))
            .step_by(stride)
            .filter(|&i| d.r[i].is_finite() && d.sim[i].is_finite() && d.slip[i].is_finite())
            .collect();
        if idx.len() < 10 {
            continue;
        }
        let a = w.r.len();
        // Model peak per side and slip stiffness near zero slip.
        let peak = idx.iter().map(|&i| d.sim[i].abs()).fold(0.0, f64::max);
        let (mut s_pos, mut f_pos, mut s_neg, mut f_neg) = (f64::INFINITY, 0.0, f64::INFINITY, 0.0);
        let (mut kfs, mut kss) = (0.0, 0.0);
        for &i in &idx {
            let (s, f) = (d.slip[i], d.sim[i].abs());
            if s > 0.0 && f > f_pos {
                f_pos = f;
                s_pos = s;
            }
            if s < 0.0 && f > f_neg {
                f_neg = f;
                s_neg = -s;
            }
            if d.sim[i].abs() < 0.3 * peak {
                kfs += d.sim[i] * s;
                kss += s * s;
            }
        }
        let k = if kss > 0.0 { (kfs / kss).abs() } else { 0.0 };
        let mr = idx.iter().map(|&i| d.r[i]).sum::<f64>() / idx.len() as f64;
        let mu = idx.iter().map(|&i| d.r[i] * d.sim[i].signum()).sum::<f64>() / idx.len() as f64;
        for (j, &i) in idx.iter().enumerate() {
            let s = d.slip[i];
            w.raw_ss += d.r[i] * d.r[i];
            w.r.push(d.r[i] - mr);
            w.u.push(d.r[i] * d.sim[i].signum() - mu);
            w.dir.push(f64::from(*d.sweep_dir.get(i).unwrap_or(&0)));
            let p = if j > 0 { idx[j - 1] } else { i };
            let df = d.sim[i] - d.sim[p];
            w.rate.push(-df);
            let dt = d.t_in_segment.get(i).copied().unwrap_or(f64::NAN)
                - d.t_in_segment.get(p).copied().unwrap_or(f64::NAN);
            w.rate_per_s.push(if dt > 0.0 { -df / dt } else { 0.0 });
            if let Some(v) = d
                .samples
                .get(i)
                .map(|x| x.vx.abs())
                .filter(|v| v.is_finite())
            {
                speed.0 += v;
                speed.1 += 1;
            }
            w.time
                .push(d.t_in_segment.get(i).copied().unwrap_or(f64::NAN));
            let theta = if peak > 0.0 { k * s.abs() / peak } else { 0.0 };
            let side_peak = if s >= 0.0 { s_pos } else { s_neg };
            w.region.push(if theta < 0.8 {
                0
            } else if s.abs() > 1.15 * side_peak {
                2
            } else {
                1
            });
            w.slip.push(s);
        }
        w.ranges.push((a, w.r.len()));
    }
    for t in w.time.iter_mut() {
        if !t.is_finite() {
            *t = 0.0;
        }
    }
    if speed.1 > 0 {
        w.speed = speed.0 / speed.1 as f64;
    }
    w
}

/// The delay the residual shows, in seconds and in metres rolled: a
/// measurement late by τ reads F(t − τ) ≈ F(t) − τ·dF/dt, so τ is the
/// least-squares slope of the residual on minus the model's force rate
/// (first order in τ; a few tenths of a second against sweeps of seconds).
/// The distance is τ times the mean wheel-centre speed (NaN without
/// samples).
fn delay(w: &Within) -> (f64, f64) {
    let tau = slope(&w.rate_per_s, &w.r);
    (tau, tau * w.speed)
}

/// Between-group share R² of `y` over groups 0..3.
fn region_r2(y: &[f64], g: &[u8]) -> f64 {
    let (mut s, mut n) = ([0.0; 3], [0usize; 3]);
    let mut tot = 0.0;
    for (v, &k) in y.iter().zip(g) {
        s[k as usize] += v;
        n[k as usize] += 1;
        tot += v * v;
    }
    let m: f64 = s.iter().sum::<f64>() / y.len().max(1) as f64;
    let ss_tot = tot - y.len() as f64 * m * m;
    let ss_b: f64 = (0..3)
        .filter(|&k| n[k] > 0)
        .map(|k| {
            let mk = s[k] / n[k] as f64;
            n[k] as f64 * (mk - m) * (mk - m)
        })
        .sum();
    if ss_tot > 0.0 {
        ss_b / ss_tot
    } else {
        0.0
    }
}

/// Circularly shift each segment's series by a random offset into `out`.
fn shift_into(x: &[f64], ranges: &[(usize, usize)], rng: &mut ChaCha8Rng, out: &mut [f64]) {
    for &(a, b) in ranges {
        let n = b - a;
        let o = rng.gen_range(0..n);
        for j in 0..n {
            out[a + j] = x[a + (j + o) % n];
        }
    }
}

/// Paired rising − falling residual at the same slip (20 bins over the slip
/// range, bins with both directions only): mean difference.
fn hysteresis(w: &Within) -> f64 {
    let (lo, hi) = w
        .slip
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &s| {
            (l.min(s), h.max(s))
        });
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return 0.0;
    }
    let mut acc = [[0.0f64; 4]; 20];
    for ((&s, &r), &d) in w.slip.iter().zip(&w.r).zip(&w.dir) {
        let b = (((s - lo) / (hi - lo)) * 20.0).min(19.0) as usize;
        if d > 0.0 {
            acc[b][0] += r;
            acc[b][1] += 1.0;
        } else if d < 0.0 {
            acc[b][2] += r;
            acc[b][3] += 1.0;
        }
    }
    let d: Vec<f64> = acc
        .iter()
        .filter(|a| a[1] > 0.0 && a[3] > 0.0)
        .map(|a| a[0] / a[1] - a[2] / a[3])
        .collect();
    d.iter().sum::<f64>() / d.len().max(1) as f64
}

/// Locate the residual structure of one channel. Findings ranked: significant
/// first by z, then the rest by p-value.
pub fn locate(d: &Residuals, o: &LocateOptions) -> Vec<Finding> {
    let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
    let np = o.permutations.max(19);
    let mut out: Vec<Finding> = Vec::new();

    // Segment level.
    let sv = segment_values(d);
    let mid_energy = |g: &Segment| {
        let i = ((g.start + g.end) / 2).min(d.energy.len().saturating_sub(1));
        d.energy.get(i).copied().unwrap_or(f64::NAN)
    };
    // (name, value per segment, the recorded condition per sample (None:
    // no sample-level reading), continuous: fitted line instead of the
    // extreme segments).
    type Cov<'c> = (
        &'static str,
        &'c dyn Fn(&Segment) -> f64,
        Option<fn(&Sample) -> f64>,
        bool,
    );
    let have_samples = !d.samples.is_empty();
    let mean_p = |g: &Segment| {
        let m = factor::segment_mean(d.samples, g, |s| s.p);
        if m.is_finite() {
            m
        } else {
            g.p
        }
    };
    let covs: [Cov; 5] = [
        ("load", &|g| g.fz, Some(|s| s.fz), false),
        ("inclination", &|g| g.gamma, Some(|s| s.gamma), false),
        (
            "pressure",
            if have_samples { &mean_p } else { &|g| g.p },
            Some(|s| s.p),
            have_samples,
        ),
        ("speed", &|g| g.vx, Some(|s| s.vx), false),
        ("energy", &mid_energy, None, false),
    ];
    let m: Vec<f64> = sv.iter().map(|v| v.mean).collect();
    let b: Vec<f64> = sv.iter().map(|v| v.scale).collect();
    let used: Vec<&Segment> = sv.iter().map(|v| &d.segments[v.k]).collect();
    for (name, f, get, continuous) in covs {
        let x: Vec<f64> = sv.iter().map(|v| f(&d.segments[v.k])).collect();
        if x.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let spread = x.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - x.iter().cloned().fold(f64::INFINITY, f64::min);
        let scale = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
        if x.len() < 4 || spread.partial_cmp(&(1e-9 * scale)) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        // Levels closer than the condition's own noise are not a factor.
        if let (true, Some(get)) = (have_samples, get) {
            if !factor::varies_beyond_noise(spread, factor::noise(d.samples, &used, get)) {
                continue;
            }
        }
        let stat = |perm: &[usize]| {
            let pm: Vec<f64> = perm.iter().map(|&j| m[j]).collect();
            let pb: Vec<f64> = perm.iter().map(|&j| b[j]).collect();
            r2(&x, &pb) + r2(&x, &pm)
        };
        let id: Vec<usize> = (0..x.len()).collect();
        let obs = stat(&id);
        let mut perm = id.clone();
        let null: Vec<f64> = (0..np)
            .map(|_| {
                for i in (1..perm.len()).rev() {
                    perm.swap(i, rng.gen_range(0..=i));
                }
                stat(&perm)
            })
            .collect();
        let (lo, hi) = if continuous {
            fitted_extremes(&x, &b)
        } else {
            extremes(&x, &b)
        };
        out.push(
            Finding::new(
                name,
                obs,
                &null,
                format!(
                    "relative force scale error {:+.2} % at {name} {:.4}, {:+.2} % at {:.4} ({} segments)",
                    100.0 * lo.1,
                    lo.0,
                    100.0 * hi.1,
                    hi.0,
                    x.len()
                ),
            )
            .with_groups(&[
                ("x_min", lo.0),
                ("x_max", hi.0),
                ("scale_at_min", lo.1),
                ("scale_at_max", hi.1),
            ])
            .with_share(segment_share(&sv, &m, &b, &x)),
        );
    }

    // Sample level.
    let w = within(d);
    if !w.r.is_empty() {
        let mut buf = vec![0.0; w.r.len()];
        let mut sample_test = |name: &'static str,
                               y: &[f64],
                               stat: &dyn Fn(&[f64]) -> f64,
                               detail: String,
                               rng: &mut ChaCha8Rng| {
            let obs = stat(y);
            let null: Vec<f64> = (0..np)
                .map(|_| {
                    shift_into(y, &w.ranges, rng, &mut buf);
                    stat(&buf)
                })
                .collect();
            let within_ss: f64 = y.iter().map(|v| v * v).sum();
            let share = if w.raw_ss > 0.0 {
                obs * within_ss / w.raw_ss
            } else {
                0.0
            };
            out.push(Finding::new(name, obs, &null, detail).with_share(share));
        };
        let region_means = {
            let (mut s, mut n) = ([0.0; 3], [0usize; 3]);
            for (v, &k) in w.u.iter().zip(&w.region) {
                s[k as usize] += v;
                n[k as usize] += 1;
            }
            (0..3)
                .map(|k| {
                    if n[k] > 0 {
                        s[k] / n[k] as f64
                    } else {
                        f64::NAN
                    }
                })
                .collect::<Vec<_>>()
        };
        let hyst = hysteresis(&w);
        let drift = slope(&w.time, &w.u);
        sample_test(
            "slip_region",
            &w.u,
            &|y| region_r2(y, &w.region),
            {
                // A region without samples has no mean: say so.
                let m = |k: usize| {
                    if region_means[k].is_finite() {
                        format!("{:+.3}", region_means[k])
                    } else {
                        "no samples".to_string()
                    }
                };
                format!(
                    "mean signed residual (+ = measured stronger): linear {}, peak {}, sliding {}",
                    m(0),
                    m(1),
                    m(2)
                )
            },
            &mut rng,
        );
        if w.dir.iter().any(|&x| x != 0.0) {
            sample_test(
                "sweep_direction",
                &w.r,
                &|y| r2(y, &w.dir),
                format!("rising − falling residual at equal slip: {hyst:+.3} (paired, slip bins)"),
                &mut rng,
            );
        }
        sample_test(
            "force_rate",
            &w.r,
            &|y| r2(y, &w.rate),
            "residual against minus the model's force rate (lag signature)".into(),
            &mut rng,
        );
        sample_test(
            "time_in_run",
            &w.u,
            &|y| r2(y, &w.time),
            "signed residual against time since the run began (drift)".into(),
            &mut rng,
        );
        for f in out.iter_mut() {
            match f.name {
                "slip_region" => {
                    f.groups = ["linear", "peak", "sliding"]
                        .iter()
                        .zip(&region_means)
                        .map(|(k, v)| (k.to_string(), *v))
                        .collect()
                }
                "sweep_direction" => f.groups = vec![("rising_minus_falling".into(), hyst)],
                "time_in_run" => f.groups = vec![("slope_per_s".into(), drift)],
                "force_rate" => {
                    let (s, m) = delay(&w);
                    f.groups = vec![("delay_s".into(), s), ("delay_m".into(), m)];
                }
                _ => {}
            }
        }
    }

    // Holm step-down adjustment.
    let mut order: Vec<usize> = (0..out.len()).collect();
    order.sort_by(|&a, &b| out[a].p_value.total_cmp(&out[b].p_value));
    let m = out.len();
    let mut running: f64 = 0.0;
    for (rank, &i) in order.iter().enumerate() {
        running = running.max(((m - rank) as f64 * out[i].p_value).min(1.0));
        out[i].p_adjusted = running;
        out[i].significant = running <= o.alpha;
    }
    out.sort_by(|a, b| {
        b.significant.cmp(&a.significant).then(if a.significant {
            b.z.total_cmp(&a.z)
        } else {
            a.p_value.total_cmp(&b.p_value)
        })
    });
    out
}

/// (x, ŷ) at the smallest and largest x, ŷ on the least-squares line of y on x.
fn fitted_extremes(x: &[f64], y: &[f64]) -> ((f64, f64), (f64, f64)) {
    let k = slope(x, y);
    let n = x.len().max(1) as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let ((a, _), (b, _)) = extremes(x, y);
    ((a, my + k * (a - mx)), (b, my + k * (b - mx)))
}

/// (x, y) at the smallest and largest x.
fn extremes(x: &[f64], y: &[f64]) -> ((f64, f64), (f64, f64)) {
    let mut lo = (f64::INFINITY, 0.0);
    let mut hi = (f64::NEG_INFINITY, 0.0);
    for (&a, &b) in x.iter().zip(y) {
        if a < lo.0 {
            lo = (a, b);
        }
        if a > hi.0 {
            hi = (a, b);
        }
    }
    (lo, hi)
}
