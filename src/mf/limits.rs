//! limits — the input conditioning that precedes the Magic Formula: range
//! limits of the property file, the low-speed reductions below VXLOW, the
//! α*/γ* definitions, and the turn-slip input; plus the report of what was
//! clamped ([`Clamped`]).
//!
//! The conditioned inputs are plain `f64` (they do not depend on the Magic
//! Formula coefficients, only on range keys), so the generic equations in
//! `equations.rs` receive them ready to use.
//!
//! Must never: allocate, or silently drop a NaN input (NaN passes through to
//! the outputs).

use super::{MfInput, UseMode};
use crate::tir::MfParams;

/// Bit set reporting which limits acted on one evaluation (use mode 1xx).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Clamped(pub u32);

impl Clamped {
    /// α was below ALPMIN.
    pub const ALPHA_LOW: u32 = 1 << 0;
    /// α was above ALPMAX.
    pub const ALPHA_HIGH: u32 = 1 << 1;
    /// γ was below CAMMIN.
    pub const GAMMA_LOW: u32 = 1 << 2;
    /// γ was above CAMMAX.
    pub const GAMMA_HIGH: u32 = 1 << 3;
    /// Fz was below FZMIN (raised to FZMIN inside the Mz equations).
    pub const FZ_LOW: u32 = 1 << 4;
    /// Fz was above FZMAX (clipped).
    pub const FZ_HIGH: u32 = 1 << 5;
    /// P was below PRESMIN.
    pub const P_LOW: u32 = 1 << 6;
    /// P was above PRESMAX.
    pub const P_HIGH: u32 = 1 << 7;
    /// κ was below KPUMIN.
    pub const KAPPA_LOW: u32 = 1 << 8;
    /// κ was above KPUMAX.
    pub const KAPPA_HIGH: u32 = 1 << 9;
    /// |Vx| ≤ VXLOW: the low-speed model reduced κ, φt and the shifts.
    pub const LOW_SPEED: u32 = 1 << 10;
    /// |Vx| + |Vsy| < VXLOW: α was reduced.
    pub const LOW_SPEED_ALPHA: u32 = 1 << 11;
    /// Ex > 1 was set to 1 (eq. 4.E14).
    pub const EX: u32 = 1 << 12;
    /// Ey > 1 was set to 1 (eq. 4.E24).
    pub const EY: u32 = 1 << 13;
    /// Et > 1 was set to 1 (eq. 4.E44).
    pub const ET: u32 = 1 << 14;
    /// Exα > 1 was set to 1 (eq. 4.E56).
    pub const EXA: u32 = 1 << 15;
    /// Eyκ > 1 was set to 1 (eq. 4.E64).
    pub const EYK: u32 = 1 << 16;
    /// EHyp > 1 was set to 1 (turn slip, eq. 4.87).
    pub const EHYP: u32 = 1 << 17;
    /// Fz < 0 was set to 0 (in every use mode).
    pub const FZ_NEGATIVE: u32 = 1 << 18;

    /// Names of the flags, for messages.
    pub const NAMES: [&'static str; 19] = [
        "alpha<ALPMIN",
        "alpha>ALPMAX",
        "gamma<CAMMIN",
        "gamma>CAMMAX",
        "Fz<FZMIN",
        "Fz>FZMAX",
        "P<PRESMIN",
        "P>PRESMAX",
        "kappa<KPUMIN",
        "kappa>KPUMAX",
        "low speed",
        "low speed (alpha)",
        "Ex>1",
        "Ey>1",
        "Et>1",
        "Exa>1",
        "Eyk>1",
        "EHyp>1",
        "Fz<0",
    ];

    /// Whether any of the bits in `mask` is set.
    pub fn has(&self, mask: u32) -> bool {
        self.0 & mask != 0
    }
    /// Whether nothing was clamped.
    pub fn is_empty(&self) -> bool {
        self.0 == 0
    }
    /// Names of the set flags.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        Self::NAMES
            .iter()
            .enumerate()
            .filter(move |(i, _)| self.0 & (1 << i) != 0)
            .map(|(_, n)| *n)
    }
}

