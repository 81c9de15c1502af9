//! fit — fitting a model to recordings by bounded, robust non-linear least
//! squares: the problem interface, Levenberg–Marquardt, particle swarm start,
//! identifiability and standard errors, staging, quality metrics, hold-out
//! splits and the printable / JSON report.
//!
//! The fitter knows nothing about tyres: a model plugs in by implementing
//! [`Problem`] (parameters with bounds, residuals, exact Jacobian columns).
//!
//! Must never: use unseeded randomness (every fit is reproducible), print or
//! draw progress itself (the caller passes a callback), approximate
//! derivatives by finite differences, or panic on user data.

pub mod holdout;
pub mod identify;
pub mod lm;
pub mod loss;
pub mod metrics;
pub mod problem;
pub mod pso;
pub mod report;
pub mod solve;

pub use holdout::{Holdout, Split};
pub use identify::{IdentifyOptions, Verdict};
pub use lm::{LmOptions, Termination};
pub use loss::{Loss, LossKind};
pub use metrics::{ChannelMetric, Condition};
pub use problem::{Param, Problem, Stack};
pub use pso::PsoOptions;
pub use report::FitReport;
pub use solve::{
    fit, fit_global, run_stages, FitOptions, FitOutcome, ParamResult, ParamStatus, ParamValues,
    Phase, Progress, ProgressFn, Stage,
};
