//! recording — what every reader produces and every later stage reads: the
//! ISO-W SI [`Sample`]s of one recording, its test-condition [`Segment`]s
//! and the channels it carries.
//!
//! Must never: hold a value in other units or axes than ISO-W SI, or a
//! channel the file lacked as anything but NaN.

use super::{load, LoadOptions};
use crate::error::Result;
use std::path::Path;

/// One sample of a recording, ISO-W axes, SI units. Channels the recording
/// lacks are NaN (see [`Recording::has`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub time: f64,
    /// Longitudinal speed of the wheel centre (m/s): for rigs that record only
    /// the belt speed V, V·cos α or V as the recording's slip reference says
    /// ([`slip_reference`](super::slip_reference)).
    pub vx: f64,
    /// Wheel spin (rad/s).
    pub omega: f64,
    /// Normal load (N, positive).
    pub fz: f64,
    /// Longitudinal slip (–).
    pub kappa: f64,
    /// Slip angle (rad).
    pub alpha: f64,
    /// Inclination angle (rad).
    pub gamma: f64,
    /// Turn slip (1/m).
    pub phit: f64,
    /// Inflation pressure (Pa).
    pub p: f64,
    /// Longitudinal force Fx (N), positive forward (driving).
    pub fx: f64,
    /// Lateral force Fy (N), positive towards +y (left).
    pub fy: f64,
    /// Overturning moment Mx (N·m), about x.
    pub mx: f64,
    /// Rolling-resistance moment My (N·m), about y.
    pub my: f64,
    /// Self-aligning moment Mz (N·m), about z.
    pub mz: f64,
}

/// Kind of a test segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SegmentKind {
    /// Slip angle α swept at constant slip ratio κ (cornering sweep).
    PureLateral,
    /// Slip ratio κ (or, without a κ channel, Fx/Fz) swept at α ≈ 0 (within
    /// the slip-angle set-point tolerance).
    PureLongitudinal,
    /// κ swept at a non-zero slip angle, or α and κ both swept.
    Combined,
    /// Neither α nor κ swept (e.g. free rolling at a set point).
    Other,
}

impl SegmentKind {
    /// Short label for tables.
    pub fn label(self) -> &'static str {
        match self {
            SegmentKind::PureLateral => "lateral",
            SegmentKind::PureLongitudinal => "longitudinal",
            SegmentKind::Combined => "combined",
            SegmentKind::Other => "other",
        }
    }
}

/// A run of samples at one set of test conditions.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Segment {
    /// First sample index (inclusive).
    pub start: usize,
    /// Last sample index (exclusive).
    pub end: usize,
    /// What the segment sweeps.
    pub kind: SegmentKind,
    /// Load set point Fz (N): median over the segment. The set points are
    /// medians of the binned runs ([`structure`](super::structure)).
    pub fz: f64,
    /// Inclination set point γ (rad): median over the segment.
    pub gamma: f64,
    /// Inflation pressure set point (Pa): median over the segment.
    pub p: f64,
    /// Speed set point (m/s): median of Vx/cos α, i.e. the road (belt) speed.
    pub vx: f64,
    /// Slip-angle set point α (rad) of a drive/brake run; NaN when α is swept.
    pub alpha: f64,
}

impl Segment {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.end - self.start
    }
    /// Whether the segment holds no sample.
    pub fn is_empty(&self) -> bool {
        self.end <= self.start
    }
}

/// A recording converted to ISO-W SI, with its test structure.
#[derive(Clone, Debug, Default)]
pub struct Recording {
    /// Where it came from.
    pub source: String,
    /// The samples (warm-up removed).
    pub samples: Vec<Sample>,
    /// Names of the [`Sample`] channels the recording actually has (e.g. "Fx", "Mz").
    pub channels: Vec<String>,
    /// Further channels (temperatures, radii …) by name, one value per sample.
    /// SI units except temperatures (°C); see [`Loaded::report`](super::Loaded::report) for their units.
    pub extra: Vec<(String, Vec<f64>)>,
    /// Test segments, in time order.
    pub segments: Vec<Segment>,
    /// Per sample: +1 swept slip rising (dα/dt > 0 in lateral, dκ/dt > 0 in
    /// longitudinal/combined segments), −1 falling, 0 unknown / outside segments.
    pub sweep_dir: Vec<i8>,
    /// Per sample: time since its segment began (s); NaN outside segments.
    pub t_in_segment: Vec<f64>,
}

/// Names of the [`Sample`] channels, in CSV column order.
pub const SAMPLE_CHANNELS: [&str; 14] = [
    "time", "Vx", "omega", "Fz", "kappa", "alpha", "gamma", "phit", "P", "Fx", "Fy", "Mx", "My",
    "Mz",
];

impl Sample {
    /// Value of a channel by its [`SAMPLE_CHANNELS`] name.
    pub fn get(&self, name: &str) -> f64 {
        self.values()[SAMPLE_CHANNELS
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))
            .unwrap_or(0)]
    }
    /// All values in [`SAMPLE_CHANNELS`] order.
    pub fn values(&self) -> [f64; 14] {
        [
            self.time, self.vx, self.omega, self.fz, self.kappa, self.alpha, self.gamma, self.phit,
            self.p, self.fx, self.fy, self.mx, self.my, self.mz,
        ]
    }
    /// Build from values in [`SAMPLE_CHANNELS`] order.
    pub fn from_values(v: &[f64; 14]) -> Sample {
        Sample {
            time: v[0],
            vx: v[1],
            omega: v[2],
            fz: v[3],
            kappa: v[4],
            alpha: v[5],
            gamma: v[6],
            phit: v[7],
            p: v[8],
            fx: v[9],
            fy: v[10],
            mx: v[11],
            my: v[12],
            mz: v[13],
        }
    }
}

impl Recording {
    /// Whether the recording has the channel (case-insensitive).
    pub fn has(&self, channel: &str) -> bool {
        self.channels
            .iter()
            .any(|c| c.eq_ignore_ascii_case(channel))
    }
    /// Extra channel by name (case-insensitive).
    pub fn extra(&self, name: &str) -> Option<&[f64]> {
        self.extra
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_slice())
    }
    /// Read any supported file with default options (report discarded; use
    /// [`load`] to see dropped rows, missing channels and the warm-up cut).
    pub fn from_file(path: &Path) -> Result<Recording> {
        Ok(load(path, &LoadOptions::default())?.recording)
    }
    /// The samples of segment `k` (empty when out of range).
    pub fn segment_samples(&self, k: usize) -> &[Sample] {
        self.segments.get(k).map_or(&[][..], |g| {
            &self.samples[g.start.min(self.samples.len())..g.end.min(self.samples.len())]
        })
    }
    /// Index of the segment holding sample `i`.
    pub fn segment_of(&self, i: usize) -> Option<usize> {
        let k = self.segments.partition_point(|s| s.end <= i);
        (k < self.segments.len() && self.segments[k].start <= i).then_some(k)
    }
}
