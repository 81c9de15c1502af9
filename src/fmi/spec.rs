//! spec — the FMU variables the Rust code binds to, as (name, type, causality).
//!
//! `build.rs` includes this file and refuses to build when
//! `modelDescription/modelDescription.xml` declares a variable that is not
//! listed here, misses one that is, or gives it another type or causality:
//! the XML and the code cannot drift apart.
//! Must never: depend on anything (build.rs compiles it on its own).

/// Every variable of the interface: (name, base type, causality).
pub const BOUND_VARIABLES: &[(&str, &str, &str)] = &[
    // inputs
    ("vx", "Real", "input"),
    ("vy", "Real", "input"),
    ("omega", "Real", "input"),
    ("Fz", "Real", "input"),
    ("gamma", "Real", "input"),
    ("p", "Real", "input"),
    ("phit", "Real", "input"),
    ("mu_scale", "Real", "input"),
    ("kappa_in", "Real", "input"),
    ("alpha_in", "Real", "input"),
    // outputs
    ("Fx", "Real", "output"),
    ("Fy", "Real", "output"),
    ("Mx", "Real", "output"),
    ("My", "Real", "output"),
    ("Mz", "Real", "output"),
    ("kappa", "Real", "output"),
    ("alpha", "Real", "output"),
    ("Re", "Real", "output"),
    ("mux", "Real", "output"),
    ("muy", "Real", "output"),
    ("Vsx", "Real", "output"),
    ("Vsy", "Real", "output"),
    ("sigma_x", "Real", "output"),
    ("sigma_y", "Real", "output"),
    ("contact", "Boolean", "output"),
    // parameters
    ("tyre_file", "String", "parameter"),
    ("input_mode", "String", "parameter"),
    ("transient", "String", "parameter"),
    ("use_mode", "Integer", "parameter"),
    ("side", "String", "parameter"),
    ("nonlinear", "Boolean", "parameter"),
    ("force_model", "String", "parameter"),
    // calculated parameters
    ("R0", "Real", "calculatedParameter"),
    ("Fz0", "Real", "calculatedParameter"),
    ("p0", "Real", "calculatedParameter"),
    ("mirrored", "Boolean", "calculatedParameter"),
];

/// Inputs whose start value follows the packaged tyre (`fmi::start`): the XML
/// holds the built-in tyre's value, `tyrekit package` writes the packaged
/// tyre's, and the GUID (build.rs) does not cover these start values, so one
/// library serves every packaged tyre.
pub const TYRE_DEPENDENT_STARTS: &[&str] = &["Fz", "omega"];

/// Log categories the code sends messages with (must be declared in `<LogCategories>`).
pub const LOG_CATEGORIES: &[&str] = &[
    "logEvents",
    "logStatusWarning",
    "logStatusError",
    "logStatusFatal",
    "logAll",
];

/// Parameters whose start value `tyrekit package` chooses (`--force-model`),
/// with the values it may write. Like [`TYRE_DEPENDENT_STARTS`] the GUID
/// (build.rs) leaves these start values out, so one library serves every
/// packaging; the instance reads the chosen value from the packaged
/// modelDescription.xml beside its resources folder (`fmi::start`).
pub const CHOSEN_STARTS: &[(&str, &[&str])] = &[("force_model", &["mf", "brush"])];
