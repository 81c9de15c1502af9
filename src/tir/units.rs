//! units — the `[UNITS]` section of a `.tir` file: unit names to SI factors,
//! and the factor of each key [`Dim`] (stiffness = force/length, …).
//!
//! Conversion happens once, on read: a value in the file times
//! [`Units::factor`] of its dimension is the SI value. The writer always
//! writes SI, so it never needs the inverse.
//!
//! Must never: guess an unknown unit (that is an error naming file, line and
//! key), or convert a dimensionless Magic Formula coefficient.

use super::keys::Dim;

/// One lbf in newtons (exact by definition: 0.45359237 kg × 9.80665 m/s²).
const LBF: f64 = 4.448_221_615_260_5;
/// One inch in metres (exact).
const INCH: f64 = 0.0254;

/// The kind of quantity a `[UNITS]` key names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitKind {
    /// `LENGTH`: radii, deflections, widths (SI: m).
    Length,
    /// `FORCE`: loads and force scalings such as FNOMIN, FZMIN (SI: N).
    Force,
    /// `ANGLE`: slip and inclination limits ALPMIN…CAMMAX, angular
    /// stiffnesses (SI: rad).
    Angle,
    /// `MASS`: tyre, belt and rim masses and inertias (SI: kg).
    Mass,
    /// `TIME`: integration settings (HMAX_LOCAL, TIME_SWITCH_INTEG) and the
    /// time part of speeds, damping, frequencies (SI: s).
    Time,
    /// `PRESSURE`: INFLPRES, NOMPRES, pressure limits (SI: Pa); not an
    /// ADAMS key, honoured when present.
    Pressure,
}

