//! Road friction scale (`Tyre::evaluate_mu`, `forces_mu`) and the zero-slip
//! properties (`Tyre::slip_properties`). Expected values come from the Magic
//! Formula's structure (peak = D, slope at the shifted origin = B·C·D = K),
//! never from the code under test.

use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::tir::TyreParams;

const MODES: [UseMode; 4] = [
    UseMode {
        limits: true,
        alpha_star: false,
        turn_slip: false,
    },
    UseMode {
        limits: false,
        alpha_star: false,
        turn_slip: false,
    },
    UseMode {
        limits: true,
        alpha_star: true,
        turn_slip: true,
    },
    UseMode {
        limits: false,
        alpha_star: false,
        turn_slip: true,
    },
];

const NO_LIMITS: UseMode = UseMode {
    limits: false,
    alpha_star: false,
    turn_slip: false,
};

fn grid() -> Vec<MfInput> {
    let mut v = Vec::new();
    for fz in [0.0, 1500.0, 4000.0, 7000.0] {
        for kappa in [-0.3, -0.02, 0.0, 0.05, 0.5] {
            for alpha in [-0.4, 0.0, 0.03, 0.2] {
                for (gamma, phit, vx) in [(0.0, 0.0, 20.0), (0.05, 0.1, -3.0), (-0.03, 0.0, 0.5)] {
                    v.push(MfInput {
                        fz,
                        kappa,
                        alpha,
                        gamma,
                        phit,
                        vx,
                        p: 0.0,
                        omega: 0.0,
                    });
                }
            }
        }
    }
    v
}

