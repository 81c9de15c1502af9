//! The pieces together, as the Magic Formula stages will use them: a
//! recording with test conditions → hold out whole conditions → fit the rest
//! → score fitted and held-out data per condition → report.
//! (The model is the benchmark's lateral stand-in until the generic MF lands.)

use tyrekit::bench::fit::{lateral_fy, LateralData, LateralStandIn, FZ0, TRUTH};
use tyrekit::data::{Recording, Sample, Segment, SegmentKind};
use tyrekit::fit::metrics::evaluate;
use tyrekit::fit::{fit, FitOptions, FitReport, Holdout};

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
    let idx = split.train_indices();
    let train = LateralData {
        alpha: idx.iter().map(|&i| d.alpha[i]).collect(),
        fz: idx.iter().map(|&i| d.fz[i]).collect(),
        gamma: idx.iter().map(|&i| d.gamma[i]).collect(),
        fy: idx.iter().map(|&i| d.fy[i]).collect(),
    };
    let p = LateralStandIn::new(train);
    let out = fit(&p, None, None, &FitOptions::default(), "pure Fy", None).unwrap();
    let sim: Vec<f64> = (0..d.fy.len())
        .map(|i| lateral_fy(&out.theta, d.alpha[i], d.fz[i], d.gamma[i], None))
        .collect();
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
    };
    let text = report.to_text();
    assert!(text.contains("Quality (held-out data)"), "{text}");
    println!("{text}");
}
