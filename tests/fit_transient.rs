//! The relaxation-length stage (`tyrekit fit --only transient`,
//! `tyrekit::fit::transient`): rig recordings whose truth is this
//! project's relaxation model (the code the FMU runs) with a known lateral
//! and longitudinal carcass stiffness → the fitted relaxation lengths come
//! back near the truth's; a steady truth → the lag is reported as not
//! identified and the start keys are kept.

use crate::common::scratch;
use tyrekit::data::Recording;
use tyrekit::fit::transient::{fit_relaxation, nominal_sigma};
use tyrekit::mf::{Forces, Tyre, UseMode};
use tyrekit::rig::{simulate, RigConfig, RigInput, SteadyMf, TruthModel, TruthOutput};
use tyrekit::tir::TyreParams;
use tyrekit::transient::{InputMode, TransientConfig, TransientKind, TransientModel, WheelInput};

/// This project's relaxation model as the rig's truth (radii from the
/// steady MF, as the rig's own effects do).
struct ProjectRelaxation {
    steady: SteadyMf,
    model: TransientModel,
}

impl ProjectRelaxation {
    fn new(tyre: Tyre) -> Self {
        ProjectRelaxation {
            steady: SteadyMf::new(tyre),
            model: TransientModel::new(TransientConfig {
                kind: TransientKind::Relaxation,
                input_mode: InputMode::Slips,
                use_mode: UseMode::default(),
            }),
        }
    }
}

impl TruthModel for ProjectRelaxation {
    fn sample(&mut self, inp: &RigInput, dt: f64) -> TruthOutput {
        let mut out = self.steady.sample(inp, dt);
        let m = &inp.mf;
        let w = WheelInput {
            vx: m.vx,
            omega: m.omega,
            fz: m.fz,
            gamma: m.gamma,
            p: m.p,
            kappa_in: m.kappa,
            alpha_in: m.alpha,
            ..Default::default()
        };
        out.forces = match self.model.step(&self.steady.tyre, &w, dt) {
            Ok(o) => Forces {
                fx: o.fx,
                fy: o.fy,
                mx: o.mx,
                my: o.my,
                mz: o.mz,
            },
            Err(_) => Forces::default(),
        };
        out
    }
    fn reset(&mut self) {
        self.model.reset()
    }
    fn describe(&self) -> String {
        "relaxation (project model)".into()
    }
}

/// A short programme (one pressure and inclination, three loads, drive/brake
/// at α = 0 only) at a sweep rate fast enough for the lag to show: 20°/s in
/// α and 1/s in κ at 40 km/h, i.e. the slip changes by ≈ 0.03 rad (0.009)
/// per σ ≈ 0.6 m rolled (0.3 m), a hysteresis of several hundred newtons.
fn config(truth: &Tyre) -> RigConfig {
    let mut cfg = RigConfig::standard(truth, 7);
    let pr = &mut cfg.programme;
    pr.pressures.truncate(1);
    pr.inclinations.truncate(1);
    pr.loads = vec![pr.loads[1], pr.loads[0], pr.loads[2]];
    pr.db_alphas.truncate(1);
    pr.alpha_rate = 20f64.to_radians();
    pr.kappa_rate = 1.0;
    pr.warmup = None;
    cfg
}

fn recording(truth: &TyreParams, model: &mut dyn TruthModel) -> Recording {
    let t = Tyre::new(truth.clone()).unwrap();
    let run = simulate(&config(&t), model);
    // The file is read back whole here, so its folder ends with this call.
    let d = scratch("fit-transient");
    let path = d.path().join(format!("{}.mat", model.describe().len()));
    run.write_mat(&path, true).unwrap();
    Recording::from_file(&path).unwrap()
}

/// The truth: the built-in tyre with carcass stiffnesses that make its
/// relaxation lengths differ from the start's by a factor 1.6 (σα) and
/// 0.7 (σκ).
fn truth_and_start() -> (TyreParams, TyreParams) {
    let start = TyreParams::builtin();
    let mut truth = start.clone();
    let cy = start.get("LATERAL_STIFFNESS").unwrap();
    let cx = start.get("LONGITUDINAL_STIFFNESS").unwrap();
    truth.set("LATERAL_STIFFNESS", cy / 1.6).unwrap();
    truth.set("LONGITUDINAL_STIFFNESS", cx / 0.7).unwrap();
    (truth, start)
}

