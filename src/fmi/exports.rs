//! exports — the 34 FMI 2.0 co-simulation functions of the shared library.
//!
//! Each is a thin wrapper: check the pointers, check the FMI state against the
//! calling-sequence table, run the work inside `catch_unwind`, turn a refused
//! call into fmi2Error with a logged message (naming the function) and a panic
//! into fmi2Fatal. The work itself lives in [`super::instance`] and
//! [`super::snapshot`].
//! Must never: unwind into the master, dereference a null pointer, or trust a
//! count/pointer pair it can check.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::instance::{allowed, phases_in, Instance, Phase, INSTANCE_TAG};
use super::logging::{Category, Logger};
use super::snapshot::{self, Snapshot, SNAPSHOT_TAG};
use super::types::*;
use super::vars;
use std::ffi::CStr;
use std::os::raw::{c_char, c_int};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The live instance behind a component pointer, if it looks like one.
unsafe fn instance<'a>(c: fmi2Component) -> Option<&'a mut Instance> {
    if c.is_null() {
        return None;
    }
    let inst = &mut *(c as *mut Instance);
    (inst.tag == INSTANCE_TAG).then_some(inst)
}

/// A C array as a slice (`n == 0` → empty; a null pointer with `n > 0` → error).
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err(format!("{what} is NULL but {n} values were announced"))
    } else {
        Ok(std::slice::from_raw_parts(p, n))
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if p.is_null() {
        Err(format!("{what} is NULL but {n} values were announced"))
    } else {
        Ok(std::slice::from_raw_parts_mut(p, n))
    }
}

/// A C string argument as UTF-8.
unsafe fn text<'a>(p: fmi2String, what: &str) -> Result<&'a str, String> {
    if p.is_null() {
        return Err(format!("{what} is NULL"));
    }
    CStr::from_ptr(p)
        .to_str()
        .map_err(|_| format!("{what} is not valid UTF-8"))
}

/// Run `work` on the instance behind `c` if the FMI state allows `fname` there.
/// Errors are logged as "fname: message" and answered with fmi2Error; a panic
/// puts the instance in the fatal state and answers fmi2Fatal.
unsafe fn guarded(
    c: fmi2Component,
    fname: &'static str,
    mask: u8,
    work: impl FnOnce(&mut Instance) -> Result<Fmi2Status, String>,
) -> Fmi2Status {
    let Some(inst) = instance(c) else {
        return Fmi2Status::Error;
    };
    let result = catch_unwind(AssertUnwindSafe(|| {
        let phase = inst.sim.phase;
        if mask & phase.bit() == 0 {
            inst.log.status(
                Fmi2Status::Error,
                &format!(
                    "{fname}: not allowed in state {} (allowed in: {})",
                    phase.name(),
                    if mask == 0 {
                        "no state of this FMU".to_string()
                    } else {
                        phases_in(mask)
                    }
                ),
            );
            return Fmi2Status::Error;
        }
        if inst.log.wants(Category::All) {
            inst.log.log(
                Fmi2Status::Ok,
                Category::All,
                &format!("{fname} (state {}, t = {})", phase.name(), inst.sim.time),
            );
        }
        match work(inst) {
            Ok(s) => s,
            Err(msg) => {
                inst.log
                    .status(Fmi2Status::Error, &format!("{fname}: {msg}"));
                Fmi2Status::Error
            }
        }
    }));
    match result {
        Ok(s) => s,
        Err(payload) => {
            let why = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            if let Some(inst) = instance(c) {
                inst.sim.phase = Phase::Fatal;
                let _ = catch_unwind(AssertUnwindSafe(|| {
                    inst.log.status(
                        Fmi2Status::Fatal,
                        &format!("{fname}: internal failure ({why}); free this instance"),
                    )
                }));
            }
            Fmi2Status::Fatal
        }
    }
}

