//! units — conversion of the unit strings found in tyre-test files
//! (TTC SI and US-customary exports, TYDEX, CSV `[unit]` suffixes) to SI.
//!
//! Must never: guess a unit. An unknown unit is an error for the channels the
//! model needs, and is passed through unchanged (and reported) for others.

/// Physical dimension a channel must have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dim {
    /// Time, stored in s.
    Time,
    /// Linear speed, stored in m/s.
    Speed,
    /// Wheel spin rate, stored in rad/s.
    AngularSpeed,
    /// Angle (slip angle, inclination), stored in rad.
    Angle,
    /// Force, stored in N.
    Force,
    /// Moment, stored in N·m.
    Moment,
    /// Inflation pressure, stored in Pa.
    Pressure,
    /// Length (loaded and effective radii), stored in m.
    Length,
    /// Temperature, stored in °C (the one non-SI unit kept).
    Temperature,
    /// Dimensionless ratio (slip ratio κ), stored as a fraction (–); `%` is divided by 100.
    Ratio,
    /// Turn slip / curvature (1/m).
    InvLength,
}

impl Dim {
    /// SI unit written by this crate.
    pub fn si(self) -> &'static str {
        match self {
            Dim::Time => "s",
            Dim::Speed => "m/s",
            Dim::AngularSpeed => "rad/s",
            Dim::Angle => "rad",
            Dim::Force => "N",
            Dim::Moment => "Nm",
            Dim::Pressure => "Pa",
            Dim::Length => "m",
            Dim::Temperature => "degC",
            Dim::Ratio => "-",
            Dim::InvLength => "1/m",
        }
    }
}

/// Linear map to SI: `si = value * scale + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToSi {
    /// Factor applied first (SI units per file unit).
    pub scale: f64,
    /// Offset added after scaling, in the SI unit (non-zero for °F and K only).
    pub offset: f64,
}

const LBF: f64 = 4.448_221_615_260_5;
const INCH: f64 = 0.0254;
const FOOT: f64 = 0.3048;

/// Normalise a unit string: lower case, no spaces, brackets or dots used as
/// multiplication, unicode degree/middle-dot replaced.
fn norm(u: &str) -> String {
    u.trim()
        .trim_start_matches(['[', '('])
        .trim_end_matches([']', ')'])
        .to_ascii_lowercase()
        .replace('°', "deg")
        .replace(['·', '*', '.', ' ', '_'], "-")
        .replace("--", "-")
}

/// The conversion of `unit` for a channel of dimension `dim`, or `None` when
/// the unit is not known for that dimension. An empty unit means "already SI"
/// only for ratios; for everything else it is unknown.
pub fn to_si(dim: Dim, unit: &str) -> Option<ToSi> {
    let u = norm(unit);
    let s = |scale: f64| Some(ToSi { scale, offset: 0.0 });
    match dim {
        Dim::Time => match u.as_str() {
            "s" | "sec" | "second" | "seconds" => s(1.0),
            "ms" => s(1e-3),
            "min" => s(60.0),
            _ => None,
        },
        Dim::Speed => match u.as_str() {
            "m/s" | "m-s^-1" | "mps" => s(1.0),
            "kph" | "km/h" | "kmh" | "km/hr" | "kmph" => s(1.0 / 3.6),
            "mph" | "mi/h" => s(0.447_04),
            "ft/s" | "fps" => s(FOOT),
            _ => None,
        },
        Dim::AngularSpeed => match u.as_str() {
            "rad/s" | "rad-s^-1" | "1/s" => s(1.0),
            "rpm" | "1/min" | "rev/min" => s(std::f64::consts::TAU / 60.0),
            "deg/s" => s(std::f64::consts::PI / 180.0),
            _ => None,
        },
        Dim::Angle => match u.as_str() {
            "rad" | "radian" | "radians" => s(1.0),
            "deg" | "degree" | "degrees" => s(std::f64::consts::PI / 180.0),
            _ => None,
        },
        Dim::Force => match u.as_str() {
            "n" | "newton" | "newtons" => s(1.0),
            "kn" => s(1e3),
            "lb" | "lbf" | "lbs" => s(LBF),
            _ => None,
        },
        Dim::Moment => match u.as_str() {
            "nm" | "n-m" | "newton-meter" | "newton-metre" => s(1.0),
            "knm" | "kn-m" => s(1e3),
            "ft-lb" | "ft-lbf" | "lb-ft" | "lbf-ft" | "ftlb" => s(LBF * FOOT),
            "in-lb" | "in-lbf" | "lb-in" | "lbf-in" | "inlb" => s(LBF * INCH),
            _ => None,
        },
        Dim::Pressure => match u.as_str() {
            "pa" => s(1.0),
            "kpa" => s(1e3),
            "mpa" => s(1e6),
            "bar" => s(1e5),
            "mbar" => s(100.0),
            "psi" | "lb/in^2" | "lbf/in^2" => s(LBF / (INCH * INCH)),
            _ => None,
        },
        Dim::Length => match u.as_str() {
            "m" | "meter" | "metre" => s(1.0),
            "cm" => s(0.01),
            "mm" => s(1e-3),
            "in" | "inch" | "inches" => s(INCH),
            "ft" => s(FOOT),
            _ => None,
        },
        Dim::Temperature => match u.as_str() {
            "degc" | "c" | "deg-c" | "celsius" => s(1.0),
            "degf" | "f" | "deg-f" | "fahrenheit" => Some(ToSi {
                scale: 5.0 / 9.0,
                offset: -32.0 * 5.0 / 9.0,
            }),
            "k" | "kelvin" => Some(ToSi {
                scale: 1.0,
                offset: -273.15,
            }),
            _ => None,
        },
        Dim::Ratio => match u.as_str() {
            "" | "-" | "1" | "none" | "ratio" | "nd" | "n/a" => s(1.0),
            "%" | "percent" => s(0.01),
            _ => None,
        },
        Dim::InvLength => match u.as_str() {
            "1/m" | "m^-1" | "-" | "" => s(1.0),
            "1/mm" => s(1e3),
            _ => None,
        },
    }
}

