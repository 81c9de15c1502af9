//! The `pressure` candidate on a *continuously varying* recorded pressure
//! (a leak-and-refill saw-tooth about one set point, not discrete levels),
//! against two pressure laws written here — neither is the MF's own form
//! nor the project rig's `Pressure` scaling:
//! * stiffness only: the tyre sees its slips scaled by c = 1 + A·dp
//!   (κ·c, tan α·c): slip stiffnesses ∝ c, peak forces unchanged;
//! * friction only: the similarity method (Pacejka, *Tyre and Vehicle
//!   Dynamics*, 3rd ed., §4.3.2) F = s·F_MF(κ/s, tan α/s), s = 1 − A·dp:
//!   peak forces ∝ s, slip stiffnesses unchanged;
//!
//! dp = p/p_set − 1. Asserted: the verdict is `pressure` and the fitted MF
//! terms put the change where the law put it (stiffness terms for the
//! first, friction terms for the second); the same drifting pressure on a
//! tyre without a law gives `none`; the report's first plot is the
//! residual against pressure.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tyrekit::data::structure::sweep_and_time;
use tyrekit::data::{Recording, SAMPLE_CHANNELS};
use tyrekit::diagnose::replay::ReplayOptions;
use tyrekit::diagnose::report::diagnose;
use tyrekit::mf::{Forces, MfInput, Tyre, UseMode};
use tyrekit::rig::{radii, simulate, Noise, RigConfig, RigInput, TruthModel, TruthOutput};

/// Saw-tooth of the recorded pressure: ±4 % about the set point, the tyre
/// warming up (pressure rising) over 60 % of the programme, then let down
/// to the low end once and rising again — as the dev set's unregulated
/// recordings do. One drop in the middle: a rise alone is confounded with
/// any state that grows with time (a tread temperature), the drop is not.
const SPAN: f64 = 0.04;
/// Share of the programme's duration one rise lasts.
const RISE: f64 = 0.6;
/// Law strength: 2 % of stiffness or friction per 1 % of pressure (within
/// the ±5 the candidate admits; published MF 6.1 fits carry |PPY1| ≈ 0.4–1.5).
const A: f64 = 2.0;