impl UnitKind {
    /// The `[UNITS]` key of this kind (`LENGTH`, `FORCE`, …).
    pub fn key(self) -> &'static str {
        match self {
            UnitKind::Length => "LENGTH",
            UnitKind::Force => "FORCE",
            UnitKind::Angle => "ANGLE",
            UnitKind::Mass => "MASS",
            UnitKind::Time => "TIME",
            UnitKind::Pressure => "PRESSURE",
        }
    }

    /// Every kind, in the order the writer puts them in `[UNITS]`.
    pub const ALL: [UnitKind; 6] = [
        UnitKind::Length,
        UnitKind::Force,
        UnitKind::Angle,
        UnitKind::Mass,
        UnitKind::Time,
        UnitKind::Pressure,
    ];

    /// The kind named by a `[UNITS]` key (case-insensitive).
    pub fn from_key(key: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.key().eq_ignore_ascii_case(key))
    }

    /// The SI unit name the writer puts in `[UNITS]`.
    pub fn si_name(self) -> &'static str {
        match self {
            UnitKind::Length => "meter",
            UnitKind::Force => "newton",
            UnitKind::Angle => "radians",
            UnitKind::Mass => "kg",
            UnitKind::Time => "second",
            UnitKind::Pressure => "pascal",
        }
    }

    /// Unit names this kind accepts, for error messages.
    pub fn accepted(self) -> &'static str {
        match self {
            UnitKind::Length => "mm, cm, m/meter/metre, km, mile, inch/in, ft/foot",
            UnitKind::Force => {
                "N/newton, kN, mN, lbf/pound_force, kpound_force, ounce_force, kgf, dyne"
            }
            UnitKind::Angle => "rad/radian/radians, deg/degree/degrees",
            UnitKind::Mass => "kg, g, lbm/pound_mass, kpound_mass, ounce_mass, slug, tonne",
            UnitKind::Time => "s/sec/second, ms/milli, min, h/hour",
            UnitKind::Pressure => "Pa/pascal, kPa, MPa, bar, psi",
        }
    }

    /// SI factor of a unit name of this kind (case-insensitive, blanks and a
    /// plural `s` tolerated), or `None` if the name is not known.
    pub fn factor(self, unit: &str) -> Option<f64> {
        let u = unit.trim().to_ascii_lowercase();
        let u = u.as_str();
        let f = match self {
            UnitKind::Length => match u {
                "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => 1e-3,
                "cm" | "centimeter" | "centimeters" | "centimetre" | "centimetres" => 1e-2,
                "m" | "meter" | "meters" | "metre" | "metres" => 1.0,
                "km" | "kilometer" | "kilometers" | "kilometre" | "kilometres" => 1e3,
                "mile" | "miles" => 5280.0 * 12.0 * INCH,
                "in" | "inch" | "inches" => INCH,
                "ft" | "foot" | "feet" => 12.0 * INCH,
                _ => return None,
            },
            UnitKind::Force => match u {
                "n" | "newton" | "newtons" => 1.0,
                "kn" | "kilonewton" | "kilonewtons" => 1e3,
                "lbf" | "pound_force" | "pounds_force" | "lb" | "lbs" => LBF,
                "kpound_force" | "kip" | "kips" => 1e3 * LBF,
                "ounce_force" | "ozf" => LBF / 16.0,
                "kgf" | "kilogram_force" | "kp" => 9.806_65,
                "millinewton" | "millinewtons" | "mn" => 1e-3,
                "dyne" | "dynes" => 1e-5,
                _ => return None,
            },
            UnitKind::Angle => match u {
                "rad" | "radian" | "radians" => 1.0,
                "deg" | "degree" | "degrees" => std::f64::consts::PI / 180.0,
                _ => return None,
            },
            UnitKind::Mass => match u {
                "kg" | "kilogram" | "kilograms" => 1.0,
                "g" | "gram" | "grams" => 1e-3,
                "lbm" | "pound_mass" | "pounds_mass" => 0.453_592_37,
                "kpound_mass" => 453.592_37,
                "ounce_mass" | "ounce" | "oz" => 0.453_592_37 / 16.0,
                "tonne" | "tonnes" | "t" | "metric_ton" => 1e3,
                "slug" | "slugs" => LBF / (12.0 * INCH),
                _ => return None,
            },
            UnitKind::Time => match u {
                "s" | "sec" | "secs" | "second" | "seconds" => 1.0,
                "ms" | "milli" | "millisecond" | "milliseconds" => 1e-3,
                "min" | "minute" | "minutes" => 60.0,
                "h" | "hr" | "hour" | "hours" => 3600.0,
                _ => return None,
            },
            UnitKind::Pressure => match u {
                "pa" | "pascal" | "pascals" => 1.0,
                "kpa" | "kilopascal" | "kilopascals" => 1e3,
                "mpa" | "megapascal" | "megapascals" => 1e6,
                "bar" => 1e5,
                "psi" => LBF / (INCH * INCH),
                "atm" => 101_325.0,
                _ => return None,
            },
        };
        Some(f)
    }
}

/// SI factors of the five (six) base units of a file.
///
/// Unit names: those of the ADAMS tyre documentation ("Units Supported in
/// Tire Property Files": METER, MM, CM, KM, MILE, FOOT, IN; NEWTON, POUND_FORCE,
/// KPOUND_FORCE, KILOGRAM_FORCE, OUNCE_FORCE, DYNE; KG, GRAM, POUND_MASS,
/// KPOUND_MASS, SLUG, OUNCE_MASS; SEC, MILLI, MIN, HOUR; RAD, DEG) and the
/// usual spellings found in files (`'newton'`, `'Newton'`, `'radians'`,
/// `'second'`, `'pascal'`, …), case-insensitive. `PRESSURE` is not an ADAMS
/// unit key but appears in files (`'pascal'`, `'Pascal'`) and is honoured.
///
/// Pressure: when `[UNITS]` names no `PRESSURE`, pressures are taken in
/// FORCE/LENGTH² as ADAMS does (Pa for an SI file, N/mm² = MPa for an
/// `mm`/`newton` file).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    /// Metres per file `LENGTH` unit.
    pub length: f64,
    /// Newtons per file `FORCE` unit.
    pub force: f64,
    /// Radians per file `ANGLE` unit.
    pub angle: f64,
    /// Kilograms per file `MASS` unit.
    pub mass: f64,
    /// Seconds per file `TIME` unit.
    pub time: f64,
    /// `None`: derived from force / length².
    pub pressure: Option<f64>,
}

