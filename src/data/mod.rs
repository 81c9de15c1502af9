//! data — tyre test recordings: readers (FSAE TTC .mat/.dat, TYDEX, CSV),
//! axis-system and unit conversion into ISO-W SI, warm-up removal, slip
//! computation and the split into test conditions.
//!
//! Pipeline ([`load`]): file → [`RawTable`] (names, units, columns as stored)
//! → channel identification (aliases) → units to SI ([`units`]) → signs to
//! ISO-W ([`conventions`]) → rows with NaN / out-of-range core values dropped
//! and counted → κ from wheel speed ([`slip`]) → warm-up cut and segments
//! ([`structure`]).
//!
//! Must never: keep a NaN or out-of-range row silently (drop and count it),
//! guess units a file states, or panic on a malformed file.

pub mod conventions;
pub mod csvio;
pub mod mat;
pub mod plot;
pub mod sanity;
pub mod slip;
pub mod slip_reference;
pub mod structure;
pub mod tdx;
pub mod ttc;
pub mod units;

mod load;
mod recording;

pub use load::{
    extra_si_unit, from_raw, load, read_raw, Format, KappaSource, LoadOptions, LoadReport, Loaded,
    RawColumn, RawTable, ReChoice, GZIP_MAX_INFLATED,
};
pub use recording::{Recording, Sample, Segment, SegmentKind, SAMPLE_CHANNELS};
