//! bench — the speed figures the issues ask for, each printed beside its named
//! peers measured in the same run (ratios, because these machines are noisy).
//! One file per area; `tyrekit bench [AREA…]` runs them.
//! Must never: be used as a pass/fail test (timings are reported, not asserted).

pub mod brush;
pub mod data;
pub mod diagnose;
pub mod fit;
pub mod fmu;
pub mod mf;
pub mod transient;

/// Context shared by all benchmark sections.
#[derive(Clone, Debug)]
pub struct BenchContext {
    /// Python interpreter with numpy/scipy/pacejka for the peers, if available.
    pub python: Option<std::path::PathBuf>,
    /// Shorter runs (for a smoke check in CI).
    pub quick: bool,
}

/// A section's scratch folder, `temp_dir()/tyrekit-bench-{tag}-{pid}`, removed
/// with everything in it when dropped: at the section's end, also when it
/// returns early with an error or panics. (The test's `tempfile` is a
/// dev-dependency only, so the binary has this one.)
pub(crate) struct ScratchDir(std::path::PathBuf);

impl ScratchDir {
    /// Create the folder; failing that, the crate's I/O error naming it.
    pub(crate) fn new(tag: &str) -> crate::Result<Self> {
        let dir = std::env::temp_dir().join(format!("tyrekit-bench-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| crate::Error::io(&dir, e))?;
        Ok(Self(dir))
    }

    /// The folder.
    pub(crate) fn path(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        // Nothing to do about a folder that cannot be removed.
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A benchmark section: (name, runner).
pub type Section = (&'static str, fn(&BenchContext) -> crate::Result<()>);

/// All sections, in print order.
pub const SECTIONS: &[Section] = &[
    ("mf", mf::run),
    ("fmu", fmu::run),
    ("transient", transient::run),
    ("brush", brush::run),
    ("fit", fit::run),
    ("diagnose", diagnose::run),
    ("data", data::run),
];
