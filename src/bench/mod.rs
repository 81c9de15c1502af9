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
