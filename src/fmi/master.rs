//! master — a minimal FMI 2.0 co-simulation importer over `dlopen`, as a
//! simulation tool would load the packaged FMU: unzip, `dlopen` the
//! `binaries/linux64/<id>.so`, resolve the functions, instantiate with a logger.
//! Used by `tyrekit demo` and the FMU benchmark (the real importers — fmpy,
//! fmi-sim, the `fmi` crate — are exercised by the tests).
//!
//! The logger: Rust cannot define a C-variadic function, so the callback is a
//! plain `extern "C"` function with the six arguments this FMU always passes
//! (format "%s" plus one string), cast to the variadic pointer type. That is
//! sound on the x86-64 System V ABI (variadic and fixed arguments travel in the
//! same registers) and only used with this FMU, which never passes another format.
//! Must never: be used as the product's FMI implementation (that is `exports`).

use super::types::*;
use crate::error::{Error, Result};
use std::ffi::{c_void, CStr, CString};
use std::os::raw::{c_char, c_int};
use std::path::{Path, PathBuf};

type FnInstantiate = unsafe extern "C" fn(
    fmi2String,
    c_int,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;
type FnComp = unsafe extern "C" fn(fmi2Component) -> Fmi2Status;
type FnFree = unsafe extern "C" fn(fmi2Component);
type FnSetup =
    unsafe extern "C" fn(fmi2Component, fmi2Boolean, f64, f64, fmi2Boolean, f64) -> Fmi2Status;
type FnReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *mut f64) -> Fmi2Status;
type FnSetRealT = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const f64) -> Fmi2Status;
type FnSetStr =
    unsafe extern "C" fn(fmi2Component, *const u32, usize, *const fmi2String) -> Fmi2Status;
type FnDoStep = unsafe extern "C" fn(fmi2Component, f64, f64, fmi2Boolean) -> Fmi2Status;

/// The FMI functions this master uses.
#[derive(Clone, Copy)]
pub struct Functions {
    pub instantiate: FnInstantiate,
    pub free_instance: FnFree,
    pub setup_experiment: FnSetup,
    pub enter_initialization_mode: FnComp,
    pub exit_initialization_mode: FnComp,
    pub terminate: FnComp,
    pub get_real: FnReal,
    pub set_real: FnSetRealT,
    pub set_string: FnSetStr,
    pub do_step: FnDoStep,
}

/// An unpacked, loaded FMU.
pub struct Fmu {
    handle: *mut c_void,
    pub f: Functions,
    pub dir: PathBuf,
    pub guid: String,
}

/// Logger callback (see the module header for why it is not variadic).
unsafe extern "C" fn print_logger(
    _env: fmi2ComponentEnvironment,
    instance: fmi2String,
    status: Fmi2Status,
    category: fmi2String,
    format: fmi2String,
    arg: fmi2String,
) {
    let s = |p: fmi2String| {
        if p.is_null() {
            String::new()
        } else {
            CStr::from_ptr(p).to_string_lossy().into_owned()
        }
    };
    let msg = if s(format) == "%s" { s(arg) } else { s(format) };
    eprintln!("[{}] {:?} {}: {}", s(category), status, s(instance), msg);
}

/// Callbacks handed to fmi2Instantiate (no memory functions: the FMU declares
/// canNotUseMemoryManagementFunctions).
pub fn callbacks() -> fmi2CallbackFunctions {
    type Fixed = unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        Fmi2Status,
        fmi2String,
        fmi2String,
        fmi2String,
    );
    type Variadic = unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        Fmi2Status,
        fmi2String,
        fmi2String,
        ...
    );
    let f: Fixed = print_logger;
    fmi2CallbackFunctions {
        // SAFETY: see the module header (x86-64 SysV; the FMU always passes "%s" + one string).
        logger: Some(unsafe { std::mem::transmute::<Fixed, Variadic>(f) }),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: std::ptr::null_mut(),
    }
}

fn read_guid(xml: &str) -> Option<String> {
    let i = xml.find("guid=\"")? + 6;
    let j = xml[i..].find('"')?;
    Some(xml[i..i + j].to_string())
}