/// Inputs after conditioning (MFeval's "post-processed inputs"), ISO-W, SI.
#[derive(Clone, Copy, Debug, Default)]
pub struct Conditions {
    /// Load in the force equations: ≥ 0, ≤ FZMAX with limits.
    pub fz: f64,
    /// Load in the Mz trail/residual torque: ≥ FZMIN with limits (0 if Fz ≤ 0).
    pub fz_mz: f64,
    /// Load before FZMAX clipping (≥ 0): My, Re, contact patch.
    pub fz_u: f64,
    /// κ after low-speed reduction and clipping.
    pub kappa: f64,
    /// κ as given (My, Re).
    pub kappa_u: f64,
    /// κ after the low-speed reduction only (the exported κ).
    pub kappa_low: f64,
    /// α after low-speed reduction and clipping.
    pub alpha: f64,
    /// α as exported (0 where Vx = 0).
    pub alpha_out: f64,
    /// α* (= tan α · sign Vx with the α* definition, else α).
    pub alpha_star: f64,
    /// γ after clipping.
    pub gamma: f64,
    /// γ as given (exported).
    pub gamma_u: f64,
    /// γ* (= sin γ with the α* definition, else γ).
    pub gamma_star: f64,
    /// cos α* (the Dr of Mz, Pacejka 3rd ed. 4.E47): without the α*
    /// definition and for |α| < π/2 it is 1/√(1 + tan²α) from the tan α
    /// already computed (cos = 1/√(1 + tan²) there, exact up to rounding;
    /// saves a cos per evaluation), else cos(α*).
    pub cos_alpha_star: f64,
    /// φt after conditioning (× cos α, low-speed reduction, sign of Vx).
    pub phit: f64,
    /// Vx.
    pub vx: f64,
    /// Pressure after clipping.
    pub p: f64,
    /// cos α′ with α′ = acos(Vcx / V′c) (Pacejka eq. 4.E6).
    pub cos_alpha_prime: f64,
    /// Low-speed factor on the shifts (1 − W(Vx), 1 above VXLOW).
    pub smooth: f64,
    /// Wheel spin used by turn slip and the radii (estimated when not given).
    pub omega: f64,
    /// Use-mode switches.
    pub mode: UseMode,
}

/// `lo ≤ x ≤ hi` clamp that reports which side acted (NaN passes through).
fn clip(x: f64, lo: f64, hi: f64, flags: &mut u32, low_bit: u32, high_bit: u32) -> f64 {
    if x < lo {
        *flags |= low_bit;
        lo
    } else if x > hi {
        *flags |= high_bit;
        hi
    } else {
        x
    }
}

