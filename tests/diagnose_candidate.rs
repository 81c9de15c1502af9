//! The relaxation candidate: named on a slip-lag truth, not on the control.

use crate::common;

use tyrekit::data::Recording;
use tyrekit::diagnose::replay::ReplayOptions;
use tyrekit::diagnose::report::diagnose;
use tyrekit::mf::Tyre;
use tyrekit::rig::{effects, simulate, Noise, RigConfig};

/// The rig's ISO-W truth of a short programme, with 12 N / 0.4 N·m white
/// sensor noise added to the forces (the rig's default levels).
fn recording(tyre: &Tyre, effect: &str) -> Recording {
    let mut cfg = RigConfig::standard(tyre, 11);
    cfg.noise = Noise::none();
    cfg.programme.pressures.truncate(1);
    cfg.programme.inclinations.truncate(1);
    cfg.programme.loads.truncate(3);
    cfg.programme.db_alphas.truncate(2);
    let mut m = effects::concealed(effect, tyre.clone(), 1.0).unwrap();
    common::noisy_recording(simulate(&cfg, m.as_mut()), effect, 12.0, 0.4, 5)
}

fn opts() -> ReplayOptions {
    common::diagnose_opts()
}

#[test]
fn relaxation_is_named_on_lagged_truth_and_none_on_control() {
    let tyre = Tyre::builtin();
    let d = diagnose(&recording(&tyre, "relaxation"), &tyre, &opts()).unwrap();
    println!(
        "{}",
        serde_json::to_string_pretty(&d.json()["effects"]).unwrap()
    );
    println!(
        "FY locate: {}",
        serde_json::to_string(&d.json()["locate"]["FY"][0]).unwrap()
    );
    assert_eq!(d.verdict(), "relaxation");
    assert_eq!(d.json()["effects"][0]["name"], "relaxation");
    // Held-out gain: the truth lags the slips, the candidate the contact
    // deflections (another formulation), so not all of it goes; measured
    // 39 %, a fifth is the floor that still means "the lag was found".
    let gain = d.json()["effects"][0]["score"].as_f64().unwrap();
    assert!(gain > 0.2, "held-out gain {gain}");
    // The lag shows as sweep-direction or force-rate structure in Fy.
    let top = d.json()["locate"]["FY"][0]["name"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        top == "sweep_direction" || top == "force_rate",
        "top finding {top}"
    );

    let c = diagnose(&recording(&tyre, "none"), &tyre, &opts()).unwrap();
    println!(
        "{}",
        serde_json::to_string_pretty(&c.json()["effects"]).unwrap()
    );
    assert_eq!(c.verdict(), "none");
    let c_json = c.json();
    let rel = c_json["effects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["name"] == "relaxation")
        .unwrap();
    assert!(
        rel["score"].as_f64().unwrap() < 0.01,
        "control: relaxation gains {}",
        rel["score"]
    );
}
