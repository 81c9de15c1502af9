//! Slip reference of a flat-belt recording (src/data/slip_reference.rs):
//! synthetic recordings written both ways — the tyre's slip referred to the
//! wheel plane (Vx = V·cos α) and to the belt speed (Vx = V) — are told apart
//! from their free-rolling samples, also with a large rolling resistance,
//! and the loader then derives κ in the recording's own reference.

use crate::common::scratch;
use std::path::{Path, PathBuf};
use tyrekit::data::slip_reference::{detect, SlipReference};
use tyrekit::data::{load, LoadOptions, Sample};

const R0: f64 = 0.30;
const CZ: f64 = 2.0e5;
const FNOM: f64 = 4000.0;
const V: f64 = 40.0 / 3.6;

/// A longitudinal force of the Magic Formula's form (Pacejka 3rd ed. eqs.
/// 4.E9–4.E18 with E = 0, no shifts) times a combined-slip weight
/// Gxα = cos(atan(Bxα·α)) (eq. 4.E57 with C = 1): enough physics for the
/// free-rolling torque balance the detection reads.
struct Tyre {
    /// Rolling resistance as Fx/Fz while rolling freely (≤ 0 physical).
    rr: f64,
}

impl Tyre {
    const B: f64 = 12.0;
    const C: f64 = 1.6;
    const MU: f64 = 1.1;
    const BXA: f64 = 8.0;
    fn re(fz: f64) -> f64 {
        R0 - fz / (3.0 * CZ)
    }
    fn gxa(alpha: f64) -> f64 {
        (Self::BXA * alpha).atan().cos()
    }
    fn fx(&self, fz: f64, kappa: f64, alpha: f64) -> f64 {
        Self::gxa(alpha) * Self::MU * fz * (Self::C * (Self::B * kappa).atan()).sin()
    }
    /// κ of the free-rolling torque balance Fx = rr·Fz at slip angle α.
    fn free_kappa(&self, alpha: f64) -> f64 {
        let f = self.rr / (Self::MU * Self::gxa(alpha));
        (f.asin() / Self::C).tan() / Self::B
    }
}

/// Deterministic noise in [−1, 1] (LCG): tests must not depend on a seed crate.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A programme at three loads: a free-rolling lateral sweep 0 → 12° → −12° →
/// 0 at 4°/s, then κ sweeps ±0.15 at α = 0 and −6° (100 Hz). The tyre's own
/// slip κ is referred to `reference`; Ω follows from it. Noise: 0.1 % on Ω,
/// 1 % of Fz on Fx. Returns the samples (vx left NaN) and the belt speed.
fn programme(tyre: &Tyre, reference: SlipReference, with_sweeps: bool) -> (Vec<Sample>, Vec<f64>) {
    let dt = 0.01;
    let mut noise = Lcg(7);
    let (mut out, mut belt) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    let mut push = |fz: f64, alpha: f64, kappa: f64, noise: &mut Lcg| {
        let vx_true = reference.vx(V, alpha);
        let omega = (1.0 + kappa) * vx_true / Tyre::re(fz) * (1.0 + 1e-3 * noise.next());
        let fx = tyre.fx(fz, kappa, alpha) + 0.01 * fz * noise.next();
        let fy = -Tyre::MU * fz * (1.3 * (10.0 * alpha).atan()).sin();
        out.push(Sample {
            time: t,
            vx: f64::NAN,
            omega,
            fz,
            kappa: f64::NAN,
            alpha,
            gamma: 0.0,
            phit: 0.0,
            p: 2.2e5,
            fx,
            fy,
            mx: f64::NAN,
            my: f64::NAN,
            mz: f64::NAN,
        });
        belt.push(V);
        t += dt;
    };
    for fz in [0.5 * FNOM, FNOM, 1.5 * FNOM] {
        // 0 → 12 → −12 → 0 degrees at 4°/s.
        let rate = 4f64.to_radians() * dt;
        let amax = 12f64.to_radians();
        let n = (amax / rate).round() as usize;
        let path = (0..n)
            .map(|i| i as f64 * rate)
            .chain((0..2 * n).map(|i| amax - i as f64 * rate))
            .chain((0..=n).map(|i| -amax + i as f64 * rate));
        for a in path {
            push(fz, a, tyre.free_kappa(a), &mut noise);
        }
        // Straight running between blocks.
        for _ in 0..300 {
            push(fz, 0.0, tyre.free_kappa(0.0), &mut noise);
        }
        if with_sweeps {
            for a in [0.0, -6f64.to_radians()] {
                for i in 0..=600 {
                    let k = 0.15 * (2.0 * std::f64::consts::PI * i as f64 / 600.0).sin();
                    push(fz, a, k, &mut noise);
                }
            }
        }
    }
    (out, belt)
}