impl Conditions {
    /// Condition one input the way MFeval 4.0 does (`Solver.parseInputs`):
    /// Fz < 0 → 0 always; with limits: φt·cos α, the low-speed reductions
    /// (linear on κ and φt below VXLOW, on α below |Vx|+|Vsy| = VXLOW, and the
    /// smooth 1 − ½(1 + cos(π Vx/VXLOW)) factor for the shifts), then the range
    /// clips. The pressure 0/NaN means INFLPRES. `omega` is left at the input;
    /// [`super::Tyre`] fills in the estimate where needed.
    pub fn new(p: &MfParams<f64>, inp: &MfInput, mode: UseMode) -> (Conditions, Clamped) {
        let mut fl = 0u32;
        let mut fz = inp.fz;
        if fz < 0.0 {
            fz = 0.0;
            fl |= Clamped::FZ_NEGATIVE;
        }
        let vx = inp.vx;
        let fz_u = fz;
        let mut kappa = inp.kappa;
        let mut kappa_low = kappa;
        let mut alpha = inp.alpha;
        let mut gamma = inp.gamma;
        let mut phit = inp.phit;
        let mut pr = if inp.p == 0.0 || inp.p.is_nan() {
            p.inflpres
        } else {
            inp.p
        };
        let mut fz_mz = fz;
        let mut smooth = 1.0;
        let tan_alpha_in = alpha.tan();
        if mode.limits {
            if phit != 0.0 {
                phit *= alpha.cos();
            }
            let vxlow = p.vxlow;
            if vx.abs() <= vxlow {
                fl |= Clamped::LOW_SPEED;
                let w = 0.5 * (1.0 + (std::f64::consts::PI * (vx / vxlow)).cos());
                smooth = 1.0 - w;
                let lin = (vx / vxlow).abs();
                kappa_low *= lin;
                phit *= lin;
                kappa *= lin;
            }
            if vx < 0.0 {
                phit = -phit;
            }
            let vsy = tan_alpha_in * vx;
            let ssum = vx.abs() + vsy.abs();
            if ssum < vxlow {
                fl |= Clamped::LOW_SPEED_ALPHA;
                alpha *= ssum / vxlow;
            }
            alpha = clip(
                alpha,
                p.alpmin,
                p.alpmax,
                &mut fl,
                Clamped::ALPHA_LOW,
                Clamped::ALPHA_HIGH,
            );
            gamma = clip(
                gamma,
                p.cammin,
                p.cammax,
                &mut fl,
                Clamped::GAMMA_LOW,
                Clamped::GAMMA_HIGH,
            );
            if fz > p.fzmax {
                fz = p.fzmax;
                fl |= Clamped::FZ_HIGH;
            }
            fz_mz = fz;
            if fz < p.fzmin {
                fz_mz = p.fzmin;
                fl |= Clamped::FZ_LOW;
            }
            if fz <= 0.0 {
                fz_mz = 0.0;
            }
            pr = clip(
                pr,
                p.presmin,
                p.presmax,
                &mut fl,
                Clamped::P_LOW,
                Clamped::P_HIGH,
            );
            kappa = clip(
                kappa,
                p.kpumin,
                p.kpumax,
                &mut fl,
                Clamped::KAPPA_LOW,
                Clamped::KAPPA_HIGH,
            );
        }
        let alpha_out = if vx == 0.0 { 0.0 } else { inp.alpha };
        // (cos α′ is Vcx/V′c itself; MFeval's cos(acos(·)) differs by an ulp.)
        let tan_alpha = if alpha == inp.alpha {
            tan_alpha_in
        } else {
            alpha.tan()
        };
        let (alpha_star, gamma_star) = if mode.alpha_star {
            (tan_alpha * crate::mf::real::sign(vx), gamma.sin())
        } else {
            (alpha, gamma)
        };
        let cos_alpha_star = if !mode.alpha_star && alpha.abs() < 0.5 * std::f64::consts::PI {
            1.0 / (1.0 + tan_alpha * tan_alpha).sqrt()
        } else {
            alpha_star.cos()
        };
        // Contact-centre speed and α′ (Pacejka eqs. 4.E6, 4.E6a), ε = 1e-6.
        let vcy = tan_alpha * vx.abs();
        let vc = (vx * vx + vcy * vcy).sqrt();
        let vc_prime = vc + EPS * crate::mf::real::sign1(vc);
        let cos_alpha_prime = vx / vc_prime;
        (
            Conditions {
                fz,
                fz_mz,
                fz_u,
                kappa,
                kappa_u: inp.kappa,
                kappa_low,
                alpha,
                alpha_out,
                alpha_star,
                gamma,
                gamma_u: inp.gamma,
                gamma_star,
                cos_alpha_star,
                phit,
                vx,
                p: pr,
                cos_alpha_prime,
                smooth,
                omega: inp.omega,
                mode,
            },
            Clamped(fl),
        )
    }
}

/// The ε of Pacejka's eq. 4.E6a that keeps denominators away from zero.
pub const EPS: f64 = 1e-6;
