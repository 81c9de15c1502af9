//! Quality metrics per channel and condition, hold-out splits and the report.

use crate::fit_support;
use fit_support::*;
use tyrekit::data::{Recording, Sample, Segment, SegmentKind};
use tyrekit::fit::metrics::{evaluate, nrmse, sigma};
use tyrekit::fit::{fit, report, FitOptions, FitReport, Holdout, Param};

fn seg(start: usize, end: usize, fz: f64, gamma: f64) -> Segment {
    Segment {
        start,
        end,
        kind: SegmentKind::PureLateral,
        fz,
        gamma,
        p: 2.0e5,
        vx: 16.0,
        alpha: 0.0,
    }
}

/// Six samples, Fy = 1..6; segments: [0,2) at 1000 N, [2,4) at 2000 N, [4,6) at 1000 N.
fn rec() -> Recording {
    let samples = (0..6)
        .map(|i| Sample {
            fy: (i + 1) as f64,
            ..Sample::default()
        })
        .collect();
    Recording {
        source: "test".into(),
        samples,
        channels: vec!["Fy".into()],
        segments: vec![
            seg(0, 2, 1000.0, 0.0),
            seg(2, 4, 2000.0, 0.0),
            seg(4, 6, 1000.0, 0.0),
        ],
        ..Recording::default()
    }
}

#[test]
fn per_condition_metrics_by_hand() {
    let r = rec();
    let sim = [1.0, 2.0, 4.0, 4.0, 5.0, 8.0]; // errors 0,0,1,0,0,2
    let m = evaluate(&r, "fy", &sim, None).unwrap();
    assert_eq!(m.len(), 3); // all, 1000 N, 2000 N
                            // all: Σe² = 5, Σy² = 91 → σ = √(5/91); RMS = √(5/6); range 5
    assert!(m[0].condition.is_none() && m[0].n == 6);
    assert!((m[0].sigma - (5.0f64 / 91.0).sqrt()).abs() < 1e-15);
    assert!((m[0].nrmse - (5.0f64 / 6.0).sqrt() / 5.0).abs() < 1e-15);
    // 1000 N: samples 0,1,4,5 → y 1,2,5,6; e² = 0,0,0,4; Σy² = 66; range 5
    let c1 = &m[1];
    assert_eq!(c1.condition.unwrap().fz, 1000.0);
    assert_eq!(c1.n, 4);
    assert!((c1.sigma - (4.0f64 / 66.0).sqrt()).abs() < 1e-15);
    assert!((c1.nrmse - 1.0 / 5.0).abs() < 1e-15);
    // 2000 N: y 3,4; e² = 1,0; Σy² = 25; range 1; RMS = √0.5
    let c2 = &m[2];
    assert!((c2.sigma - 0.2).abs() < 1e-15);
    assert!((c2.nrmse - 0.5f64.sqrt()).abs() < 1e-15);
    // Wrong length or unknown channel: errors, not panics.
    assert!(evaluate(&r, "fy", &sim[..3], None).is_err());
    assert!(evaluate(&r, "torque", &sim, None).is_err());
    // sanity of the free functions on the same numbers
    assert_eq!(sigma(&sim, &sim), 0.0);
    assert!(nrmse(&[0.0; 2], &[1.0, 1.0]).is_nan());
}

