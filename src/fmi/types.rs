//! types — the FMI 2.0 C types (fmi2TypesPlatform.h / fmi2FunctionTypes.h),
//! declared here as `#[repr(C)]` so the product build needs no bindgen/libclang
//! (the `fmi-sys` bindings generate them with bindgen at build time).
//! Must never: differ in layout from the standard headers.
#![allow(non_camel_case_types)]

use std::os::raw::{c_char, c_int, c_uint, c_void};

/// fmi2Component (FMI 2.0 §2.1.2): the opaque handle of one FMU instance that
/// fmi2Instantiate returns; here a `*mut Instance`.
pub type fmi2Component = *mut c_void;
/// fmi2ComponentEnvironment (§2.1.2): the master's opaque pointer, handed back
/// unchanged as the first argument of the logger and stepFinished callbacks.
pub type fmi2ComponentEnvironment = *mut c_void;
/// fmi2FMUstate (§2.1.2, §2.1.8): the opaque handle of a saved FMU state; here a
/// `*mut Snapshot`.
pub type fmi2FMUstate = *mut c_void;
/// fmi2ValueReference (§2.1.2): the `valueReference` of a variable in
/// modelDescription.xml (`unsigned int`).
pub type fmi2ValueReference = c_uint;
/// fmi2Real (§2.1.2): `double`.
pub type fmi2Real = f64;
/// fmi2Integer (§2.1.2): `int`.
pub type fmi2Integer = c_int;
/// fmi2Boolean (§2.1.2): `int`, [`FMI2_TRUE`] or [`FMI2_FALSE`].
pub type fmi2Boolean = c_int;
/// fmi2Char (§2.1.2): `char`, one byte of a UTF-8 string.
pub type fmi2Char = c_char;
/// fmi2String (§2.1.2): `const fmi2Char*`, a NUL-terminated UTF-8 string.
pub type fmi2String = *const fmi2Char;
/// fmi2Byte (§2.1.2): `char`, one byte of a serialized FMU state (§2.1.8).
pub type fmi2Byte = c_char;

/// fmi2True (fmi2TypesPlatform.h): 1.
pub const FMI2_TRUE: fmi2Boolean = 1;
/// fmi2False (fmi2TypesPlatform.h): 0.
pub const FMI2_FALSE: fmi2Boolean = 0;

/// fmi2Status (FMI 2.0 §2.1.3): the result of every FMI function (`OK` to
/// `Fatal` in order of severity).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Fmi2Status {
    /// fmi2OK: all well.
    Ok = 0,
    /// fmi2Warning: things are not quite right, but the computation can continue
    /// (the reason was logged).
    Warning = 1,
    /// fmi2Discard: the result is not usable (co-simulation: e.g. a status the
    /// slave cannot report, §4.2.3); the master decides whether to go on.
    Discard = 2,
    /// fmi2Error: the call failed (the reason was logged). This FMU leaves the
    /// instance as it was, so a later valid call works (a failed
    /// fmi2ExitInitializationMode excepted: it enters the error state).
    Error = 3,
    /// fmi2Fatal: the computations are irreparably corrupted; here answered
    /// when a panic was caught, after which only fmi2FreeInstance is useful.
    Fatal = 4,
    /// fmi2Pending: an asynchronous fmi2DoStep is still running (§4.2.2); never
    /// returned here, steps are synchronous.
    Pending = 5,
}

// fmi2Type (FMI 2.0 §2.1.5; passed to fmi2Instantiate as a C enum, i.e. an int).
/// fmi2ModelExchange: the `fmuType` of a model-exchange instance (refused by
/// this FMU).
pub const FMI2_MODEL_EXCHANGE: c_int = 0;
/// fmi2CoSimulation: the `fmuType` of a co-simulation instance, the only one
/// this FMU implements.
pub const FMI2_CO_SIMULATION: c_int = 1;

/// fmi2StatusKind (FMI 2.0 §4.2.3; a C enum, i.e. an int): which status
/// fmi2Get*Status reports.
pub type fmi2StatusKind = c_int;
/// fmi2DoStepStatus: status of an asynchronous fmi2DoStep (fmi2GetStatus).
pub const FMI2_DO_STEP_STATUS: fmi2StatusKind = 0;
/// fmi2PendingStatus: progress text of a pending step (fmi2GetStringStatus).
pub const FMI2_PENDING_STATUS: fmi2StatusKind = 1;
/// fmi2LastSuccessfulTime: time (s) the slave last stepped to successfully
/// (fmi2GetRealStatus).
pub const FMI2_LAST_SUCCESSFUL_TIME: fmi2StatusKind = 2;
/// fmi2Terminated: whether the slave wants the simulation ended
/// (fmi2GetBooleanStatus).
pub const FMI2_TERMINATED: fmi2StatusKind = 3;

/// fmi2CallbackLogger (FMI 2.0 §2.1.5): `(componentEnvironment, instanceName,
/// status, category, message, ...)`, printf-style and variadic; the FMU always
/// calls it with the format "%s" and one NUL-terminated argument, never with
/// user text as the format.
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        Fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;
/// fmi2CallbackAllocateMemory (§2.1.5): calloc-like `(nobj, size)`; never called
/// by this FMU (it allocates with Rust's allocator).
pub type fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>;
/// fmi2CallbackFreeMemory (§2.1.5): frees what allocateMemory returned; never
/// called by this FMU.
pub type fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(*mut c_void)>;
/// fmi2StepFinished (§2.1.5, §4.2.2): tells the master an asynchronous
/// fmi2DoStep has ended; may be null, never called here (steps are synchronous).
pub type fmi2StepFinished = Option<unsafe extern "C" fn(fmi2ComponentEnvironment, Fmi2Status)>;

/// fmi2CallbackFunctions (FMI 2.0 §2.1.5): the master's callbacks, passed to
/// fmi2Instantiate (field order and layout as in fmi2FunctionTypes.h).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct fmi2CallbackFunctions {
    /// Message sink for the instance ([`super::logging::Logger`]); may be null.
    pub logger: fmi2CallbackLogger,
    /// `allocateMemory` (unused here).
    pub allocate_memory: fmi2CallbackAllocateMemory,
    /// `freeMemory` (unused here).
    pub free_memory: fmi2CallbackFreeMemory,
    /// `stepFinished` (unused here: steps are synchronous).
    pub step_finished: fmi2StepFinished,
    /// `componentEnvironment`, passed back as the first argument of `logger`.
    pub component_environment: fmi2ComponentEnvironment,
}
