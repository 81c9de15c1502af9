//! data — tyre test recordings: readers (FSAE TTC .mat/.dat, TYDEX, CSV),
//! axis-system and unit conversion into ISO-W SI, warm-up removal, slip
//! computation and the split into test conditions.
//!
//! Must never: keep a NaN or out-of-range row silently (drop and count it),
//! guess units a file states, or panic on a malformed file.
//!
//! STUB: the types below are the contract `fit` and `diagnose` build on.

/// One sample of a recording, ISO-W axes, SI units. Channels the recording
/// lacks are NaN (see [`Recording::has`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub time: f64,
    /// Longitudinal speed (m/s).
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
    pub fx: f64,
    pub fy: f64,
    pub mx: f64,
    pub my: f64,
    pub mz: f64,
}

/// Kind of a test segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SegmentKind {
    PureLateral,
    PureLongitudinal,
    Combined,
    Other,
}

/// A run of samples at one set of test conditions.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Segment {
    /// First sample index (inclusive).
    pub start: usize,
    /// Last sample index (exclusive).
    pub end: usize,
    pub kind: SegmentKind,
    /// Set points (binned): load (N), inclination (rad), pressure (Pa), speed (m/s), slip angle (rad, drive/brake runs).
    pub fz: f64,
    pub gamma: f64,
    pub p: f64,
    pub vx: f64,
    pub alpha: f64,
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
    pub extra: Vec<(String, Vec<f64>)>,
    /// Test segments, in time order.
    pub segments: Vec<Segment>,
    /// Per sample: +1 slip rising, −1 falling, 0 unknown.
    pub sweep_dir: Vec<i8>,
    /// Per sample: time since its segment began (s).
    pub t_in_segment: Vec<f64>,
}

impl Recording {
    /// Whether the recording has the channel (case-insensitive).
    pub fn has(&self, channel: &str) -> bool {
        self.channels
            .iter()
            .any(|c| c.eq_ignore_ascii_case(channel))
    }
}
