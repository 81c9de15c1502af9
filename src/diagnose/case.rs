//! case — the one recipe from a baseline and its recordings to a diagnosis
//! and the two files `tyrekit diagnose` writes, so that the command, the
//! benchmark and the tests run the same sequence:
//!
//! 1. a baseline given with `--tir` is compared as it is
//!    ([`Case::given`]); a fitted one ([`Case::fitted`]) first has the
//!    channels it did not fit blanked ([`super::baseline::drop_unfitted`]),
//!    keeps the recording it was fitted on for the re-estimation, and —
//!    where its fit removed sensor zeros — is compared on the corrected
//!    copy ([`super::sensor_zero::for_diagnosis`]);
//! 2. [`Case::diagnose`] runs [`super::report::diagnose_with`], with the
//!    re-estimation of a fitted baseline beneath the verdict
//!    ([`super::reestimate`]) where the zeros were left to the MF, and
//!    otherwise builds `extended.tir` again on the recording as measured
//!    ([`super::sensor_zero::extended_as_measured`]).
//!
//! Must never: write files or print (the caller does), or diagnose a
//! recording other than the one it says it compared ([`Case::rec`]).

use super::baseline::{drop_unfitted, Baseline};
use super::reestimate::refit_fitted_baseline;
use super::report::{diagnose_with, merge, Diagnosis};
use super::sensor_zero::{
    extended_as_measured, for_diagnosis, AsMeasured, ForDiagnosis, ZeroFinding,
};
use crate::data::Recording;
use crate::error::Result;
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::tir::TyreParams;

/// A baseline and the recordings prepared for its diagnosis.
pub struct Case {
    /// The tyre the diagnosis compares: the fit without the sensor zeros
    /// where it removed them ([`Baseline::compared`]), else the baseline.
    compared: Tyre,
    /// `baseline.tir`: the given tyre, or the fit to the recordings as
    /// measured.
    baseline_file: TyreParams,
    for_d: ForDiagnosis,
    /// The sensor zeros the fit found (`None` for a given tyre): the
    /// report's `sensor_zeros`.
    zeros: Option<ZeroFinding>,
    /// Channels not diagnosed at all: the fit had no segments for them
    /// ([`drop_unfitted`]).
    pub dropped: Vec<&'static str>,
}

/// What [`Case::diagnose`] gives: the diagnosis and the two files.
pub struct Outcome {
    /// The diagnosis of [`Case::rec`] against [`Case::compared`]; its
    /// report and explanation describe `extended_file`.
    pub diagnosis: Diagnosis,
    /// `baseline.tir`.
    pub baseline_file: TyreParams,
    /// `extended.tir`: the baseline with the verdict's extension.
    pub extended_file: TyreParams,
}

impl Case {
    /// A tyre given by the user (`--tir`), compared with the recordings
    /// merged as they are; no re-estimation (the tyre is the user's).
    pub fn given(tyre: Tyre, recs: Vec<Recording>) -> Self {
        Self {
            baseline_file: tyre.params().clone(),
            compared: tyre,
            for_d: for_diagnosis(None, merge(recs), None),
            zeros: None,
            dropped: Vec::new(),
        }
    }

    /// The baseline `b` fitted to `recs`: the channels it did not fit are
    /// blanked, and with `reestimate` (the default; `--keep-baseline`
    /// turns it off) the recording it was fitted on is kept so that its
    /// Magic Formula can be fitted again beneath a named extension.
    pub fn fitted(b: &Baseline, mut recs: Vec<Recording>, reestimate: bool) -> Result<Self> {
        let fitted_on = reestimate.then(|| merge(recs.clone()));
        let dropped = drop_unfitted(&mut recs, b);
        Ok(Self {
            compared: Tyre::new(b.compared().clone())?,
            baseline_file: b.tyre.clone(),
            for_d: for_diagnosis(Some(b), merge(recs), fitted_on),
            zeros: Some(ZeroFinding::of(b)),
            dropped,
        })
    }

    /// The recording the diagnosis compares (what the plots show): the
    /// zeros subtracted where the fit removed them.
    pub fn rec(&self) -> &Recording {
        &self.for_d.rec
    }

    /// The tyre the diagnosis compares with [`Self::rec`].
    pub fn compared(&self) -> &Tyre {
        &self.compared
    }

    /// The recordings as measured and the first fit, where the diagnosis
    /// compares without the sensor zeros (`None` otherwise).
    pub fn measured(&self) -> Option<&AsMeasured> {
        self.for_d.measured.as_ref()
    }

    /// Diagnose, and build the files; the report carries the sensor zeros
    /// the fit found (`sensor_zeros`). `threads` for the re-estimation's
    /// fits; `step` is told each stage's name (progress).
    pub fn diagnose(&self, threads: usize, step: &mut dyn FnMut(&str)) -> Result<Outcome> {
        let refit = refit_fitted_baseline(threads);
        let mut d = diagnose_with(
            &self.for_d.rec,
            &self.compared,
            &ReplayOptions::default(),
            self.for_d.refit(&refit),
            step,
        )?;
        let extended_file = match &self.for_d.measured {
            Some(m) => extended_as_measured(&mut d, &self.compared, m, &refit, step)?,
            None => d.extended.params().clone(),
        };
        d.report.sensor_zeros = self.zeros.clone();
        Ok(Outcome {
            diagnosis: d,
            baseline_file: self.baseline_file.clone(),
            extended_file,
        })
    }
}