/// FMI 2.0 §2.1.4: the platform types of the headers the binary was built with,
/// always "default" (fmi2TypesPlatform.h). Refuses nothing.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// FMI 2.0 §2.1.4: the FMI version of the headers, always "2.0". Refuses nothing.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// FMI 2.0 §2.1.5: switch debug logging, or the named log categories, on or
/// off (see [`Logger::set_debug_logging`]). Allowed in every state; refuses an
/// unknown category name or a NULL/non-UTF-8 list entry, and then changes nothing.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> Fmi2Status {
    guarded(c, "fmi2SetDebugLogging", allowed::ANY, |inst| {
        let cats = slice(categories, n, "categories")?;
        let mut names = Vec::with_capacity(cats.len());
        for p in cats {
            names.push(text(*p, "category name")?);
        }
        inst.log.set_debug_logging(logging_on != 0, &names)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.5: create an instance and load the packaged resources/tyre.tir.
/// Returns NULL, the reason logged, for an empty instanceName, an `fmuType` other
/// than fmi2CoSimulation, a GUID not this binary's, a missing or unusable
/// fmuResourceLocation and an unusable tyre file. `visible` is ignored.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: fmi2String,
    fmu_type: c_int,
    guid: fmi2String,
    resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        let callbacks = if functions.is_null() {
            None
        } else {
            Some(*functions)
        };
        let name = if instance_name.is_null() {
            ""
        } else {
            CStr::from_ptr(instance_name).to_str().unwrap_or("")
        };
        let log = Logger::new(callbacks, name, logging_on != 0);
        let fail = |log: &Logger, msg: String| {
            log.status(Fmi2Status::Error, &format!("fmi2Instantiate: {msg}"));
            std::ptr::null_mut()
        };
        if instance_name.is_null() || name.is_empty() {
            return fail(&log, "instanceName must be a non-empty string".into());
        }
        if fmu_type != FMI2_CO_SIMULATION {
            return fail(
                &log,
                format!(
                    "fmuType {fmu_type} requested, this FMU supports co-simulation ({FMI2_CO_SIMULATION}) only"
                ),
            );
        }
        let g = match text(guid, "fmuGUID") {
            Ok(g) => g,
            Err(e) => return fail(&log, e),
        };
        if g != vars::GUID {
            return fail(
                &log,
                format!(
                    "GUID mismatch: the master passed {g}, this binary implements {} (modelDescription.xml and binary from different builds)",
                    vars::GUID
                ),
            );
        }
        let loc = if resource_location.is_null() {
            None
        } else {
            match CStr::from_ptr(resource_location).to_str() {
                Ok(s) => Some(s),
                Err(_) => return fail(&log, "fmuResourceLocation is not valid UTF-8".into()),
            }
        };
        match Instance::new(log, loc) {
            Ok(inst) => Box::into_raw(inst) as fmi2Component,
            Err((log, msg)) => fail(&log, msg),
        }
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// FMI 2.0 §2.1.5: free the instance and every FMU state it created that the
/// master did not free. NULL or a pointer that is not a live instance is ignored.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        if let Some(inst) = instance(c) {
            inst.event("freed");
            inst.tag = 0;
            // Every FMU state the master did not free goes with its instance
            // (each holds a copy of the simulation and a share of the tyre).
            for addr in std::mem::take(&mut inst.states) {
                let snap = addr as *mut Snapshot;
                if (*snap).tag == SNAPSHOT_TAG {
                    (*snap).tag = 0;
                    drop(Box::from_raw(snap));
                }
            }
            drop(Box::from_raw(c as *mut Instance));
        }
    }));
}

/// FMI 2.0 §2.1.6: set startTime (s, the first communication point) and
/// stopTime (s). `tolerance` is ignored (fixed-step model); only in the instantiated
/// state; refuses a non-finite startTime and a stopTime that is non-finite or
/// below startTime. stopTime is recorded, not enforced.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    _tolerance_defined: fmi2Boolean,
    _tolerance: fmi2Real,
    start_time: fmi2Real,
    stop_time_defined: fmi2Boolean,
    stop_time: fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2SetupExperiment", allowed::INSTANTIATED, |inst| {
        inst.setup_experiment(start_time, (stop_time_defined != 0).then_some(stop_time))?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.6: enter initialization mode (start values and parameters
/// may still be set). Only in the instantiated state.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> Fmi2Status {
    guarded(
        c,
        "fmi2EnterInitializationMode",
        allowed::INSTANTIATED,
        |inst| {
            inst.sim.phase = Phase::InitializationMode;
            inst.event("entered initialization mode");
            Ok(Fmi2Status::Ok)
        },
    )
}

