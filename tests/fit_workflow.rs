//! The pieces together, as the Magic Formula stages will use them: a
//! recording with test conditions → hold out whole conditions → fit the rest
//! → score fitted and held-out data per condition → report.
//! (The model is the benchmark's lateral stand-in until the generic MF lands.)

use crate::standin;
use standin::{lateral_fy, LateralData, FZ0, LOWER, NAMES, START, TRUTH, UPPER};
use tyrekit::data::{Recording, Sample, Segment, SegmentKind};
use tyrekit::fit::metrics::evaluate;
use tyrekit::fit::{
    fit, fit_global, simulate, FitOptions, FitReport, Holdout, Param, PsoOptions, RecordingProblem,
    SampleModel,
};

/// The benchmark's lateral stand-in as a per-sample model of Fy.
struct StandIn(Vec<Param>);

impl StandIn {
    fn new() -> StandIn {
        StandIn(
            (0..18)
                .map(|i| Param::new(NAMES[i], START[i], LOWER[i], UPPER[i]))
                .collect(),
        )
    }
}

impl SampleModel for StandIn {
    fn params(&self) -> &[Param] {
        &self.0
    }
    fn eval(&self, theta: &[f64], s: &Sample, cols: &[usize], grad: Option<&mut [f64]>) -> f64 {
        match grad {
            None => lateral_fy(theta, s.alpha, s.fz, s.gamma, None),
            Some(g) => {
                let mut full = [0.0; 18];
                let v = lateral_fy(theta, s.alpha, s.fz, s.gamma, Some(&mut full));
                for (k, &c) in cols.iter().enumerate() {
                    g[k] = full[c];
                }
                v
            }
        }
    }
}

fn recording(d: &LateralData) -> Recording {
    let samples: Vec<Sample> = (0..d.fy.len())
        .map(|i| Sample {
            alpha: d.alpha[i],
            fz: d.fz[i],
            gamma: d.gamma[i],
            fy: d.fy[i],
            p: 2.0e5,
            ..Sample::default()
        })
        .collect();
    // one segment per run of constant (Fz, γ)
    let mut segments = Vec::new();
    let mut start = 0;
    for i in 1..=samples.len() {
        if i == samples.len()
            || samples[i].fz != samples[start].fz
            || samples[i].gamma != samples[start].gamma
        {
            segments.push(Segment {
                start,
                end: i,
                kind: SegmentKind::PureLateral,
                fz: samples[start].fz,
                gamma: samples[start].gamma,
                p: 2.0e5,
                vx: 16.0,
                alpha: 0.0,
            });
            start = i;
        }
    }
    Recording {
        source: "synthetic".into(),
        samples,
        channels: vec!["Fy".into()],
        segments,
        ..Recording::default()
    }
}

#[test]
fn fit_on_some_conditions_predicts_the_held_out_ones() {
    let d = LateralData::generate(24_000, 5);
    let rec = recording(&d);
    assert_eq!(rec.segments.len(), 12); // 4 loads × 3 inclinations
    let split = Holdout::parse("condition:4").unwrap().split(&rec);
    assert_eq!(split.test.len(), 3);
    let model = StandIn::new();
    let p = RecordingProblem::new(&model, &rec, "Fy", Some(&split.train))
        .unwrap()
        .with_threads(2);
    assert_eq!(p.sample_indices(), &split.train_indices()[..]);
    let out = fit(&p, None, None, &FitOptions::default(), "pure Fy", None).unwrap();
    let sim = simulate(&model, &out.theta, &rec);
    let fitted = evaluate(&rec, "Fy", &sim, Some(&split.train)).unwrap();
    let held = evaluate(&rec, "Fy", &sim, Some(&split.test)).unwrap();
    // per-condition rows only for the conditions present in each half
    assert_eq!(held.len(), 1 + 3);
    assert_eq!(fitted.len(), 1 + 9);
    // The model is right, so on unseen conditions the error is the noise
    // (σ_n = 1 % of PDY1·FZ0) plus a parameter-uncertainty part far smaller:
    // σ ≈ σ_n / RMS(Fy). Allow 10 % over that.
    let test_idx = split.test_indices();
    let rms =
        (test_idx.iter().map(|&i| d.fy[i] * d.fy[i]).sum::<f64>() / test_idx.len() as f64).sqrt();
    let noise_sigma = 0.01 * TRUTH[1] * FZ0 / rms;
    assert!(
        held[0].sigma < 1.1 * noise_sigma,
        "held-out σ {} vs noise {}",
        held[0].sigma,
        noise_sigma
    );
    assert!(
        held[0].sigma > 0.9 * noise_sigma,
        "σ below the noise floor is impossible"
    );
    let report = FitReport {
        sources: vec![rec.source.clone()],
        stages: vec![out],
        metrics: fitted,
        holdout_metrics: held,
        ..Default::default()
    };
    let text = report.to_text();
    assert!(text.contains("Quality (held-out data)"), "{text}");
    println!("{text}");
}

#[test]
fn missing_measurements_are_dropped_and_swarm_runs_on_a_subsample() {
    let d = LateralData::generate(6_000, 9);
    let mut rec = recording(&d);
    for i in (0..rec.samples.len()).step_by(100) {
        rec.samples[i].fy = f64::NAN;
    }
    let model = StandIn::new();
    let p = RecordingProblem::new(&model, &rec, "fy", None).unwrap();
    assert_eq!(p.dropped, 60);
    assert_eq!(p.sample_indices().len(), 6_000 - 60);
    let sub = p.every(10);
    assert_eq!(sub.sample_indices().len(), 594);
    let o = FitOptions {
        pso: Some(PsoOptions {
            iterations: 40,
            ..PsoOptions::default()
        }),
        ..FitOptions::default()
    };
    let out = fit_global(&p, Some(&sub), None, None, &o, "pure Fy", None).unwrap();
    // The data are the stand-in plus 1 % noise: every parameter within 4.5
    // standard errors of the truth (see fit_standin.rs for the reasoning).
    for (k, r) in out.params.iter().enumerate() {
        assert!(
            (r.value - TRUTH[k]).abs() < 4.5 * r.stderr.unwrap(),
            "{}: {}",
            r.name,
            r.value
        );
    }
    assert!(out.cost.is_finite());
    // an unknown channel is an error, not a panic
    assert!(RecordingProblem::new(&model, &rec, "torque", None).is_err());
}