#[test]
fn relaxation_lengths_come_back_from_a_lagged_rig_recording() {
    let (truth, start) = truth_and_start();
    let tt = Tyre::new(truth.clone()).unwrap();
    let mut model = ProjectRelaxation::new(tt.clone());
    let rec = recording(&truth, &mut model);
    let mut fitted = start.clone();
    let (fits, skipped) = fit_relaxation(&[rec], &mut fitted, None, 100).unwrap();
    assert!(skipped.is_empty(), "{skipped:?}");
    assert_eq!(fits.len(), 2);
    for f in &fits {
        let lateral = f.channel == "Fy";
        let want = nominal_sigma(&tt, lateral);
        eprintln!(
            "{}: {} {:.6e} → {:.6e}; σ start {:.4} m, fitted {:.4} m, truth {:.4} m; cost steady {:.4e} start {:.4e} fitted {:.4e} ({} replays)",
            f.channel, f.key, f.start, f.value, f.sigma_start, f.sigma, want, f.cost_steady, f.cost_start, f.cost, f.evaluations
        );
        assert!(f.identified, "{}: {}", f.channel, f.note);
        // Tolerance 3 %: the truth is the fitted model itself, so only the
        // rig's sensor noise (12 N on Fx, Fy; 0.02° on α; speed 0.02 m/s)
        // and the search resolution (0.4 % in σ) separate them; 3 % is
        // about five times the spread seen between noise seeds.
        assert!(
            (f.sigma / want - 1.0).abs() < 0.03,
            "{}: σ fitted {} m, truth {} m",
            f.channel,
            f.sigma,
            want
        );
        assert!(f.cost < 0.5 * f.cost_start && f.cost < f.cost_steady);
        // The key written is the one fitted; nothing else changed.
        assert_eq!(fitted.get(&f.key), Some(f.value));
    }
    for (k, v) in start.p.as_slice().iter().enumerate() {
        let name = tyrekit::tir::keys::KEYS[k].name;
        if name != "LATERAL_STIFFNESS" && name != "LONGITUDINAL_STIFFNESS" {
            assert_eq!(
                fitted.p.as_slice()[k].to_bits(),
                v.to_bits(),
                "{name} changed"
            );
        }
    }
}

#[test]
fn a_steady_truth_shows_no_lag() {
    let (_, start) = truth_and_start();
    let mut model = SteadyMf::new(Tyre::new(start.clone()).unwrap());
    let rec = recording(&start, &mut model);
    let mut fitted = start.clone();
    let (fits, _) = fit_relaxation(&[rec], &mut fitted, None, 100).unwrap();
    assert_eq!(fits.len(), 2);
    for f in &fits {
        eprintln!(
            "{}: identified {} ({}); σ fitted {:.4} m; cost steady {:.4e} fitted {:.4e}",
            f.channel, f.identified, f.note, f.sigma, f.cost_steady, f.cost
        );
        assert!(!f.identified, "{}: a lag 'found' in steady data", f.channel);
        assert_eq!(f.value, f.start);
        assert_eq!(fitted.get(&f.key), start.get(&f.key));
    }
}

#[test]
fn the_staged_fit_runs_the_transient_stage_when_asked() {
    let (truth, start) = truth_and_start();
    let tt = Tyre::new(truth.clone()).unwrap();
    let mut model = ProjectRelaxation::new(tt.clone());
    let rec = recording(&truth, &mut model);
    let opts = tyrekit::fit::mf_fit::MfFitOptions {
        only: vec![],
        transient: true,
        nominal_from_data: false,
        ..Default::default()
    };
    let res = tyrekit::fit::mf_fit::fit_mf(&[rec], start, &opts, None).unwrap();
    assert_eq!(res.report.relaxation.len(), 2);
    assert!(res.report.relaxation.iter().all(|f| f.identified));
    let text = res.report.to_text();
    assert!(text.contains("Stage transient") && text.contains("LATERAL_STIFFNESS"));
    let lat = &res.report.relaxation[0];
    assert_eq!(res.tyre.get("LATERAL_STIFFNESS"), Some(lat.value));
}