fn pressure_at(p_set: f64, period: f64, t: f64) -> f64 {
    let phase = (t / period).rem_euclid(1.0);
    p_set * (1.0 + SPAN * (2.0 * phase - 1.0))
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Law {
    None,
    Stiffness,
    Friction,
}

struct PressureLaw {
    tyre: Tyre,
    mode: UseMode,
    law: Law,
    p_set: f64,
    /// Duration of one rise (s).
    period: f64,
}

impl TruthModel for PressureLaw {
    fn sample(&mut self, inp: &RigInput, _dt: f64) -> TruthOutput {
        let p = pressure_at(self.p_set, self.period, inp.time);
        let dp = p / self.p_set - 1.0;
        let (c, s) = match self.law {
            Law::None => (1.0, 1.0),
            Law::Stiffness => (1.0 + A * dp, 1.0),
            Law::Friction => (1.0, 1.0 - A * dp),
        };
        let m = MfInput {
            p,
            kappa: inp.mf.kappa * c / s,
            alpha: (inp.mf.alpha.tan() * c / s).atan(),
            ..inp.mf
        };
        let o = self.tyre.evaluate(&m, self.mode);
        let (re, rl) = radii(&self.tyre, inp.mf.fz, o.re, o.rl);
        TruthOutput {
            forces: Forces {
                fx: s * o.fx,
                fy: s * o.fy,
                mx: o.mx,
                my: o.my,
                mz: s * o.mz,
            },
            re,
            rl,
            tread_temp: f64::NAN,
        }
    }
    fn describe(&self) -> String {
        format!("pressure law {:?}, A = {A}", self.law)
    }
}

fn mode() -> UseMode {
    UseMode {
        limits: false,
        alpha_star: false,
        turn_slip: false,
    }
}

/// The truth of a reduced programme at one pressure set point, with the
/// recorded pressure following the saw-tooth (plus 0.1 kPa sensor noise)
/// and 12 N / 0.4 N·m white noise on the forces (the rig's default levels).
fn recording(tyre: &Tyre, law: Law) -> Recording {
    recording_rising_over(tyre, law, RISE)
}

/// [`recording`] with one rise of the pressure lasting `rise` of the
/// programme's duration (> 1: it rises through the whole run, never let down).
fn recording_rising_over(tyre: &Tyre, law: Law, rise: f64) -> Recording {
    let mut cfg = RigConfig::standard(tyre, 23);
    cfg.noise = Noise::none();
    let pr = &mut cfg.programme;
    pr.pressures.truncate(2);
    pr.pressures.remove(0); // the nominal pressure only
    pr.inclinations.truncate(1);
    pr.loads.truncate(3);
    pr.db_alphas.truncate(2);
    let p_set = pr.pressures[0];
    let mut m = PressureLaw {
        tyre: tyre.clone(),
        mode: mode(),
        law: Law::None,
        p_set,
        period: f64::INFINITY,
    };
    // The programme's duration from a first run, then the run with the law.
    let duration = simulate(&cfg, &mut m)
        .truth
        .last()
        .map_or(600.0, |s| s.time);
    m.law = law;
    m.period = rise * duration;
    let run = simulate(&cfg, &mut m);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut g = || {
        let u1: f64 = rng.gen::<f64>().max(1e-300);
        let u2: f64 = rng.gen();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let mut samples = run.truth;
    for s in &mut samples {
        s.p = pressure_at(p_set, m.period, s.time) + 100.0 * g();
        s.fx += 12.0 * g();
        s.fy += 12.0 * g();
        s.mz += 0.4 * g();
    }
    as_recording(format!("{law:?}"), samples, run.plan)
}

/// Samples and the programme's segments as a recording.
fn as_recording(
    source: String,
    samples: Vec<tyrekit::data::Sample>,
    segments: Vec<tyrekit::data::Segment>,
) -> Recording {
    let (sweep_dir, t_in_segment) = sweep_and_time(&samples, &segments);
    Recording {
        source,
        samples,
        channels: SAMPLE_CHANNELS.iter().map(|c| c.to_string()).collect(),
        extra: vec![],
        segments,
        sweep_dir,
        t_in_segment,
    }
}

fn opts() -> ReplayOptions {
    ReplayOptions {
        use_mode: mode(),
        ..Default::default()
    }
}

/// The pressure candidate's fitted parameter `k` of a diagnosis.
fn fitted(d: &tyrekit::diagnose::report::Diagnosis, k: &str) -> f64 {
    d.json()["effects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["name"] == "pressure")
        .and_then(|e| e["parameters"][k].as_f64())
        .unwrap_or(f64::NAN)
}

fn show(d: &tyrekit::diagnose::report::Diagnosis) {
    println!("verdict {}: {}", d.verdict(), d.explanation());
    for e in d.json()["effects"].as_array().unwrap() {
        println!(
            "  {:<18} gain {:+.3} dBIC {:+.1} {} {}",
            e["name"].as_str().unwrap_or(""),
            e["score"].as_f64().unwrap_or(f64::NAN),
            e["delta_bic"].as_f64().unwrap_or(f64::NAN),
            e["channels"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|c| format!(
                    "{} {:+.3}",
                    c["channel"],
                    c["oos_gain"].as_f64().unwrap_or(f64::NAN)
                ))
                .collect::<Vec<_>>()
                .join(", "),
            e["parameters"]
        );
    }
}

#[test]
fn stiffness_law_is_named_pressure_with_stiffness_terms() {
    let tyre = Tyre::builtin();
    let base = |k: &str| tyre.params().get(k).unwrap();
    let rec = recording(&tyre, Law::Stiffness);
    let d = diagnose(&rec, &tyre, &opts()).unwrap();
    show(&d);
    assert_eq!(d.verdict(), "pressure");
    // The law adds A to the stiffness terms of the file (Kyα, Kxκ ∝
    // (1 + PP?1·dpi)) in pure slip; it also scales combined slips and
    // stretches Mz's trail curve, which the MF's terms do not, so the fit
    // takes a part of it: a rise between A/4 and 1.5·A.
    for k in ["PPY1", "PPX1"] {
        let add = fitted(&d, k) - base(k);
        assert!(
            add > 0.25 * A && add < 1.5 * A,
            "{k}: fitted change {add:.3}, law {A}"
        );
    }
    // Friction unchanged: the friction terms move far less than the stiffness terms.
    for (f, s) in [("PPY3", "PPY1"), ("PPX3", "PPX1")] {
        let (df, ds) = (fitted(&d, f) - base(f), fitted(&d, s) - base(s));
        assert!(df.abs() < 0.5 * ds.abs(), "{f} moved {df:.3}, {s} {ds:.3}");
    }
    // The words state the fitted law in kPa: Kyα ∝ (1 + PPY1·dpi) at
    // dpi = 10 kPa / NOMPRES (Pacejka, eq. 4.E25, 4.E2b).
    let p0 = base("NOMPRES");
    let at = format!("at +10 kPa over {:.0} kPa", p0 / 1e3);
    let ky = format!(
        "Fy cornering stiffness {:+.1} %",
        100.0 * 10e3 / p0 * fitted(&d, "PPY1")
    );
    let e = d.explanation();
    assert!(e.contains(&at) && e.contains(&ky), "{at} / {ky}: {e}");
}

#[test]
fn friction_law_is_named_pressure_with_friction_terms() {
    let tyre = Tyre::builtin();
    let base = |k: &str| tyre.params().get(k).unwrap();
    let rec = recording(&tyre, Law::Friction);
    let d = diagnose(&rec, &tyre, &opts()).unwrap();
    show(&d);
    assert_eq!(d.verdict(), "pressure");
    // μ ∝ (1 + PP?3·dpi) against s = 1 − A·dp: −A on top of the file's
    // value; between −1.5·A and −A/4 as for the stiffness law.
    for k in ["PPY3", "PPX3"] {
        let add = fitted(&d, k) - base(k);
        assert!(
            add < -0.25 * A && add > -1.5 * A,
            "{k}: fitted change {add:.3}, law {}",
            -A
        );
    }
    // The report shows the verdict's own evidence first.
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose_pressure");
    std::fs::create_dir_all(&dir).unwrap();
    let plots = tyrekit::diagnose::plots::draw_all(&rec, &d, &dir).unwrap();
    assert!(
        plots[0].file.starts_with("residual_pressure_"),
        "first plot {}",
        plots[0].file
    );
    assert!(dir.join(&plots[0].file).is_file());
}

#[test]
fn drifting_pressure_without_a_law_is_none() {
    let tyre = Tyre::builtin();
    let d = diagnose(&recording(&tyre, Law::None), &tyre, &opts()).unwrap();
    show(&d);
    assert_eq!(d.verdict(), "none");
    // Let down once: pressure and time are told apart, nothing to qualify.
    assert!(
        !d.explanation()
            .contains("cannot be told from any other slow drift"),
        "{}",
        d.explanation()
    );
}

/// A pressure that only rises through the run (a warming tyre never let
/// down) cannot be told from any other slow drift: with no law in the
/// forces the verdict stays `none`, but the words must not claim that
/// nothing is missing without saying what the recording cannot separate.
#[test]
fn a_pressure_rising_through_the_run_qualifies_nothing_missing() {
    let tyre = Tyre::builtin();
    let d = diagnose(
        &recording_rising_over(&tyre, Law::None, 1.2),
        &tyre,
        &opts(),
    )
    .unwrap();
    show(&d);
    assert_eq!(d.verdict(), "none");
    let e = d.explanation();
    assert!(!e.starts_with("Nothing is missing:"), "{e}");
    assert!(
        e.contains("cannot be told from any other slow drift"),
        "{e}"
    );
    assert!(e.contains("rises"), "{e}");
}

/// Each channel's BIC charges the pressure terms that can move it
/// (PPX1, PPX3 in Fx; PPY1, PPY3 in Fy; PPY1, PPY3, PPZ1 in Mz — Pacejka,
/// *Tyre and Vehicle Dynamics*, 3rd ed., eqs. 4.E13–4.E42), not all five:
/// a 5-term candidate whose evidence lives in one channel would otherwise
/// pay for the other channel's terms (dev-set r09: a recorded pressure
/// drift that moves Fy 3.9 % held out was `none` until this).
#[test]
fn each_channel_is_charged_the_pressure_terms_acting_on_it() {
    use tyrekit::diagnose::candidate::{all, evaluate, FX, FY, MZ};
    let tyre = Tyre::builtin();
    let rec = recording(&tyre, Law::Stiffness);
    let cands = all();
    let pressure: Vec<&dyn tyrekit::diagnose::candidate::Candidate> = cands
        .iter()
        .filter(|c| c.name() == "pressure")
        .map(|c| c.as_ref())
        .collect();
    let ev = evaluate(&rec, &tyre, &opts(), &pressure).unwrap();
    let (e, fitted) = &ev[0];
    assert_eq!(e.n_params, 5);
    let on: Vec<usize> = [FX, FY, MZ]
        .iter()
        .map(|&j| fitted.parameters_on(j))
        .collect();
    assert_eq!(on, [2, 2, 3]);
}

/// The confound a real rig has: an unregulated tyre's pressure rises as it
/// warms (gas law, p ∝ absolute temperature), so a thermal effect comes
/// with a recorded pressure that follows the tread temperature. The forces
/// carry the rig's thermal truth only (friction with temperature, at
/// strength `level`), no pressure law. Returns the diagnosis.
fn heating_with_gas_law_pressure(level: f64) -> tyrekit::diagnose::report::Diagnosis {
    use tyrekit::rig::effects;
    // A tyre without pressure terms, as the diagnosis's own baseline is
    // (`diagnose::baseline`): with the built-in file's terms, the baseline
    // itself would answer the drifting recorded pressure, which the truth
    // (run at the set pressure) does not.
    let mut params = Tyre::builtin().params().clone();
    for k in tyrekit::diagnose::baseline::HELD_PRESSURE_KEYS {
        params.set(k, 0.0).unwrap();
    }
    let tyre = Tyre::new(params).unwrap();
    let mut cfg = RigConfig::standard(&tyre, 31);
    cfg.noise = Noise::none();
    let pr = &mut cfg.programme;
    pr.pressures.truncate(2);
    pr.pressures.remove(0);
    pr.inclinations.truncate(1);
    pr.loads.truncate(3);
    pr.db_alphas.truncate(2);
    let p_set = pr.pressures[0];
    let mut truth = effects::concealed("thermal", tyre.clone(), level).unwrap();
    let run = simulate(&cfg, truth.as_mut());
    // The rig's tread temperature channel, row by row with the truth.
    let tc = run.table.column("TSTC").expect("TSTC").data.clone();
    let t0 = tc[0];
    let mut samples = run.truth;
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let mut g = || {
        let u1: f64 = rng.gen::<f64>().max(1e-300);
        let u2: f64 = rng.gen();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    for (s, t) in samples.iter_mut().zip(&tc) {
        s.p = p_set * (273.15 + t) / (273.15 + t0) + 100.0 * g();
        s.fx += 12.0 * g();
        s.fy += 12.0 * g();
        s.mz += 0.4 * g();
    }
    let rec = as_recording("thermal, pressure by the gas law".into(), samples, run.plan);
    let d = diagnose(&rec, &tyre, &opts()).unwrap();
    show(&d);
    d
}

/// Heating with a pressure that follows the tread temperature exactly: a
/// pressure law with friction falling as the pressure rises can stand in
/// for part of it, so `pressure` also qualifies, but the thermal law, which
/// has the heating's dynamics and acts on every channel alike, must win —
/// at the rig's strength (friction −12 … +2 % over the run; measured pooled
/// BIC −336 against −68) and at 0.3 of it (−123 against −37) — with
/// `pressure` reported beside it. Each channel's BIC charging only the
/// pressure terms acting on it does not decide this: the winner among
/// qualifying candidates is chosen on the pooled BIC, which charges all.
/// (Run with the built-in file's own pressure terms as baseline, the weak
/// case went to `pressure`: that baseline answered the drifting recorded
/// pressure itself, and the candidate's terms undid it.)
#[test]
fn a_pressure_that_follows_the_tread_temperature_does_not_turn_heating_into_pressure() {
    for level in [1.0, 0.3] {
        let d = heating_with_gas_law_pressure(level);
        assert_eq!(d.verdict(), "thermal", "level {level}: {}", d.explanation());
        assert!(
            d.report.also_qualifying.iter().any(|c| c == "pressure"),
            "level {level}: pressure not reported beside thermal: {}",
            d.explanation()
        );
    }
}
