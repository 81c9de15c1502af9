//! channel — the one typed name of a recorded/simulated channel (Fx, Fy,
//! Fz, Mx, My, Mz; ISO-W, SI): its name as in the recording's columns
//! ([`crate::data::SAMPLE_CHANNELS`]), the upper-case key the diagnosis
//! report writes ("FX"), its unit, and how to read it from a measured
//! [`Sample`], a model [`Solution`] or the hot path's [`Forces`].
//!
//! Must never: fall back silently to another channel for an unknown name
//! (parsing returns `None`), or invent a simulated Fz (Fz is the model's
//! input: its simulated value is NaN, which every score skips).

use crate::data::Sample;
use crate::mf::{Forces, Real, Solution};

/// A force or moment channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Channel {
    /// Longitudinal force Fx (N, along the ISO-W x axis: positive forward, as when driving).
    Fx,
    /// Lateral force Fy (N, along the ISO-W y axis: positive to the left).
    Fy,
    /// Vertical load Fz (N, positive pressing the tyre on the road): the
    /// model's input, never simulated.
    Fz,
    /// Overturning moment Mx (N·m, about the ISO-W x axis).
    Mx,
    /// Rolling resistance moment My (N·m, about the ISO-W y axis).
    My,
    /// Self-aligning moment Mz (N·m, about the ISO-W z axis, up).
    Mz,
}

impl Channel {
    /// All channels, in [`crate::data::SAMPLE_CHANNELS`] order.
    pub const ALL: [Channel; 6] = [
        Channel::Fz,
        Channel::Fx,
        Channel::Fy,
        Channel::Mx,
        Channel::My,
        Channel::Mz,
    ];
    /// The channels the diagnosis scores and reports (Fx, Fy, Mz).
    pub const SCORED: [Channel; 3] = [Channel::Fx, Channel::Fy, Channel::Mz];

    /// Name as in [`crate::data::SAMPLE_CHANNELS`] and as engineers write it ("Fy").
    pub fn name(self) -> &'static str {
        match self {
            Channel::Fx => "Fx",
            Channel::Fy => "Fy",
            Channel::Fz => "Fz",
            Channel::Mx => "Mx",
            Channel::My => "My",
            Channel::Mz => "Mz",
        }
    }
    /// Upper-case key of the diagnosis report's JSON ("FY").
    pub fn key(self) -> &'static str {
        match self {
            Channel::Fx => "FX",
            Channel::Fy => "FY",
            Channel::Fz => "FZ",
            Channel::Mx => "MX",
            Channel::My => "MY",
            Channel::Mz => "MZ",
        }
    }
    /// SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Fx | Channel::Fy | Channel::Fz => "N",
            Channel::Mx | Channel::My | Channel::Mz => "N m",
        }
    }
    /// A channel by its name or key, case-insensitive ("fy", "FY", "Fy").
    pub fn parse(s: &str) -> Option<Channel> {
        Channel::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(s.trim()))
    }
    /// Whether it is a force (N) rather than a moment (N m).
    pub fn is_force(self) -> bool {
        matches!(self, Channel::Fx | Channel::Fy | Channel::Fz)
    }
    /// The measured value of a sample.
    pub fn measured(self, s: &Sample) -> f64 {
        match self {
            Channel::Fx => s.fx,
            Channel::Fy => s.fy,
            Channel::Fz => s.fz,
            Channel::Mx => s.mx,
            Channel::My => s.my,
            Channel::Mz => s.mz,
        }
    }
    /// The slip that drives the channel in a test: κ for Fx and My, α otherwise.
    pub fn driving_slip(self, s: &Sample) -> f64 {
        match self {
            Channel::Fx | Channel::My => s.kappa,
            _ => s.alpha,
        }
    }
    /// The channel of a model solution (Fz, the model's input: NaN).
    #[inline]
    pub fn of<T: Real>(self, s: &Solution<T>) -> T {
        match self {
            Channel::Fx => s.fx,
            Channel::Fy => s.fy,
            Channel::Fz => T::from(f64::NAN),
            Channel::Mx => s.mx,
            Channel::My => s.my,
            Channel::Mz => s.mz,
        }
    }
    /// The channel of the `f64` hot-path result (Fz, the model's input: NaN).
    #[inline]
    pub fn of_forces(self, f: &Forces) -> f64 {
        match self {
            Channel::Fx => f.fx,
            Channel::Fy => f.fy,
            Channel::Fz => f64::NAN,
            Channel::Mx => f.mx,
            Channel::My => f.my,
            Channel::Mz => f.mz,
        }
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Serialised as its report key ("FY"), the form `diagnosis.json` has always used.
impl serde::Serialize for Channel {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.key())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names round-trip and match the sample's column names.
    #[test]
    fn names_round_trip() {
        for c in Channel::ALL {
            assert_eq!(Channel::parse(c.name()), Some(c));
            assert_eq!(Channel::parse(c.key()), Some(c));
            assert!(crate::data::SAMPLE_CHANNELS.contains(&c.name()));
            let mut v = [0.0; 14];
            let k = crate::data::SAMPLE_CHANNELS
                .iter()
                .position(|n| *n == c.name())
                .unwrap();
            v[k] = 7.0;
            assert_eq!(c.measured(&Sample::from_values(&v)), 7.0);
        }
        assert_eq!(Channel::parse("Fw"), None);
    }
}
