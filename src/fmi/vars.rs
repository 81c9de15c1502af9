//! vars — the FMU's variables: the table `build.rs` generates from
//! `modelDescription/modelDescription.xml` (value references, storage slots,
//! start values, the GUID and the XML text itself) and typed storage for them.
//! Must never: be edited by hand to add a variable (edit the XML and spec.rs),
//! or allocate when a value is read or written.

use std::ffi::CString;

/// FMI base type of a variable (the child element of `<ScalarVariable>`,
/// FMI 2.0 §2.2.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    /// `<Real>`: an `fmi2Real` (f64), read/written by fmi2GetReal/fmi2SetReal.
    Real,
    /// `<Integer>`: an `fmi2Integer` (i32).
    Integer,
    /// `<Boolean>`: an `fmi2Boolean` (stored as `bool`).
    Boolean,
    /// `<String>`: an `fmi2String` (stored NUL-terminated).
    String,
}

impl VarType {
    /// The XML element name.
    pub fn name(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        }
    }
}

/// FMI causality (FMI 2.0 §2.2.7; only those the interface uses).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// `input`: set by the master before each step (wheel motion, load, pressure, …).
    Input,
    /// `output`: computed by the step (forces, moments, slips, …).
    Output,
    /// `parameter`: set by the master before initialization (tyre file, modes).
    Parameter,
    /// `calculatedParameter`: computed from the parameters and the tyre file
    /// (e.g. its unloaded radius and nominal load).
    CalculatedParameter,
}

/// FMI variability (FMI 2.0 §2.2.7): when a variable's value may change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    /// `constant`: never changes.
    Constant,
    /// `fixed`: fixed after initialization (fmi2ExitInitializationMode).
    Fixed,
    /// `tunable`: may change between communication points, set by the master.
    Tunable,
    /// `discrete`: changes only at communication points.
    Discrete,
    /// `continuous`: a Real that may change continuously in time.
    Continuous,
}

/// Start value from the XML.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    /// No `start` attribute (calculated variables start at 0 / false / "").
    None,
    /// `start` of a Real, in the variable's unit (SI).
    Real(f64),
    /// `start` of an Integer.
    Integer(i32),
    /// `start` of a Boolean.
    Boolean(bool),
    /// `start` of a String.
    String(&'static str),
}

/// One row of the generated variable table.
#[derive(Clone, Copy, Debug)]
pub struct VarInfo {
    /// `valueReference`: the number the master passes to fmi2Get*/fmi2Set*.
    pub vr: u32,
    /// `name` (e.g. `Fz`, `tyre_file`).
    pub name: &'static str,
    /// Base type: which storage array and getter/setter it belongs to.
    pub ty: VarType,
    /// Index into the storage array of its type.
    pub slot: usize,
    /// `causality`.
    pub causality: Causality,
    /// `variability`.
    pub variability: Variability,
    /// `start` value.
    pub start: Start,
    /// `unit` of a Real as the XML writes it (SI: "N", "N.m", "m/s", "rad", "1";
    /// "" when none).
    pub unit: &'static str,
    /// Hard lower limit of a Real (`min` of the XML; −inf when none).
    pub min: f64,
    /// Hard upper limit of a Real (`max` of the XML; +inf when none).
    pub max: f64,
    /// `description`: one line for the master's user.
    pub description: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/fmi_vars.rs"));

/// The variable with value reference `vr`, if any.
#[inline]
pub fn lookup(vr: u32) -> Option<&'static VarInfo> {
    let i = *VR_TABLE.get(vr as usize)?;
    VARIABLES.get(i as usize)
}

/// The variable called `name`, if any.
pub fn by_name(name: &str) -> Option<&'static VarInfo> {
    VARIABLES.iter().find(|v| v.name == name)
}

/// Typed storage of every variable's current value.
#[derive(Clone, Debug, PartialEq)]
pub struct Values {
    /// Real values by slot ([`real`]), SI units.
    pub reals: [f64; real::N],
    /// Integer values by slot ([`integer`]).
    pub integers: [i32; integer::N],
    /// Boolean values by slot ([`boolean`]).
    pub booleans: [bool; boolean::N],
    /// NUL-terminated so that fmi2GetString can hand out pointers into them.
    pub strings: [CString; string::N],
}

impl Values {
    /// Every variable at its start value (calculated ones at 0 / false / "").
    pub fn start() -> Values {
        let mut v = Values {
            reals: [0.0; real::N],
            integers: [0; integer::N],
            booleans: [false; boolean::N],
            strings: std::array::from_fn(|_| CString::default()),
        };
        for info in VARIABLES.iter() {
            match info.start {
                Start::Real(x) => v.reals[info.slot] = x,
                Start::Integer(x) => v.integers[info.slot] = x,
                Start::Boolean(x) => v.booleans[info.slot] = x,
                // Start strings come from the XML, which build.rs parsed: no NUL inside.
                Start::String(s) => v.strings[info.slot] = CString::new(s).unwrap_or_default(),
                Start::None => {}
            }
        }
        v
    }

    /// A string variable as UTF-8 text (set through fmi2SetString, checked there).
    pub fn string(&self, slot: usize) -> &str {
        self.strings[slot].to_str().unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_consistent_with_lookup() {
        for (i, v) in VARIABLES.iter().enumerate() {
            let found = lookup(v.vr).expect("every declared vr resolves");
            assert_eq!(found.name, v.name, "row {i}");
        }
        assert!(lookup(u32::MAX).is_none());
        assert!(lookup(VR_TABLE.len() as u32).is_none());
    }

    #[test]
    fn guid_looks_like_a_guid() {
        assert_eq!(GUID.len(), 38);
        assert!(GUID.starts_with('{') && GUID.ends_with('}'));
        assert!(MODEL_DESCRIPTION_XML.contains(GUID));
        assert!(!MODEL_DESCRIPTION_XML.contains("@GUID@"));
    }

    #[test]
    fn start_values_come_from_the_xml() {
        let v = Values::start();
        assert_eq!(v.reals[real::MU_SCALE], 1.0);
        assert_eq!(
            v.reals[real::P],
            0.0,
            "p = 0 is the 'file INFLPRES' sentinel"
        );
        assert_eq!(v.integers[integer::USE_MODE], 111);
        assert_eq!(v.string(string::TRANSIENT), "file");
        assert_eq!(v.string(string::INPUT_MODE), "velocities");
    }
}
