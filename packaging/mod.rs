//! packaging — builds the `.fmu` archive (a zip): `modelDescription.xml` (the
//! text build.rs generated, GUID included), `binaries/linux64/<modelIdentifier>.so`
//! (the crate's cdylib), `resources/tyre.tir` and `documentation/index.html`.
//!
//! Compiled into the binary as `crate::fmi::packaging` (via `#[path]` in
//! `src/main.rs`), used by `tyrekit package`, `tyrekit demo` and the FMU
//! benchmark. The shared library is embedded in the binary at build time
//! (`build_lib.rs`, run by build.rs), so an installed `tyrekit` packages from
//! any directory; `--library` ships another build of the same interface. The
//! start values of `Fz` and `omega` are the packaged tyre's free-rolling state
//! (`fmi::start`). A library that does not contain this interface's GUID is
//! never shipped, and the .fmu holds no path of the packaging machine.
//! Must never: ship a library whose GUID differs from the XML's, or leave a
//! half-written .fmu behind.

use crate::error::{Error, Result};
use crate::fmi::spec::{CHOSEN_STARTS, TYRE_DEPENDENT_STARTS};
use crate::fmi::start::start_span;
use crate::fmi::vars::{Start, VARIABLES};
use crate::fmi::{GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};
use crate::mf::Tyre;
use crate::tir::TyreParams;
use std::io::Write;
use std::path::PathBuf;

/// HTML template of `documentation/index.html` (placeholders `{{…}}`).
const DOC_TEMPLATE: &str = include_str!("documentation/index.html");

/// File name of the cdylib cargo builds.
pub const LIB_FILE: &str = "libtyrekit.so";

/// What to package.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Tyre property file to ship as resources/tyre.tir (default: the built-in tyre).
    pub tir: Option<PathBuf>,
    /// Output path (default: [`default_fmu_path`]).
    pub out: Option<PathBuf>,
    /// Shared library to ship (default: [`EMBEDDED_LIBRARY`]).
    pub library: Option<PathBuf>,
    /// Default of the `force_model` parameter in the packaged XML (`mf` when
    /// None): a start value chosen at packaging (`spec::CHOSEN_STARTS`), which
    /// the one library reads back from the packaged XML at instantiation.
    pub force_model: Option<String>,
}

/// The chosen start values (`spec::CHOSEN_STARTS`) for `opts`, checked
/// against the values the library knows.
pub fn chosen_starts(opts: &Options) -> Result<Vec<(&'static str, String)>> {
    let mut out = Vec::new();
    if let Some(f) = &opts.force_model {
        let f = f.trim().to_ascii_lowercase();
        let allowed = CHOSEN_STARTS
            .iter()
            .find(|c| c.0 == "force_model")
            .map_or(&[][..], |c| c.1);
        if !allowed.contains(&f.as_str()) {
            return Err(Error::Input(format!(
                "--force-model {f}: expected one of {}",
                allowed.join(", ")
            )));
        }
        out.push(("force_model", f));
    }
    Ok(out)
}

/// The FMU's shared library, built by build.rs (`packaging/build_lib.rs`) from
/// this binary's own sources and embedded here: packaging needs no source tree.
pub const EMBEDDED_LIBRARY: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/fmu_lib.so"));

/// How [`EMBEDDED_LIBRARY`] was built (portable zigbuild or host toolchain).
pub const EMBEDDED_BUILD: &str = include_str!(concat!(env!("OUT_DIR"), "/fmu_lib.txt"));

/// The crate root this binary was built from (may not exist where it runs).
pub fn crate_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The source tree this binary was built from, when the current directory is
/// inside it (and it is still there).
pub fn source_tree() -> Option<PathBuf> {
    let root = crate_root();
    let cwd = std::env::current_dir().ok()?;
    (root.join("Cargo.toml").is_file() && cwd.starts_with(&root)).then_some(root)
}

/// The cargo target directory (CARGO_TARGET_DIR or `<crate>/target`).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map(|p| {
            if p.is_absolute() {
                p
            } else {
                crate_root().join(p)
            }
        })
        .unwrap_or_else(|| crate_root().join("target"))
}

/// Inside the source tree `target/fmu/TyreKit.fmu`, elsewhere `./TyreKit.fmu`.
pub fn default_fmu_path() -> PathBuf {
    let file = format!("{MODEL_IDENTIFIER}.fmu");
    match source_tree() {
        Some(_) => target_dir().join("fmu").join(file),
        None => PathBuf::from(file),
    }
}

/// Scratch space for `demo`/`bench`: under the target dir inside the source
/// tree, else the system's temporary directory.
pub fn scratch_dir(name: &str) -> PathBuf {
    let base = match source_tree() {
        Some(_) => target_dir().join("fmu"),
        None => std::env::temp_dir(),
    };
    base.join(format!("tyrekit-{name}-{}", std::process::id()))
}

/// Does the library implement this interface (its GUID inside)?
fn has_guid(bytes: &[u8]) -> bool {
    bytes.windows(GUID.len()).any(|w| w == GUID.as_bytes())
}