fn bits(a: &[f64]) -> Vec<u64> {
    a.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn mu_scale_one_is_bit_identical() {
    let t = Tyre::builtin();
    for mode in MODES {
        for x in grid() {
            let a = t.evaluate(&x, mode);
            let b = t.evaluate_mu(&x, mode, 1.0);
            assert_eq!(bits(&a.to_array()), bits(&b.to_array()), "{x:?} {mode:?}");
            let f = t.forces(&x, mode);
            let g = t.forces_mu(&x, mode, 1.0);
            assert_eq!(
                bits(&[f.fx, f.fy, f.mx, f.my, f.mz]),
                bits(&[g.fx, g.fy, g.mx, g.my, g.mz])
            );
        }
    }
}

/// The built-in MF 6.1 tyre with the pure-slip shifts removed, so that the
/// slope at the origin is exactly B·C·D = K (at γ = 0).
fn unshifted() -> Tyre {
    let mut t = TyreParams::builtin();
    for k in [
        "PHX1", "PHX2", "PVX1", "PVX2", "PHY1", "PHY2", "PVY1", "PVY2",
    ] {
        assert!(t.p.set(k, 0.0), "{k}");
    }
    Tyre::new(t).unwrap()
}

fn at(fz: f64, kappa: f64, alpha: f64) -> MfInput {
    MfInput {
        fz,
        kappa,
        alpha,
        vx: 20.0,
        ..Default::default()
    }
}

#[test]
fn half_friction_halves_peak_and_keeps_stiffness() {
    let t = unshifted();
    for fz in [2000.0, 4000.0, 6500.0] {
        // Peaks of D·sin(C·atan(…)) over a sweep of step 1e-4: both sweeps
        // reach the maximum (sin = 1) well inside the range, so peak ∝ D ∝ μ.
        // Grid error near a smooth maximum ≤ ½(B·C·Δ)² ≈ ½(40·1.4·1e-4)² ≈ 2e-5
        // at worst (B doubles at μ = 0.5); it is one-sided, so compare at 5e-5.
        let peak = |mu: f64, lat: bool| {
            (1..=8000)
                .map(|i| {
                    let s = i as f64 * 1e-4;
                    let x = if lat { at(fz, 0.0, s) } else { at(fz, s, 0.0) };
                    let f = t.forces_mu(&x, NO_LIMITS, mu);
                    if lat {
                        f.fy.abs()
                    } else {
                        f.fx.abs()
                    }
                })
                .fold(0.0, f64::max)
        };
        for lat in [true, false] {
            let (p1, p2) = (peak(1.0, lat), peak(0.5, lat));
            assert!(
                (p2 / p1 - 0.5).abs() < 5e-5,
                "peak ratio {} (lateral {lat}, Fz {fz})",
                p2 / p1
            );
        }
        // Slope at the origin: B·C·D = Kyα and Kxκ (4.E25, 4.E15), neither of
        // which contains λμ. Central difference, h = 1e-6: truncation
        // ~(B·h)² ≤ 2e-9, rounding ~1e-16·Fz/h ≈ 1e-12 relative → 1e-6.
        let h = 1e-6;
        let o1 = t.evaluate(&at(fz, 0.0, 0.0), NO_LIMITS);
        let o2 = t.evaluate_mu(&at(fz, 0.0, 0.0), NO_LIMITS, 0.5);
        assert_eq!(o1.kya, o2.kya);
        assert_eq!(o1.kxk, o2.kxk);
        // ×0.5 is exact in binary: the friction coefficients halve exactly.
        assert_eq!(o2.mux, 0.5 * o1.mux);
        assert_eq!(o2.muy, 0.5 * o1.muy);
        for mu in [1.0, 0.5] {
            let fy = |a| t.forces_mu(&at(fz, 0.0, a), NO_LIMITS, mu).fy;
            let fx = |k| t.forces_mu(&at(fz, k, 0.0), NO_LIMITS, mu).fx;
            let ky = (fy(h) - fy(-h)) / (2.0 * h);
            let kx = (fx(h) - fx(-h)) / (2.0 * h);
            assert!(
                (ky - o1.kya).abs() < 1e-6 * o1.kya.abs(),
                "{ky} vs {}",
                o1.kya
            );
            assert!(
                (kx - o1.kxk).abs() < 1e-6 * o1.kxk.abs(),
                "{kx} vs {}",
                o1.kxk
            );
        }
        // The moments follow: at large slip, |Mz| shrinks with the road
        // friction (trail × force and residual torque both scale with D).
        let x = at(fz, 0.0, 0.3);
        let m1 = t.forces_mu(&x, NO_LIMITS, 1.0).mz.abs();
        let m2 = t.forces_mu(&x, NO_LIMITS, 0.5).mz.abs();
        assert!(m2 < m1, "Mz {m2} !< {m1}");
    }
}

#[test]
fn slip_properties_match_evaluate_bit_for_bit() {
    let t = Tyre::builtin();
    for mode in MODES {
        for x in grid() {
            for mu in [1.0, 0.65] {
                let s = t.slip_properties_mu(&x, mode, mu);
                let o = t.evaluate_mu(
                    &MfInput {
                        kappa: 0.0,
                        alpha: 0.0,
                        ..x
                    },
                    mode,
                    mu,
                );
                let want = [
                    o.re, o.cx, o.cy, o.kxk, o.kya, o.sigmax, o.sigmay, o.mux, o.muy,
                ];
                let got = [
                    s.re, s.cx, s.cy, s.kxk, s.kya, s.sigmax, s.sigmay, s.mux, s.muy,
                ];
                assert_eq!(bits(&want), bits(&got), "{x:?} {mode:?} mu {mu}");
                // The zero-slip forces and My as numbers (a zero may carry
                // another sign: Gyκ·Fy0 + SVyκ adds a signed zero), γ as used.
                assert_eq!(
                    [o.fx, o.fy, o.my],
                    [s.fx, s.fy, s.my],
                    "{x:?} {mode:?} mu {mu}"
                );
                assert_eq!(o.gamma.to_bits(), s.gamma.to_bits());
            }
            let a = t.slip_properties(&x, mode);
            let b = t.slip_properties_mu(&x, mode, 1.0);
            assert_eq!(a, b);
        }
    }
}