impl Default for Units {
    fn default() -> Self {
        Units::SI
    }
}

impl Units {
    /// SI: every factor 1.
    pub const SI: Units = Units {
        length: 1.0,
        force: 1.0,
        angle: 1.0,
        mass: 1.0,
        time: 1.0,
        pressure: None,
    };

    /// Set the factor of one kind.
    pub fn set(&mut self, kind: UnitKind, factor: f64) {
        match kind {
            UnitKind::Length => self.length = factor,
            UnitKind::Force => self.force = factor,
            UnitKind::Angle => self.angle = factor,
            UnitKind::Mass => self.mass = factor,
            UnitKind::Time => self.time = factor,
            UnitKind::Pressure => self.pressure = Some(factor),
        }
    }

    /// Whether every factor is exactly 1 (nothing to convert).
    pub fn is_si(&self) -> bool {
        Dim::ALL.iter().all(|&d| self.factor(d) == 1.0)
    }

    /// Factor from file units to SI for a value of dimension `dim`.
    pub fn factor(&self, dim: Dim) -> f64 {
        let (l, f, a, m, t) = (self.length, self.force, self.angle, self.mass, self.time);
        match dim {
            Dim::One => 1.0,
            Dim::Length => l,
            Dim::Force => f,
            Dim::Angle => a,
            Dim::Mass => m,
            Dim::Time => t,
            Dim::Pressure => self.pressure.unwrap_or(f / (l * l)),
            Dim::Speed => l / t,
            Dim::Stiffness => f / l,
            Dim::Damping => f * t / l,
            Dim::TorsionStiffness => f * l / a,
            Dim::Inertia => m * l * l,
            Dim::Acceleration => l / (t * t),
            Dim::Frequency => 1.0 / t,
        }
    }

    /// Convert a file value of dimension `dim` to SI. A factor of exactly 1
    /// leaves the value bit-identical.
    pub fn to_si(&self, dim: Dim, value: f64) -> f64 {
        let f = self.factor(dim);
        if f == 1.0 {
            value
        } else {
            value * f
        }
    }
}

impl Dim {
    /// Every dimension, for exhaustive checks.
    pub const ALL: [Dim; 14] = [
        Dim::One,
        Dim::Length,
        Dim::Force,
        Dim::Angle,
        Dim::Mass,
        Dim::Time,
        Dim::Pressure,
        Dim::Speed,
        Dim::Stiffness,
        Dim::Damping,
        Dim::TorsionStiffness,
        Dim::Inertia,
        Dim::Acceleration,
        Dim::Frequency,
    ];
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_case_insensitive() {
        assert_eq!(UnitKind::Force.factor("Newton"), Some(1.0));
        assert_eq!(UnitKind::Pressure.factor("Pascal"), Some(1.0));
        assert_eq!(UnitKind::Angle.factor("radian"), Some(1.0));
        assert_eq!(UnitKind::Length.factor("furlong"), None);
        // 1 psi = 6894.757 Pa (NIST SP 811 table B.8: 6.894 757 E+03).
        let psi = UnitKind::Pressure.factor("psi").unwrap();
        assert!((psi - 6894.757).abs() < 1e-3);
    }

    #[test]
    fn derived_dimensions() {
        let mut u = Units::SI;
        u.set(UnitKind::Length, 1e-3);
        u.set(UnitKind::Force, 1e3);
        // kN/mm = 1e6 N/m
        assert!((u.factor(Dim::Stiffness) - 1e6).abs() < 1e-6);
        // no PRESSURE key: kN/mm² = 1e9 Pa
        assert!((u.factor(Dim::Pressure) - 1e9).abs() < 1e-3);
        assert!(!u.is_si());
        assert!(Units::SI.is_si());
    }
}
