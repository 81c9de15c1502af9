//! `extended.tir` holds the verdict refitted on every segment
//! (`candidate::refit_on_all`), not the half fit that was scored: the
//! selection is made out of sample, the estimate then uses all the data.

use crate::common;

use tyrekit::diagnose::candidate::{all, evaluate, held_out_sse, refit_on_all};
use tyrekit::diagnose::report::diagnose;
use tyrekit::mf::Tyre;
use tyrekit::rig::effects::{Scaling, ScalingKind};
use tyrekit::rig::{simulate, RigConfig};

#[test]
fn the_extended_file_is_the_verdict_refitted_on_both_halves() {
    let tyre = Tyre::builtin();
    // Peak friction 8 % lower per unit dfz (the rig's load sensitivity),
    // three loads, one pressure and inclination, 12 N / 0.4 N·m noise.
    let mut m = Scaling::new(tyre.clone(), ScalingKind::LoadSensitivity, 0.08);
    let mut cfg = RigConfig::standard(&tyre, 11);
    cfg.noise = tyrekit::rig::Noise::none();
    cfg.programme.pressures.truncate(1);
    cfg.programme.inclinations.truncate(1);
    cfg.programme.loads.truncate(3);
    cfg.programme.db_alphas.truncate(2);
    let rec = common::noisy_recording(simulate(&cfg, &mut m), "load", 12.0, 0.4, 3);
    let opts = common::diagnose_opts();

    let d = diagnose(&rec, &tyre, &opts).unwrap();
    assert_eq!(d.verdict(), "load_sensitivity", "{}", d.explanation());

    // The report names what the file holds.
    let written = d
        .report
        .extended_parameters
        .as_ref()
        .expect("refit parameters");
    assert!(!written.is_empty());
    let cands = all();
    let named = cands
        .iter()
        .find(|c| c.name() == "load_sensitivity")
        .unwrap();
    let refit = refit_on_all(&rec, &tyre, &opts, named.as_ref()).unwrap();
    for (k, v) in refit.parameters() {
        assert_eq!(written.get(&k), Some(&v), "{k}: report against refit");
    }

    // The refit has seen the held-out half, the half fit has not: on that
    // half the refit must fit strictly better. Equal figures would mean the
    // "refit" never saw it (the same LM from the same start on the same
    // samples gives bit-identical parameters).
    let refs: Vec<_> = cands.iter().map(|c| c.as_ref()).collect();
    let ev = evaluate(&rec, &tyre, &opts, &refs).unwrap();
    let half = &ev
        .iter()
        .find(|(e, _)| e.name == "load_sensitivity")
        .unwrap()
        .1;
    let sse_half = held_out_sse(&rec, &half.predict(&rec).unwrap());
    let sse_refit = held_out_sse(&rec, &refit.predict(&rec).unwrap());
    let sse_ext = held_out_sse(&rec, &d.extended_sim);
    println!("held-out SSE: half fit {sse_half:.6}, refit {sse_refit:.6}, extended {sse_ext:.6}");
    assert!(sse_refit < sse_half, "{sse_refit} !< {sse_half}");
    // And what the plots draw is the file's simulation.
    assert_eq!(sse_ext, sse_refit);
}