/// `modelDescription.xml` for `tyre`: the build's XML with the start values of
/// [`TYRE_DEPENDENT_STARTS`] set to the tyre's free-rolling state
/// ([`crate::fmi::start::free_rolling`], what the instance starts with) and
/// those of `chosen` ([`chosen_starts`], read back by the instance).
pub fn model_description(tyre: &Tyre, chosen: &[(&'static str, String)]) -> Result<String> {
    let mut xml = MODEL_DESCRIPTION_XML.to_string();
    let mut set = |name: &str, value: &str| -> Result<()> {
        let r = start_span(&xml, name).ok_or_else(|| {
            Error::Other(format!(
                "modelDescription.xml: no start value of \"{name}\" to set"
            ))
        })?;
        xml.replace_range(r, value);
        Ok(())
    };
    for (name, value) in crate::fmi::start::free_rolling(tyre) {
        if !TYRE_DEPENDENT_STARTS.contains(&name) {
            return Err(Error::Other(format!(
                "{name} is not in spec::TYRE_DEPENDENT_STARTS"
            )));
        }
        if !value.is_finite() {
            return Err(Error::Other(format!(
                "the tyre gives no finite free-rolling {name} ({value}): check FNOMIN and UNLOADED_RADIUS"
            )));
        }
        // `{}` prints the shortest text that reads back to the same f64.
        set(name, &format!("{value}"))?;
    }
    for (name, value) in chosen {
        set(name, value)?;
    }
    Ok(xml)
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `documentation/index.html` for this interface and tyre.
pub fn documentation(tyre_label: &str, tyre: &Tyre, chosen: &[(&'static str, String)]) -> String {
    let tyre_starts = crate::fmi::start::free_rolling(tyre);
    let mut rows = String::new();
    for v in VARIABLES.iter() {
        let dependent = tyre_starts.iter().find(|(n, _)| *n == v.name);
        let start = match v.start {
            Start::Real(_) if dependent.is_some() => {
                format!(
                    "{} (this tyre, free rolling)",
                    dependent.map_or(0.0, |d| d.1)
                )
            }
            Start::None => String::new(),
            Start::Real(x) => format!("{x}"),
            Start::Integer(x) => format!("{x}"),
            Start::Boolean(x) => format!("{x}"),
            Start::String(_) if chosen.iter().any(|c| c.0 == v.name) => {
                format!(
                    "\"{}\" (chosen at packaging)",
                    chosen
                        .iter()
                        .find(|c| c.0 == v.name)
                        .map_or("", |c| c.1.as_str())
                )
            }
            Start::String(s) => format!("\"{s}\""),
        };
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            html_escape(v.name),
            v.causality,
            v.ty.name(),
            html_escape(v.unit),
            html_escape(&start),
            html_escape(v.description)
        ));
    }
    DOC_TEMPLATE
        .replace("{{GUID}}", GUID)
        .replace("{{MODEL_IDENTIFIER}}", MODEL_IDENTIFIER)
        .replace("{{TYRE}}", &html_escape(tyre_label))
        .replace("{{VARIABLES}}", rows.trim_end())
}

/// Build the .fmu; returns its path.
pub fn package(opts: &Options) -> Result<PathBuf> {
    let out = opts.out.clone().unwrap_or_else(default_fmu_path);
    let (tir_text, label, tyre) = match &opts.tir {
        Some(p) => {
            // Refuse a file the FMU could not load at instantiation
            // (the same reader and validation as fmi2Instantiate; doubts shown).
            let tyre = Tyre::from_file(p)?;
            for w in tyre.warnings() {
                eprintln!("tyrekit: warning: {}: {w}", p.display());
            }
            let bytes = crate::tir::read_file(p)?;
            // The file name only: no path of the packaging machine in the FMU.
            let name = p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let label = format!("{name} ({:?})", tyre.version());
            (bytes, label, tyre)
        }
        None => {
            let text = TyreParams::builtin().to_tir_string();
            // The tyre exactly as the FMU will read it back.
            let params = TyreParams::from_tir_str(&text, "tyre.tir")?;
            let tyre = Tyre::new(params)?;
            (
                text.into_bytes(),
                "the built-in default tyre".to_string(),
                tyre,
            )
        }
    };
    let chosen = chosen_starts(opts)?;
    let xml = model_description(&tyre, &chosen)?;
    let so: std::borrow::Cow<[u8]> = match &opts.library {
        Some(l) => {
            let b = std::fs::read(l).map_err(|e| Error::io(l, e))?;
            if !has_guid(&b) {
                return Err(Error::Other(format!(
                    "{} does not implement this interface (GUID {GUID} not inside): build it from the same sources, or leave --library out to ship the embedded one",
                    l.display()
                )));
            }
            b.into()
        }
        None => EMBEDDED_LIBRARY.into(),
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let doc = documentation(&label, &tyre, &chosen);
    let tmp = out.with_extension("fmu.part");
    let write = || -> std::result::Result<(), Box<dyn std::error::Error>> {
        let f = std::fs::File::create(&tmp)?;
        let mut zip = zip::ZipWriter::new(f);
        let deflate = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .unix_permissions(0o644);
        let entries: [(String, &[u8]); 5] = [
            ("modelDescription.xml".into(), xml.as_bytes()),
            // The instance reads its chosen start values (force_model) here:
            // masters such as fmpy extract only binaries/ and resources/.
            ("resources/modelDescription.xml".into(), xml.as_bytes()),
            (format!("binaries/linux64/{MODEL_IDENTIFIER}.so"), &so),
            ("resources/tyre.tir".into(), &tir_text),
            ("documentation/index.html".into(), doc.as_bytes()),
        ];
        for (name, data) in entries {
            let o = if name.ends_with(".so") {
                deflate.unix_permissions(0o755)
            } else {
                deflate
            };
            zip.start_file(name, o)?;
            zip.write_all(data)?;
        }
        zip.finish()?;
        Ok(())
    };
    if let Err(e) = write() {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::Other(format!("writing {}: {e}", out.display())));
    }
    std::fs::rename(&tmp, &out).map_err(|e| Error::io(&out, e))?;
    Ok(out)
}
