//! packaging — builds the `.fmu` archive (a zip): `modelDescription.xml` (the
//! text build.rs generated, GUID included), `binaries/linux64/<modelIdentifier>.so`
//! (the crate's cdylib), `resources/tyre.tir` and `documentation/index.html`.
//!
//! Compiled into the crate as `tyrekit::fmi::packaging` (via `#[path]`), used by
//! `tyrekit package`, `tyrekit demo`, the FMU benchmark and the tests.
//! The shared library is `target/release/libtyrekit.so`; when the crate's
//! sources are at hand `cargo build --release --lib` is run first (a no-op when
//! up to date), so `package` just works after a source change. A library that
//! does not contain this interface's GUID is never shipped.
//! Must never: ship a library whose GUID differs from the XML's, or leave a
//! half-written .fmu behind.

use crate::error::{Error, Result};
use crate::fmi::vars::{Start, VARIABLES};
use crate::fmi::{GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};
use crate::tir::TyreParams;
use std::io::Write;
use std::path::{Path, PathBuf};

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
    /// Shared library to ship (default: [`find_library`]).
    pub library: Option<PathBuf>,
    /// Default of the `force_model` parameter in the packaged XML (`mf` when
    /// None): `brush` ships the interface variant with that start value
    /// (its own GUID, which the library accepts: `vars::START_VARIANTS`).
    pub force_model: Option<String>,
}

/// The modelDescription.xml to ship for a `force_model` default.
pub fn model_description(force_model: Option<&str>) -> Result<&'static str> {
    match force_model.map(|s| s.trim().to_ascii_lowercase()) {
        None => Ok(MODEL_DESCRIPTION_XML),
        Some(f) if f == "mf" => Ok(MODEL_DESCRIPTION_XML),
        Some(f) => crate::fmi::vars::START_VARIANTS
            .iter()
            .find(|v| v.0 == "force_model" && v.1 == f)
            .map(|v| v.3)
            .ok_or_else(|| Error::Input(format!("--force-model {f}: expected mf or brush"))),
    }
}

/// The crate root this binary was built from.
pub fn crate_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
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

/// `target/fmu/TyreKit.fmu`.
pub fn default_fmu_path() -> PathBuf {
    target_dir().join("fmu").join("TyreKit.fmu")
}

/// Does the library at `p` implement this interface (its GUID inside)?
fn has_guid(p: &Path) -> bool {
    std::fs::read(p)
        .map(|b| b.windows(GUID.len()).any(|w| w == GUID.as_bytes()))
        .unwrap_or(false)
}

/// The release cdylib: `cargo build --release --lib` is run first when the
/// crate's sources are at hand (a no-op when it is up to date, a rebuild when
/// the sources changed since); otherwise the library beside the running
/// executable or in `target/release` is used if it implements this interface.
pub fn find_library() -> Result<PathBuf> {
    let release = target_dir().join("release").join(LIB_FILE);
    let manifest = crate_root().join("Cargo.toml");
    if manifest.is_file() {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let built = std::process::Command::new(&cargo)
            .args(["build", "--release", "--lib", "--quiet", "--manifest-path"])
            .arg(&manifest)
            .status();
        match built {
            Ok(s) if s.success() => {}
            Ok(_) => {
                return Err(Error::Other(
                    "`cargo build --release --lib` failed: cannot build the FMU library".into(),
                ))
            }
            Err(e) => eprintln!("tyrekit: cannot run cargo ({e}); using the library as built"),
        }
    }
    let beside_exe = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(|d| d.join(LIB_FILE)));
    let candidates = std::iter::once(release.clone()).chain(beside_exe);
    for p in candidates {
        if p.is_file() && has_guid(&p) {
            return Ok(p);
        }
    }
    Err(Error::Other(format!(
        "no FMU library implementing GUID {GUID} found ({} missing or from another interface): run `cargo build --release`",
        release.display()
    )))
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `documentation/index.html` for this interface and tyre.
pub fn documentation(tyre_label: &str) -> String {
    let mut rows = String::new();
    for v in VARIABLES.iter() {
        let start = match v.start {
            Start::None => String::new(),
            Start::Real(x) => format!("{x}"),
            Start::Integer(x) => format!("{x}"),
            Start::Boolean(x) => format!("{x}"),
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
    let xml = model_description(opts.force_model.as_deref())?;
    let (tir_text, label) = match &opts.tir {
        Some(p) => {
            // Refuse a file the FMU could not load at instantiation.
            // (the same reader and validation as fmi2Instantiate; doubts shown).
            let tyre = crate::mf::Tyre::from_file(p)?;
            for w in tyre.warnings() {
                eprintln!("tyrekit: warning: {}: {w}", p.display());
            }
            let bytes = crate::tir::read_file(p)?;
            (bytes, format!("{} ({:?})", p.display(), tyre.version()))
        }
        None => (
            TyreParams::builtin().to_tir_string().into_bytes(),
            "the built-in default tyre".to_string(),
        ),
    };
    let lib = match &opts.library {
        Some(l) => l.clone(),
        None => find_library()?,
    };
    let so = std::fs::read(&lib).map_err(|e| Error::io(&lib, e))?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let doc = documentation(&label);
    let tmp = out.with_extension("fmu.part");
    let write = || -> std::result::Result<(), Box<dyn std::error::Error>> {
        let f = std::fs::File::create(&tmp)?;
        let mut zip = zip::ZipWriter::new(f);
        let deflate = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .unix_permissions(0o644);
        let entries: [(String, &[u8]); 4] = [
            ("modelDescription.xml".into(), xml.as_bytes()),
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
