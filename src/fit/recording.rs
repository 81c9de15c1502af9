//! recording — a [`Problem`] over the samples of a recording, for models that
//! predict one channel sample by sample (the steady-state Magic Formula
//! stages): residual = model(θ, sample) − measured channel.
//!
//! A model implements [`SampleModel`]; [`RecordingProblem`] does the rest:
//! choosing samples (hold-out ranges, segment kinds), dropping samples whose
//! measured channel is missing, weights, thread-parallel evaluation, and a
//! decimated copy for the particle swarm.
//!
//! Must never: fit a sample whose measured value is NaN (it is dropped and
//! counted), or allocate per sample.

use super::metrics::channel_value;
use super::problem::{par_rows, Param, Problem};
use crate::data::{Recording, Sample};
use nalgebra::DMatrixViewMut;
use std::ops::Range;

/// A model of one channel, evaluated sample by sample.
pub trait SampleModel: Sync {
    /// All parameters, in θ order.
    fn params(&self) -> &[Param];
    /// The simulated channel at sample `s`. If `grad` is given, also write
    /// ∂value/∂θ_{`cols[k]`} into `grad[k]` (exact: analytic or AD; `grad`
    /// has `cols.len()` entries).
    fn eval(&self, theta: &[f64], s: &Sample, cols: &[usize], grad: Option<&mut [f64]>) -> f64;
}

/// One channel of (part of) a recording as a least-squares problem.
pub struct RecordingProblem<'a, M: SampleModel> {
    model: &'a M,
    samples: &'a [Sample],
    channel: String,
    /// Indices of the samples fitted.
    idx: Vec<usize>,
    /// Samples skipped because the measured channel was not finite.
    pub dropped: usize,
    weights: Option<Vec<f64>>,
    /// Threads for evaluation (results do not depend on it).
    pub threads: usize,
}

impl<'a, M: SampleModel> RecordingProblem<'a, M> {
    /// Fit `channel` (Fx, Fy, Mz …) of `rec` over the samples in `ranges`
    /// (`None`: all), skipping samples whose measured value is not finite.
    pub fn new(
        model: &'a M,
        rec: &'a Recording,
        channel: &str,
        ranges: Option<&[Range<usize>]>,
    ) -> crate::Result<Self> {
        let n = rec.samples.len();
        if channel_value(&Sample::default(), channel).is_none() {
            return Err(crate::Error::Input(format!(
                "{}: cannot fit unknown channel '{channel}' (expected Fx, Fy, Mx, My, Mz)",
                rec.source
            )));
        }
        let all = 0..n;
        let ranges = ranges.unwrap_or(std::slice::from_ref(&all));
        let mut idx = Vec::new();
        let mut dropped = 0;
        for r in ranges {
            for i in r.start.min(n)..r.end.min(n) {
                if channel_value(&rec.samples[i], channel).is_some_and(f64::is_finite) {
                    idx.push(i);
                } else {
                    dropped += 1;
                }
            }
        }
        Ok(RecordingProblem {
            model,
            samples: &rec.samples,
            channel: channel.to_string(),
            idx,
            dropped,
            weights: None,
            threads: 1,
        })
    }

    /// Weight every residual by `w` (e.g. 1/σ² of the channel, so channels
    /// of different units can be [`super::Stack`]ed).
    pub fn with_weight(mut self, w: f64) -> Self {
        self.weights = (w != 1.0).then(|| vec![w; self.idx.len()]);
        self
    }

    /// Evaluate on `threads` threads.
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads.max(1);
        self
    }

    /// A copy keeping every `k`-th fitted sample (for the swarm's many evaluations).
    pub fn every(&self, k: usize) -> Self {
        let k = k.max(1);
        let idx: Vec<usize> = self.idx.iter().step_by(k).copied().collect();
        RecordingProblem {
            model: self.model,
            samples: self.samples,
            channel: self.channel.clone(),
            weights: self.weights.as_ref().map(|w| vec![w[0]; idx.len()]),
            idx,
            dropped: self.dropped,
            threads: self.threads,
        }
    }

    /// Indices of the fitted samples.
    pub fn sample_indices(&self) -> &[usize] {
        &self.idx
    }

    fn measured(&self, i: usize) -> f64 {
        channel_value(&self.samples[i], &self.channel).unwrap_or(f64::NAN)
    }
}

impl<M: SampleModel> Problem for RecordingProblem<'_, M> {
    fn params(&self) -> &[Param] {
        self.model.params()
    }
    fn n_residuals(&self) -> usize {
        self.idx.len()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        par_rows(self.threads, 0, r, None, &|first, r: &mut [f64], _| {
            for (k, rk) in r.iter_mut().enumerate() {
                let i = self.idx[first + k];
                *rk = self.model.eval(theta, &self.samples[i], &[], None) - self.measured(i);
            }
        });
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        par_rows(
            self.threads,
            0,
            r,
            Some(jac),
            &|first, r: &mut [f64], jac| {
                let Some(jac) = jac else { return };
                let mut g = vec![0.0; cols.len()]; // one per block, not per sample
                for (k, rk) in r.iter_mut().enumerate() {
                    let i = self.idx[first + k];
                    *rk = self.model.eval(theta, &self.samples[i], cols, Some(&mut g))
                        - self.measured(i);
                    for (j, gj) in g.iter().enumerate() {
                        jac[(k, j)] = *gj;
                    }
                }
            },
        );
    }
    fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
}

/// The model's channel for every sample of `rec` (for the metrics).
pub fn simulate<M: SampleModel>(model: &M, theta: &[f64], rec: &Recording) -> Vec<f64> {
    rec.samples
        .iter()
        .map(|s| model.eval(theta, s, &[], None))
        .collect()
}