#[test]
fn wheel_plane_and_belt_recordings_are_told_apart() {
    // Rolling resistance 1.5 % of Fz (a car tyre) and 10 % (a fitted
    // racing-tyre file with QSY1 = 0.1, as some real .tir files have).
    for rr in [-0.015, -0.10] {
        let tyre = Tyre { rr };
        let (s, v) = programme(&tyre, SlipReference::WheelPlane, true);
        let e = detect(&s, &v).expect("enough free-rolling samples");
        assert_eq!(e.reference, SlipReference::WheelPlane, "rr {rr}: {e:?}");
        // Wheel plane: V/Ω grows at least like 1/cos α (s ≥ 1), plus the
        // rolling-resistance drift; the noise moves s by < 0.1.
        assert!(e.share > 0.9, "rr {rr}: {e:?}");
        let (s, v) = programme(&tyre, SlipReference::Belt, true);
        let e = detect(&s, &v).expect("enough free-rolling samples");
        assert_eq!(e.reference, SlipReference::Belt, "rr {rr}: {e:?}");
        // Belt: s is the drift alone, ≥ 0 and well below 1 − MARGIN.
        assert!(e.share > -0.1 && e.share < 0.7, "rr {rr}: {e:?}");
        assert!(
            e.free_fx_ratio < 0.0,
            "free-rolling Fx is the rolling resistance: {e:?}"
        );
    }
}

#[test]
fn no_slip_angle_leverage_leaves_the_decision_open() {
    let tyre = Tyre { rr: -0.015 };
    let (s, v) = programme(&tyre, SlipReference::Belt, true);
    // Only the straight-running rows: nothing to regress on.
    let (s, v): (Vec<Sample>, Vec<f64>) = s
        .into_iter()
        .zip(v)
        .filter(|(x, _)| x.alpha.abs() < 0.5f64.to_radians())
        .unzip();
    assert!(detect(&s, &v).is_none());
}

fn write_csv(d: &Path, name: &str, s: &[Sample], v: &[f64]) -> PathBuf {
    let p = d.join(name);
    let mut txt = String::from(
        "Time [s],V [m/s],W [rad/s],SA [rad],IA [rad],Re [m],P [Pa],Fx [N],Fy [N],Fz [N]\n",
    );
    for (x, &vi) in s.iter().zip(v) {
        txt += &format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            x.time,
            vi,
            x.omega,
            x.alpha,
            x.gamma,
            vi / x.omega,
            x.p,
            x.fx,
            x.fy,
            x.fz
        );
    }
    std::fs::write(&p, txt).unwrap();
    p
}

#[test]
fn the_loader_derives_kappa_in_the_recordings_own_reference() {
    let tyre = Tyre { rr: -0.015 };
    let d = scratch("slipref");
    for reference in [SlipReference::WheelPlane, SlipReference::Belt] {
        let (s, v) = programme(&tyre, reference, true);
        let p = write_csv(d.path(), &format!("{reference:?}.csv"), &s, &v);
        let l = load(
            &p,
            &LoadOptions {
                remove_warmup: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(
            l.report.slip_reference.starts_with(reference.describe()),
            "{reference:?}: {}",
            l.report.slip_reference
        );
        // κ at the ±6° points of the free-rolling lateral sweep relative to
        // straight free rolling: the tyre's own change is
        // free_kappa(6°) − free_kappa(0) (≈ −1e-3, the rolling resistance
        // under Gxα); the other reference would be off by 1/cos 6° − 1 =
        // 5.5e-3. Tolerance 1e-3: Ω noise 1e-3 averaged over > 50 rows.
        let six = 6f64.to_radians();
        let mean_kappa = |sel: &dyn Fn(&Sample) -> bool| {
            let k: Vec<f64> = l
                .recording
                .samples
                .iter()
                .filter(|x| sel(x))
                .map(|x| x.kappa)
                .collect();
            assert!(k.len() > 50, "{reference:?}: {} rows", k.len());
            k.iter().sum::<f64>() / k.len() as f64
        };
        // The lateral sweep passes ±6° moving; the drive/brake block sits at
        // exactly −6° and is left out.
        let at6 = mean_kappa(&|x| {
            (x.alpha.abs() - six).abs() < 0.2f64.to_radians() && (x.alpha + six).abs() > 1e-9
        });
        let at0 = mean_kappa(&|x| x.alpha == 0.0 && x.fx.abs() < 0.05 * x.fz);
        let want = tyre.free_kappa(six) - tyre.free_kappa(0.0);
        assert!(
            (at6 - at0 - want).abs() < 1e-3,
            "{reference:?}: κ(6°) − κ(0) = {:.5} vs the tyre's {want:.5}",
            at6 - at0
        );
    }
}