impl Fmu {
    /// Unzip `fmu` into `dir` and load its library.
    pub fn open(fmu: &Path, dir: &Path) -> Result<Fmu> {
        let file = std::fs::File::open(fmu).map_err(|e| Error::io(fmu, e))?;
        let mut zip = zip::ZipArchive::new(file)
            .map_err(|e| Error::Other(format!("{}: not an FMU archive: {e}", fmu.display())))?;
        let _ = std::fs::remove_dir_all(dir);
        zip.extract(dir)
            .map_err(|e| Error::Other(format!("unpacking {}: {e}", fmu.display())))?;
        let md_path = dir.join("modelDescription.xml");
        let xml = std::fs::read_to_string(&md_path).map_err(|e| Error::io(&md_path, e))?;
        let guid = read_guid(&xml)
            .ok_or_else(|| Error::Other("modelDescription.xml has no guid".into()))?;
        let id = super::MODEL_IDENTIFIER;
        let so = dir.join("binaries/linux64").join(format!("{id}.so"));
        let c_so = CString::new(so.to_string_lossy().as_bytes())
            .map_err(|_| Error::Other("path contains NUL".into()))?;
        // SAFETY: plain dlopen of a library path; symbols checked below.
        let handle = unsafe { libc::dlopen(c_so.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
        if handle.is_null() {
            // SAFETY: dlerror returns a static message or NULL.
            let why = unsafe {
                let e = libc::dlerror();
                if e.is_null() {
                    "unknown".into()
                } else {
                    CStr::from_ptr(e).to_string_lossy().into_owned()
                }
            };
            return Err(Error::Other(format!("dlopen {}: {why}", so.display())));
        }
        let sym = |name: &CStr| -> Result<*mut c_void> {
            // SAFETY: handle is live; name is NUL-terminated.
            let p = unsafe { libc::dlsym(handle, name.as_ptr()) };
            if p.is_null() {
                Err(Error::Other(format!(
                    "{}: missing {}",
                    so.display(),
                    name.to_string_lossy()
                )))
            } else {
                Ok(p)
            }
        };
        // SAFETY: each symbol is the FMI 2.0 function of that name and signature.
        let f = unsafe {
            Functions {
                instantiate: std::mem::transmute::<*mut c_void, FnInstantiate>(sym(
                    c"fmi2Instantiate",
                )?),
                free_instance: std::mem::transmute::<*mut c_void, FnFree>(sym(
                    c"fmi2FreeInstance",
                )?),
                setup_experiment: std::mem::transmute::<*mut c_void, FnSetup>(sym(
                    c"fmi2SetupExperiment",
                )?),
                enter_initialization_mode: std::mem::transmute::<*mut c_void, FnComp>(sym(
                    c"fmi2EnterInitializationMode",
                )?),
                exit_initialization_mode: std::mem::transmute::<*mut c_void, FnComp>(sym(
                    c"fmi2ExitInitializationMode",
                )?),
                terminate: std::mem::transmute::<*mut c_void, FnComp>(sym(c"fmi2Terminate")?),
                get_real: std::mem::transmute::<*mut c_void, FnReal>(sym(c"fmi2GetReal")?),
                set_real: std::mem::transmute::<*mut c_void, FnSetRealT>(sym(c"fmi2SetReal")?),
                set_string: std::mem::transmute::<*mut c_void, FnSetStr>(sym(c"fmi2SetString")?),
                do_step: std::mem::transmute::<*mut c_void, FnDoStep>(sym(c"fmi2DoStep")?),
            }
        };
        Ok(Fmu {
            handle,
            f,
            dir: dir.to_path_buf(),
            guid,
        })
    }

    /// `file://` URI of the unpacked resources folder.
    pub fn resource_uri(&self) -> String {
        let abs = std::fs::canonicalize(self.dir.join("resources"))
            .unwrap_or_else(|_| self.dir.join("resources"));
        format!("file://{}", abs.display())
    }

    /// Instantiate a co-simulation slave and bring it to initialization mode
    /// (`strings` are (vr, value) parameters set before initialization).
    pub fn slave(
        &self,
        name: &str,
        cb: &fmi2CallbackFunctions,
        strings: &[(u32, &str)],
    ) -> Result<Slave<'_>> {
        let n = CString::new(name).map_err(|_| Error::Other("name contains NUL".into()))?;
        let g = CString::new(self.guid.as_str()).map_err(|_| Error::Other("bad guid".into()))?;
        let r = CString::new(self.resource_uri()).map_err(|_| Error::Other("bad path".into()))?;
        // SAFETY: valid C strings; cb outlives the slave (caller keeps it).
        let c = unsafe {
            (self.f.instantiate)(
                n.as_ptr(),
                FMI2_CO_SIMULATION,
                g.as_ptr(),
                r.as_ptr(),
                cb,
                0,
                0,
            )
        };
        if c.is_null() {
            return Err(Error::Other(
                "fmi2Instantiate returned NULL (see the log above)".into(),
            ));
        }
        let s = Slave {
            fmu: self,
            c,
            initialized: std::cell::Cell::new(false),
        };
        for (vr, v) in strings {
            let cv = CString::new(*v).map_err(|_| Error::Other("value contains NUL".into()))?;
            let p: *const c_char = cv.as_ptr();
            // SAFETY: one vr and one string pointer.
            s.check(
                unsafe { (self.f.set_string)(c, vr, 1, &p) },
                "fmi2SetString",
            )?;
        }
        // SAFETY: live component.
        unsafe {
            s.check(
                (self.f.setup_experiment)(c, 0, 0.0, 0.0, 0, 0.0),
                "fmi2SetupExperiment",
            )?;
            s.check(
                (self.f.enter_initialization_mode)(c),
                "fmi2EnterInitializationMode",
            )?;
        }
        Ok(s)
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        // SAFETY: every Slave borrows the Fmu, so none is alive any more.
        unsafe {
            libc::dlclose(self.handle);
        }
    }
}

/// One instance of the loaded FMU.
pub struct Slave<'a> {
    fmu: &'a Fmu,
    pub c: fmi2Component,
    initialized: std::cell::Cell<bool>,
}