/// FMI 2.0 §2.1.6: leave initialization mode for stepComplete after computing
/// the initial outputs. If the model refuses the parameters or inputs, answers
/// fmi2Error and enters the error state.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2ExitInitializationMode", allowed::INIT, |inst| {
        inst.exit_initialization()?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.6: end the simulation (terminated state; values remain
/// readable). Only in stepComplete.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2Terminate", allowed::STEP, |inst| {
        inst.sim.phase = Phase::Terminated;
        inst.event("terminated");
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.6: back to the state right after fmi2Instantiate (start values,
/// the packaged tyre). Refused only in the fatal state.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2Reset", allowed::ALL_LIVE, |inst| {
        inst.reset()?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: read Real variables (SI units as the XML declares them). In
/// initialization mode the outputs are computed first. Refuses an unknown or
/// non-Real value reference and a NULL array with `nvr > 0`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2GetReal", allowed::GET, |inst| {
        inst.get_real(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: read Integer variables (`use_mode`). Refuses an unknown or
/// non-Integer value reference and a NULL array with `nvr > 0`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> Fmi2Status {
    guarded(c, "fmi2GetInteger", allowed::GET, |inst| {
        inst.get_integer(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: read Boolean variables (`contact`, `nonlinear`,
/// `mirrored`). Refuses an unknown or non-Boolean value reference and a NULL
/// array with `nvr > 0`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> Fmi2Status {
    guarded(c, "fmi2GetBoolean", allowed::GET, |inst| {
        inst.get_boolean(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: read String variables; the pointers stay valid until the
/// next call on this instance. Refuses an unknown or non-String value reference and
/// a NULL array with `nvr > 0`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> Fmi2Status {
    guarded(c, "fmi2GetString", allowed::GET, |inst| {
        inst.get_string(slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: write Real inputs (SI units); every value is checked before
/// any is stored. Refuses unknown or non-Real value references, outputs and
/// calculated parameters, non-finite values, values outside the XML's min/max and
/// a pressure `p` in (0, [`P_MIN`](super::instance::P_MIN)) Pa.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2SetReal", allowed::SET, |inst| {
        inst.set_real(slice(vr, nvr, "vr")?, slice(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: write Integer parameters (`use_mode`), validated as they are
/// set. Refuses unknown or non-Integer value references, outputs and calculated
/// parameters, fixed parameters after initialization and invalid values (value
/// not taken).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> Fmi2Status {
    guarded(c, "fmi2SetInteger", allowed::SET, |inst| {
        inst.set_integer(slice(vr, nvr, "vr")?, slice(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: write Boolean parameters (`nonlinear`). Refuses unknown or
/// non-Boolean value references, outputs (`contact`) and calculated parameters
/// (`mirrored`), and fixed parameters after initialization.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> Fmi2Status {
    guarded(c, "fmi2SetBoolean", allowed::SET, |inst| {
        inst.set_boolean(slice(vr, nvr, "vr")?, slice(value, nvr, "value")?)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.7: write String parameters (`tyre_file` loads the file;
/// `input_mode`, `transient`, `side`, `force_model` are validated as set). Refuses
/// unknown or non-String value references, fixed parameters after initialization,
/// NULL or non-UTF-8 text, invalid values and unloadable tyre files (value not
/// taken).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> Fmi2Status {
    guarded(c, "fmi2SetString", allowed::SET, |inst| {
        let vrs = slice(vr, nvr, "vr")?;
        let vals = slice(value, nvr, "value")?;
        for (r, v) in vrs.iter().zip(vals) {
            inst.set_string(*r, text(*v, "string value")?)?;
        }
        Ok(Fmi2Status::Ok)
    })
}

/// The snapshot behind an fmi2FMUstate, if it looks like one.
unsafe fn snapshot_ref<'a>(s: fmi2FMUstate) -> Result<&'a Snapshot, String> {
    if s.is_null() {
        return Err("FMUstate is NULL".into());
    }
    let snap = &*(s as *const Snapshot);
    if snap.tag != SNAPSHOT_TAG {
        return Err("FMUstate was not created by this FMU (or was freed)".into());
    }
    Ok(snap)
}

/// FMI 2.0 §2.1.8: copy the instance's complete state into a new FMU state
/// (`*state` NULL) or into the given one. Refused in the fatal state, for a NULL
/// `state` pointer and for a `*state` that is not a live FMU state.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> Fmi2Status {
    guarded(c, "fmi2GetFMUstate", allowed::ALL_LIVE, |inst| {
        if state.is_null() {
            return Err("FMUstate pointer is NULL".into());
        }
        if (*state).is_null() {
            let snap = Box::new(Snapshot {
                tag: SNAPSHOT_TAG,
                sim: inst.sim.clone(),
                owner: c as usize,
            });
            let p = Box::into_raw(snap);
            inst.states.push(p as usize);
            *state = p as fmi2FMUstate;
        } else {
            snapshot_ref(*state)?;
            let snap = &mut *(*state as *mut Snapshot);
            snap.sim.clone_from(&inst.sim);
        }
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.8: restore the instance to a saved FMU state. Refused in the
/// fatal state, for NULL or a pointer that is not a live FMU state, and for a
/// state inconsistent with its own parameters.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> Fmi2Status {
    guarded(c, "fmi2SetFMUstate", allowed::ALL_LIVE, |inst| {
        let snap = snapshot_ref(state)?;
        inst.restore(&snap.sim)?;
        inst.event(&format!("FMU state restored (t = {})", inst.sim.time));
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.8: free an FMU state and set `*state` to NULL (NULL is a no-op).
/// Refuses a state created by another instance.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> Fmi2Status {
    guarded(c, "fmi2FreeFMUstate", allowed::ALL_LIVE, |inst| {
        if state.is_null() || (*state).is_null() {
            return Ok(Fmi2Status::Ok);
        }
        let owner = snapshot_ref(*state)?.owner;
        if owner != c as usize {
            return Err("FMUstate belongs to another instance; free it with that one".into());
        }
        let addr = *state as usize;
        inst.states.retain(|&a| a != addr);
        let mut snap = Box::from_raw(*state as *mut Snapshot);
        snap.tag = 0;
        drop(snap);
        *state = std::ptr::null_mut();
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.8: the number of bytes fmi2SerializeFMUstate will write for
/// this state. Refuses a NULL or non-live state and a NULL `size` pointer.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> Fmi2Status {
    guarded(
        c,
        "fmi2SerializedFMUstateSize",
        allowed::ALL_LIVE,
        |_inst| {
            let snap = snapshot_ref(state)?;
            if size.is_null() {
                return Err("size pointer is NULL".into());
            }
            *size = snapshot::serialize(&snap.sim).len();
            Ok(Fmi2Status::Ok)
        },
    )
}

/// FMI 2.0 §2.1.8: write the state as bytes (format: [`super::snapshot`]).
/// Refuses a non-live state and a buffer smaller than
/// fmi2SerializedFMUstateSize.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> Fmi2Status {
    guarded(c, "fmi2SerializeFMUstate", allowed::ALL_LIVE, |_inst| {
        let snap = snapshot_ref(state)?;
        let data = snapshot::serialize(&snap.sim);
        if size < data.len() {
            return Err(format!(
                "buffer of {size} bytes is too small, {} needed (fmi2SerializedFMUstateSize)",
                data.len()
            ));
        }
        let out = slice_mut(bytes as *mut u8, data.len(), "serializedState")?;
        out.copy_from_slice(&data);
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.8: rebuild an FMU state from bytes of fmi2SerializeFMUstate.
/// Refuses a NULL `state` pointer, a buffer that fails any check (magic, version,
/// length, GUID, checksum, values) and one saved with a tyre other than the
/// instance's current or packaged one; never opens a file.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> Fmi2Status {
    guarded(c, "fmi2DeSerializeFMUstate", allowed::ALL_LIVE, |inst| {
        if state.is_null() {
            return Err("FMUstate pointer is NULL".into());
        }
        let data = slice(bytes as *const u8, size, "serializedState")?;
        let sim = snapshot::deserialize(inst, data)?;
        if (*state).is_null() {
            let p = Box::into_raw(Box::new(Snapshot {
                tag: SNAPSHOT_TAG,
                sim,
                owner: c as usize,
            }));
            inst.states.push(p as usize);
            *state = p as fmi2FMUstate;
        } else {
            snapshot_ref(*state)?;
            (*(*state as *mut Snapshot)).sim = sim;
        }
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §2.1.9: partial derivatives of outputs with respect to inputs.
/// Always refused (`providesDirectionalDerivative = false`).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    _v_unknown: *const fmi2ValueReference,
    _n_unknown: usize,
    _v_known: *const fmi2ValueReference,
    _n_known: usize,
    _dv_known: *const fmi2Real,
    _dv_unknown: *mut fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2GetDirectionalDerivative", allowed::GET, |_| {
        Err("not provided (providesDirectionalDerivative = false)".into())
    })
}

/// FMI 2.0 §4.2.1: time derivatives of inputs for interpolation over a step.
/// Always refused (`canInterpolateInputs = false`: inputs are held constant).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *const fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2SetRealInputDerivatives", allowed::SET, |_| {
        Err(
            "not supported (canInterpolateInputs = false): inputs are held constant over a step"
                .into(),
        )
    })
}

/// FMI 2.0 §4.2.1: time derivatives of outputs at the communication point.
/// Always refused (`maxOutputDerivativeOrder = 0`).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> Fmi2Status {
    guarded(
        c,
        "fmi2GetRealOutputDerivatives",
        allowed::OUTPUT_DERIVATIVES,
        |_| Err("not supported (maxOutputDerivativeOrder = 0)".into()),
    )
}

/// FMI 2.0 §4.2.2: advance by `communicationStepSize` (s) with the inputs held
/// constant, synchronously (never fmi2Pending). Only in stepComplete; refuses a
/// step size that is not finite and > 0, a `currentCommunicationPoint` other than
/// the FMU's time, out-of-range inputs, Fz above
/// [`fz_limit`](super::instance::fz_limit) and a model failure, changing nothing.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    current_communication_point: fmi2Real,
    communication_step_size: fmi2Real,
    _no_set_fmu_state_prior: fmi2Boolean,
) -> Fmi2Status {
    guarded(c, "fmi2DoStep", allowed::STEP, |inst| {
        inst.do_step(current_communication_point, communication_step_size)?;
        Ok(Fmi2Status::Ok)
    })
}

/// FMI 2.0 §4.2.2: cancel an asynchronous step. Refused in every state: steps
/// are synchronous, so none is ever in progress.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> Fmi2Status {
    // Steps are synchronous: there is never a step in progress to cancel.
    guarded(c, "fmi2CancelStep", allowed::NONE, |_| {
        Ok(Fmi2Status::Error)
    })
}

/// A status that is not available: fmi2Discard with a warning.
fn not_available(inst: &Instance, what: &str, kind: fmi2StatusKind) -> Result<Fmi2Status, String> {
    inst.log.status(
        Fmi2Status::Warning,
        &format!("{what}: status kind {kind} is not available (steps are synchronous)"),
    );
    Ok(Fmi2Status::Discard)
}

/// FMI 2.0 §4.2.3: the fmi2Status of an asynchronous step (fmi2DoStepStatus).
/// Answers fmi2Discard with a warning for every kind (steps are synchronous);
/// refuses a NULL `value`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut Fmi2Status,
) -> Fmi2Status {
    guarded(c, "fmi2GetStatus", allowed::STATUS, |inst| {
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        not_available(inst, "fmi2GetStatus", kind)
    })
}

/// FMI 2.0 §4.2.3: for fmi2LastSuccessfulTime, the time (s) the FMU last
/// stepped to; fmi2Discard with a warning for other kinds; refuses a NULL `value`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2GetRealStatus", allowed::STATUS, |inst| {
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        if kind == FMI2_LAST_SUCCESSFUL_TIME {
            *value = inst.sim.time;
            return Ok(Fmi2Status::Ok);
        }
        not_available(inst, "fmi2GetRealStatus", kind)
    })
}

/// FMI 2.0 §4.2.3: an Integer status; none is defined, so fmi2Discard with a
/// warning for every kind; refuses a NULL `value`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> Fmi2Status {
    guarded(c, "fmi2GetIntegerStatus", allowed::STATUS, |inst| {
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        not_available(inst, "fmi2GetIntegerStatus", kind)
    })
}

/// FMI 2.0 §4.2.3: for fmi2Terminated, always fmi2False (the FMU never ends a
/// simulation by itself); fmi2Discard with a warning for other kinds; refuses a
/// NULL `value`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> Fmi2Status {
    guarded(c, "fmi2GetBooleanStatus", allowed::STATUS, |inst| {
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        if kind == FMI2_TERMINATED {
            // The FMU never ends a simulation by itself.
            *value = FMI2_FALSE;
            return Ok(Fmi2Status::Ok);
        }
        not_available(inst, "fmi2GetBooleanStatus", kind)
    })
}

/// FMI 2.0 §4.2.3: the fmi2PendingStatus text of an asynchronous step;
/// fmi2Discard with a warning for every kind (steps are synchronous); refuses a
/// NULL `value`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2String,
) -> Fmi2Status {
    guarded(c, "fmi2GetStringStatus", allowed::STATUS, |inst| {
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        not_available(inst, "fmi2GetStringStatus", kind)
    })
}