#[test]
fn holdout_by_run_and_by_condition() {
    let r = rec();
    // run:2 holds out the 2nd run (1-based).
    let s = Holdout::parse("run:2").unwrap().split(&r);
    assert_eq!(s.test, vec![2..4]);
    assert_eq!(s.train, vec![0..2, 4..6]);
    // condition:2 → conditions sorted (1000 N, 2000 N): the 2nd is 2000 N.
    let s = Holdout::parse("condition:2").unwrap().split(&r);
    assert_eq!(s.test_indices(), vec![2, 3]);
    // default K = 5 with 3 runs would hold out nothing → the last run instead.
    let s = Holdout::parse("run").unwrap().split(&r);
    assert_eq!(s.test, vec![4..6]);
    // condition (2 conditions) → the last condition, 2000 N.
    let s = Holdout::parse("condition").unwrap().split(&r);
    assert_eq!(s.test, vec![2..4]);
    assert_eq!(Holdout::parse("none").unwrap().split(&r).train, vec![0..6]);
    // no sample in both halves, none lost
    let s = Holdout::parse("run:2").unwrap().split(&r);
    let mut all = s.train_indices();
    all.extend(s.test_indices());
    all.sort();
    assert_eq!(all, (0..6).collect::<Vec<_>>());
    // malformed segments (reversed, past the end) neither panic nor mark samples
    let mut odd = rec();
    odd.segments.push(seg(5, 3, 3000.0, 0.0));
    odd.segments.push(seg(4, 99, 3000.0, 0.0));
    let s2 = Holdout::parse("run:4").unwrap().split(&odd);
    assert_eq!(s2.test, vec![]);
    let m = evaluate(&odd, "Fy", &[1.0; 6], None).unwrap();
    // the 3000 N condition has only samples 4, 5 (from the in-range part of 4..99)
    assert_eq!(m.last().unwrap().n, 2);
    for bad in ["run:1", "run:x", "sideways"] {
        assert!(Holdout::parse(bad).is_err(), "{bad}");
    }
    // held-out metrics use only the held-out samples
    let sim = [1.0, 2.0, 4.0, 4.0, 5.0, 8.0];
    let m = evaluate(&r, "Fy", &sim, Some(&s.test)).unwrap();
    assert_eq!(m[0].n, 2);
    assert!((m[0].sigma - 0.2).abs() < 1e-15);
}

#[test]
fn report_table_is_aligned_and_json_round_trips() {
    let x = linspace(0.0, 1.0, 10);
    let y: Vec<f64> = x.iter().map(|&x| 1.0 + 2.0 * x).collect();
    let p = Curve::new(
        vec![Param::unbounded("a", 0.0), Param::unbounded("b", 0.0)],
        x,
        y,
        line_model,
        line_grad,
    );
    let out = fit(&p, None, None, &FitOptions::default(), "line", None).unwrap();
    let r = rec();
    let sim = [1.0, 2.0, 4.0, 4.0, 5.0, 8.0];
    let rep = FitReport {
        sources: vec!["test".into()],
        stages: vec![out],
        metrics: evaluate(&r, "Fy", &sim, None).unwrap(),
        ..Default::default()
    };
    let text = rep.to_text();
    assert!(text.contains("Stage 'line'") && text.contains("sigma [%]"));
    // Metrics table: every row has its right-aligned "n" column ending at the same place.
    let t = report::metrics_table(&rep.metrics);
    let lines: Vec<&str> = t.lines().collect();
    let header_n_end = lines[0].find("  n").unwrap() + 3;
    for l in &lines[2..] {
        assert_eq!(&l[header_n_end - 1..header_n_end].trim().len(), &1, "{t}");
    }
    // σ of the first row printed in percent: 100·√(5/91) = 23.44
    assert!(lines[2].contains("23.44"), "{t}");
    let js = rep.to_json().unwrap();
    let back: FitReport = serde_json::from_str(&js).unwrap();
    assert_eq!(back.stages[0].theta, rep.stages[0].theta);
    // serde_json's default float parser may be 1 ulp off (exact needs its
    // `float_roundtrip` feature), hence a relative 1e-15.
    for (a, b) in back.metrics.iter().zip(&rep.metrics) {
        assert_eq!(
            (a.n, &a.channel, a.condition),
            (b.n, &b.channel, b.condition)
        );
        for (u, v) in [(a.sigma, b.sigma), (a.nrmse, b.nrmse), (a.rms, b.rms)] {
            assert!((u - v).abs() <= 1e-15 * v.abs());
        }
    }
    assert!(js.contains("\"status\": \"fitted\""), "{js}");
}
