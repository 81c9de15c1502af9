//! fit — fitting a model to recordings by bounded, robust non-linear least
//! squares: the problem interface, Levenberg–Marquardt, particle swarm start,
//! identifiability and standard errors, staging, quality metrics, hold-out
//! splits and the printable / JSON report.
//!
//! Must never: use unseeded randomness (every fit is reproducible), print or
//! draw progress itself (the caller passes a callback), approximate
//! derivatives by finite differences, or panic on user data.
//!
//! # Plugging a model in
//! The fitter knows nothing about tyres. A model stage implements
//! [`Problem`]:
//! - [`Problem::params`]: every parameter of θ, in order, as [`Param`]
//!   (name = the lower-case `.tir` key, start, lower/upper bounds, `free`).
//!   List the parameters you trust most first: when two are collinear the
//!   later one is held (see [`identify`]).
//! - [`Problem::n_residuals`] and [`Problem::residuals`]: r(θ) = model − data
//!   over the stage's samples (allocate nothing per call).
//! - [`Problem::jacobian`]: r and the exact ∂r/∂θ for the requested columns
//!   only (`cols`), written column k ↔ `cols[k]` into a column-major view.
//!   For the Magic Formula: seed a dual number per requested column.
//! - optionally [`Problem::weights`] (e.g. 1/σ² per channel), and
//!   [`Problem::row_jacobian`] + [`Problem::threads`]: J by row blocks, so the
//!   fitter accumulates JᵀJ without storing J (the MF stages do).
//!
//! For a model predicting a channel sample by sample, implement
//! [`SampleModel`] instead and let [`RecordingProblem`] build the problem
//! (sample selection, NaN dropping, weights, threads, swarm subsample).
//! Several channels of one stage (Fy and Mz …) go together with [`Stack`].
//! Then [`fit`] (or [`fit_global`] with a subsampled problem for the swarm)
//! fits one stage, and [`run_stages`] runs pure Fx → pure Fy → Mz →
//! combined → relaxation, passing values on by name ([`ParamValues`]).
//! [`metrics::evaluate`] scores simulated channels per condition, on the
//! fitted samples or on a [`Holdout`] split; [`FitReport`] prints tables and
//! writes `fit.json`. Progress: pass `Some(&mut |p: &Progress| …)`.

pub mod brush;
pub mod channels;
pub mod geometry;
pub mod grad_pure;
pub mod holdout;
pub mod identify;
pub(crate) mod initial;
pub mod lm;
pub mod loss;
pub mod metrics;
pub mod mf_fit;
pub mod mf_stages;
pub mod plot;
pub mod problem;
pub mod pso;
pub mod recording;
pub mod report;
pub mod solve;
pub mod timing;
pub mod transient;
pub mod validity;

pub use holdout::{Holdout, Split};
pub use identify::{IdentifyOptions, Verdict};
pub use lm::{LmOptions, Termination};
pub use loss::{Loss, LossKind};
pub use metrics::{ChannelMetric, Condition};
pub use problem::{Param, Problem, RowJacobian, Stack};
pub use pso::PsoOptions;
pub use recording::{simulate, RecordingProblem, SampleModel};
pub use report::FitReport;
pub use solve::{
    fit, fit_global, run_stages, FitOptions, FitOutcome, ParamResult, ParamStatus, ParamValues,
    Phase, Progress, ProgressFn, Stage,
};