/// The unit in a column header such as `Fy [N]` or `SA (deg)`: (name, unit).
pub fn split_header(h: &str) -> (String, Option<String>) {
    let h = h.trim().trim_matches('"');
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let (Some(a), true) = (h.rfind(open), h.ends_with(close)) {
            let name = h[..a].trim().to_string();
            let unit = h[a + 1..h.len() - 1].trim().to_string();
            if !name.is_empty() {
                return (name, Some(unit));
            }
        }
    }
    (h.to_string(), None)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conv(d: Dim, u: &str, x: f64) -> f64 {
        let c = to_si(d, u).unwrap();
        x * c.scale + c.offset
    }

    #[test]
    fn customary_units_match_their_definitions() {
        // 1 lbf = 0.45359237 kg * 9.80665 m/s^2 (exact by definition).
        assert!((conv(Dim::Force, "lb", 1.0) - 0.453_592_37 * 9.806_65).abs() < 1e-12);
        // 1 psi = 6894.757 Pa.
        assert!((conv(Dim::Pressure, "psi", 1.0) - 6894.757).abs() < 1e-3);
        assert!((conv(Dim::Speed, "kph", 36.0) - 10.0).abs() < 1e-12);
        assert!((conv(Dim::Speed, "mph", 25.0) - 11.176).abs() < 1e-9);
        assert!((conv(Dim::Temperature, "degF", 212.0) - 100.0).abs() < 1e-9);
        assert!((conv(Dim::Temperature, "K", 273.15)).abs() < 1e-9);
        assert!((conv(Dim::Moment, "ft-lb", 1.0) - 1.355_817_948).abs() < 1e-8);
        assert!((conv(Dim::Length, "cm", 25.0) - 0.25).abs() < 1e-12);
        assert!((conv(Dim::AngularSpeed, "rpm", 60.0) - std::f64::consts::TAU).abs() < 1e-12);
        assert!((conv(Dim::Angle, "°", 180.0) - std::f64::consts::PI).abs() < 1e-12);
        assert!((conv(Dim::Moment, "N·m", 2.0) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn unknown_units_are_not_guessed() {
        assert!(to_si(Dim::Force, "kgf").is_none());
        assert!(to_si(Dim::Angle, "").is_none());
        assert!(to_si(Dim::Pressure, "N").is_none());
    }

    #[test]
    fn header_units() {
        assert_eq!(split_header("Fy [N]"), ("Fy".into(), Some("N".into())));
        assert_eq!(split_header(" SR [-]"), ("SR".into(), Some("-".into())));
        assert_eq!(split_header("alpha"), ("alpha".into(), None));
        assert_eq!(split_header("SA (deg)"), ("SA".into(), Some("deg".into())));
    }
}