impl Slave<'_> {
    fn check(&self, s: Fmi2Status, what: &str) -> Result<()> {
        if s == Fmi2Status::Ok {
            Ok(())
        } else {
            Err(Error::Other(format!("{what} returned {s:?}")))
        }
    }
    /// fmi2SetReal.
    pub fn set_real(&self, vrs: &[u32], v: &[f64]) -> Result<()> {
        // SAFETY: equal-length slices, live component.
        self.check(
            unsafe {
                (self.fmu.f.set_real)(self.c, vrs.as_ptr(), vrs.len().min(v.len()), v.as_ptr())
            },
            "fmi2SetReal",
        )
    }
    /// fmi2GetReal.
    pub fn get_real(&self, vrs: &[u32], v: &mut [f64]) -> Result<()> {
        // SAFETY: equal-length slices, live component.
        self.check(
            unsafe {
                (self.fmu.f.get_real)(self.c, vrs.as_ptr(), vrs.len().min(v.len()), v.as_mut_ptr())
            },
            "fmi2GetReal",
        )
    }
    /// fmi2ExitInitializationMode.
    pub fn exit_initialization(&self) -> Result<()> {
        // SAFETY: live component.
        self.check(
            unsafe { (self.fmu.f.exit_initialization_mode)(self.c) },
            "fmi2ExitInitializationMode",
        )?;
        self.initialized.set(true);
        Ok(())
    }
    /// fmi2DoStep.
    pub fn do_step(&self, t: f64, h: f64) -> Result<()> {
        // SAFETY: live component.
        self.check(
            unsafe { (self.fmu.f.do_step)(self.c, t, h, 1) },
            "fmi2DoStep",
        )
    }
}

impl Drop for Slave<'_> {
    fn drop(&mut self) {
        // SAFETY: live component, freed once.
        unsafe {
            if self.initialized.get() {
                (self.fmu.f.terminate)(self.c);
            }
            (self.fmu.f.free_instance)(self.c);
        }
    }
}
