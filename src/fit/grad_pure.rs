//! grad_pure — closed-form derivatives of the pure-slip Magic Formula forces
//! with respect to their coefficients, for the fitter's pure Fx and pure Fy
//! stages: one `f64` evaluation gives the channel and ∂/∂ every pure-slip
//! coefficient at a few times the cost of the value alone, instead of the
//! 27 dual lanes of forward-mode AD.
//!
//! The value mirrors [`crate::mf::Model`]'s `fy_only` / `fx_only` (fit use
//! mode: no turn slip, so ζ0…ζ4 = 1) operation by operation:
//! Fy = Gyκ·Fy0 + SVyκ (4.E58) with Fy0 = Dy sin(Cy atan(By αy − Ey(By αy −
//! atan By αy))) + SVy (4.E19–4.E30, Pacejka, *Tyre and Vehicle Dynamics*,
//! 3rd ed.; pressure terms of Besselink, Schmeitz & Pacejka, VSD 48 (2010));
//! Fx = Gxα·Fx0 with Fx0 of 4.E9–4.E18. The combined-slip factors Gyκ, SVyκ
//! per unit μy, Gxα contain no pure-slip coefficient and are passed in
//! ([`Weights`], computed once per sample). MF 5.2 and PAC2002 differ only in
//! SHy (PHY3·γ instead of Kyγ0, 4.E27 of the 5.2 manual) and in the camber
//! scaling LGAY/LGAX, both handled here.
//!
//! The derivatives are taken in reverse (adjoint) order: the sensitivity of
//! the force to each intermediate (Dy, Cy, By, αy, Ey, SVy, Kyα, Kyγ0 …) is
//! formed once, then each coefficient's derivative is its few local partials
//! times those. Piecewise constants (sgn αy in Ey, sgn κx in Ex, the ε guards
//! of 4.E26/4.E16/4.E27, the Ey ≤ 1 clip with range limits on) are held as
//! the dual-number evaluation holds them (derivative of the chosen branch).
//! `tests/fit_grad_pure.rs` compares every column with num-dual's.
//!
//! Must never: allocate, evaluate a term differently from `mf::equations`
//! (a change there must be mirrored here; the test catches it), or be used
//! for a stage whose parameter table holds anything but these coefficients
//! (the factors in [`Weights`] would go stale).

use super::mf_stages::Channel;
use crate::mf::limits::EPS;
use crate::mf::real::{sign, sign1};
use crate::mf::{Conditions, Form, Model};
use crate::tir::MfParams;

/// The pure-Fy coefficients, local index order of the gradient.
pub const FY_KEYS: [&str; 28] = [
    "pcy1", "pdy1", "pdy2", "pdy3", "pey1", "pey2", "pey3", "pey4", "pey5", "pky1", "pky2", "pky3",
    "pky4", "pky5", "pky6", "pky7", "phy1", "phy2", "phy3", "pvy1", "pvy2", "pvy3", "pvy4", "ppy1",
    "ppy2", "ppy3", "ppy4", "ppy5",
];
/// The pure-Fx coefficients, local index order of the gradient.
pub const FX_KEYS: [&str; 19] = [
    "pcx1", "pdx1", "pdx2", "pdx3", "pex1", "pex2", "pex3", "pex4", "pkx1", "pkx2", "pkx3", "phx1",
    "phx2", "pvx1", "pvx2", "ppx1", "ppx2", "ppx3", "ppx4",
];
/// Largest gradient length ([`FY_KEYS`]).
pub const MAX_KEYS: usize = 28;

/// The combined-slip factors of one sample ([`weights`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Weights {
    /// Gyκ (4.E59) for Fy, Gxα (4.E51) for Fx.
    pub g: f64,
    /// SVyκ per unit μy·ζ2 (4.E66, 4.E67) for Fy; 0 for Fx.
    pub sv_unit: f64,
}

/// The combined-slip factors of `channel` at `c` for `model` (the start
/// tyre's: they do not depend on the pure-slip coefficients).
pub fn weights(model: &Model<f64>, c: &Conditions, channel: Channel) -> Weights {
    // Pure slip (κ = 0 for Fy, α* = 0 for Fx): Gyκ = cos(…SHyκ…)/cos(…SHyκ…)
    // and Gxα likewise are exactly 1 and SVyκ ∝ sin(RVY5·atan 0) is 0, so
    // the same values without the weighting functions' transcendentals.
    let pure = match channel {
        Channel::Fy => c.kappa == 0.0,
        _ => c.alpha_star == 0.0,
    };
    if pure {
        return Weights {
            g: 1.0,
            sv_unit: 0.0,
        };
    }
    let (gyk, svyk, gxa) = model.slip_weights(c);
    match channel {
        Channel::Fy => Weights {
            g: gyk,
            sv_unit: svyk,
        },
        _ => Weights {
            g: gxa,
            sv_unit: 0.0,
        },
    }
}

/// The coefficients of `channel` for which [`PureGrad`] gives derivatives
/// (`None`: no closed form here).
pub fn keys(channel: Channel) -> Option<&'static [&'static str]> {
    match channel {
        Channel::Fy => Some(&FY_KEYS),
        Channel::Fx => Some(&FX_KEYS),
        _ => None,
    }
}

/// Local gradient index of `.tir` key `name` (lower case) for `channel`.
pub fn local_index(channel: Channel, name: &str) -> Option<usize> {
    keys(channel)?.iter().position(|k| *k == name)
}

/// One parameter set prepared for value-and-gradient evaluation of one
/// pure-slip channel.
#[derive(Clone, Debug)]
pub struct PureGrad {
    p: MfParams<f64>,
    channel: Channel,
    is52: bool,
    fz0p: f64,
    inv_fz0p: f64,
    inv_nompres: f64,
    lgax: f64,
    lgay: f64,
}

impl PureGrad {
    /// Prepare `p` (evaluated with `form`'s equations) for `channel`;
    /// `None` for channels without a closed form here.
    pub fn new(p: &MfParams<f64>, form: Form, channel: Channel) -> Option<PureGrad> {
        keys(channel)?;
        // As `Model::new` computes them (same bits).
        let fz0p = p.lfzo * p.fnomin;
        let (lgax, lgay) = if form == Form::Pac2002 {
            (p.lgax, p.lgay)
        } else {
            (1.0, 1.0)
        };
        Some(PureGrad {
            p: p.clone(),
            channel,
            is52: form != Form::Mf6,
            fz0p,
            inv_fz0p: fz0p.recip(),
            inv_nompres: p.nompres.recip(),
            lgax,
            lgay,
        })
    }

    /// The channel at `c` and, with `grad` (at least [`keys`]`.len()` long),
    /// its derivative with respect to every coefficient of [`keys`], in
    /// that order.
    #[inline]
    pub fn eval(&self, c: &Conditions, w: Weights, grad: Option<&mut [f64]>) -> f64 {
        match self.channel {
            Channel::Fy => self.fy(c, w, grad),
            _ => self.fx(c, w, grad),
        }
    }

    /// Fy = Gyκ·Fy0 + SVyκ (see the module doc) and ∂Fy/∂[`FY_KEYS`].
    fn fy(&self, c: &Conditions, w: Weights, grad: Option<&mut [f64]>) -> f64 {
        let p = &self.p;
        let fz = c.fz;
        let dfz = (fz - self.fz0p) * self.inv_fz0p; // 4.E2a
        let dpi = (c.p - p.nompres) * self.inv_nompres; // 4.E2b
        let gs = c.gamma_star * self.lgay;
        let lmuy = p.lmuy;
        // Kyα load shape sin(PKY4 atan(arg)) and Kyα (4.E25).
        let den1 = p.pky2 + p.pky5 * gs * gs;
        let den2 = p.ppy2 * dpi + 1.0;
        let arg = (fz * self.inv_fz0p) / (den1 * den2);
        // sin(2 atan a) = 2a/(1 + a²): Model's value-only shortcut (same bits).
        let pky4_is_2 = p.pky4 == 2.0;
        let at = if pky4_is_2 && grad.is_none() {
            f64::NAN // not needed
        } else {
            arg.atan()
        };
        let shape = if pky4_is_2 {
            arg * 2.0 / (arg * arg + 1.0)
        } else {
            (p.pky4 * at).sin()
        };
        let ppy1_f = p.ppy1 * dpi + 1.0;
        let g3 = -(p.pky3 * gs.abs()) + 1.0;
        let kya = p.pky1 * self.fz0p * ppy1_f * g3 * shape * 1.0 * p.lky;
        let svyg = fz * (p.pvy3 + p.pvy4 * dfz) * gs * p.lkyc * lmuy * 1.0; // 4.E28
        let ppy5_f = p.ppy5 * dpi + 1.0;
        let kyg0 = fz * (p.pky6 + p.pky7 * dfz) * ppy5_f * p.lkyc; // 4.E30
        let kp = kya + EPS * sign1(kya);
        let q = (kyg0 * gs - svyg) / kp;
        let shy = if self.is52 {
            (p.phy1 + p.phy2 * dfz) * p.lhy + p.phy3 * gs * p.lkyc
        } else {
            (p.phy1 + p.phy2 * dfz) * p.lhy + q * 1.0 + 1.0 - 1.0 // 4.E27, ζ0 = ζ4 = 1
        };
        let svy = fz * (p.pvy1 + p.pvy2 * dfz) * p.lvy * lmuy * 1.0 + svyg; // 4.E29
        let (shy, svy) = (shy * c.smooth, svy * c.smooth);
        let ay = shy + c.alpha_star; // 4.E20
        let cy = p.pcy1 * p.lcy; // 4.E21
        let m1 = p.pdy1 + p.pdy2 * dfz;
        let m2 = p.ppy3 * dpi + p.ppy4 * dpi * dpi + 1.0;
        let m3 = -(p.pdy3 * gs * gs) + 1.0;
        let muy = m1 * m2 * m3 * lmuy; // 4.E23
        let dy = muy * fz * 1.0; // 4.E22
        let s_ay = sign1(ay);
        let e1 = p.pey1 + p.pey2 * dfz;
        let e2 = p.pey5 * gs * gs + 1.0 - (p.pey3 + p.pey4 * gs) * s_ay;
        let mut ey = e1 * e2 * p.ley; // 4.E24
        let capped = c.mode.limits && ey > 1.0;
        if capped {
            ey = 1.0;
        }
        let den = cy * dy + EPS * sign1(dy);
        let by = kya / den; // 4.E26
        let x = by * ay;
        let ax = x.atan();
        let inner = if ey == 0.0 { x } else { x - ey * (x - ax) };
        let ai = inner.atan();
        // sin and cos of one angle in one call when both are needed (glibc's
        // sincos: the same values as sin, cos).
        let (s, co) = if grad.is_some() {
            (cy * ai).sin_cos()
        } else {
            ((cy * ai).sin(), f64::NAN)
        };
        let mut fy0 = dy * s + svy; // 4.E19
        let neg = c.mode.alpha_star && c.vx < 0.0;
        if neg {
            fy0 = -fy0;
        }
        let muy_out = if fz == 0.0 { 0.0 } else { muy };
        let fy = w.g * fy0 + w.sv_unit * muy_out * 1.0; // 4.E58
        let Some(gr) = grad else { return fy };
        let gr = &mut gr[..FY_KEYS.len()];

        // Adjoints: ∂Fy/∂(intermediate).
        let (inv_den, inv_kp, inv_den1) = (1.0 / den, 1.0 / kp, 1.0 / den1);
        let inv_a2 = 1.0 / (arg * arg + 1.0);
        let f = if neg { -w.g } else { w.g };
        let f_in = f * dy * co * cy / (inner * inner + 1.0);
        let g_x = f_in * (1.0 - ey + ey / (x * x + 1.0));
        let g_ey = if capped { 0.0 } else { -f_in * (x - ax) };
        let g_by = g_x * ay;
        let g_ay = g_x * by;
        let mut g_k = g_by * inv_den;
        let g_dy = f * s - g_by * by * cy * inv_den;
        let g_cy = f * dy * co * ai - g_by * by * dy * inv_den;
        let g_muy = g_dy * fz + if fz == 0.0 { 0.0 } else { w.sv_unit };
        let g_shy = g_ay * c.smooth;
        let g_svy = f * c.smooth;
        let mut g_svyg = g_svy;
        let mut g_kyg0 = 0.0;
        if !self.is52 {
            g_kyg0 = g_shy * gs * inv_kp;
            g_svyg -= g_shy * inv_kp;
            g_k -= g_shy * q * inv_kp;
        }
        // Kyα partials.
        let k_shape = p.pky1 * self.fz0p * ppy1_f * g3 * p.lky;
        let g_shape = g_k * k_shape;
        let dshape_darg = if pky4_is_2 {
            // d/da of 2a/(1 + a²) = cos(2 atan a)·2/(1 + a²)
            2.0 * (1.0 - arg * arg) * inv_a2 * inv_a2
        } else {
            (p.pky4 * at).cos() * p.pky4 * inv_a2
        };
        let cos_shape = if pky4_is_2 {
            (1.0 - arg * arg) * inv_a2
        } else {
            (p.pky4 * at).cos()
        };
        let g_arg = g_shape * dshape_darg;
        let kya_rest = self.fz0p * g3 * shape * p.lky;
        gr[0] = g_cy * p.lcy; // pcy1
        let gm = g_muy * lmuy;
        gr[1] = gm * m2 * m3; // pdy1
        gr[2] = gm * dfz * m2 * m3; // pdy2
        gr[3] = -gm * m1 * m2 * gs * gs; // pdy3
        let ge = g_ey * p.ley;
        gr[4] = ge * e2; // pey1
        gr[5] = ge * dfz * e2; // pey2
        gr[6] = -ge * e1 * s_ay; // pey3
        gr[7] = -ge * e1 * gs * s_ay; // pey4
        gr[8] = ge * e1 * gs * gs; // pey5
        gr[9] = g_k * kya_rest * ppy1_f; // pky1
        gr[10] = -g_arg * arg * inv_den1; // pky2
        gr[11] = -g_k * p.pky1 * self.fz0p * ppy1_f * gs.abs() * shape * p.lky; // pky3
        gr[12] = g_shape * cos_shape * at; // pky4
        gr[13] = -g_arg * arg * gs * gs * inv_den1; // pky5
        let gk0 = g_kyg0 * fz * p.lkyc;
        gr[14] = gk0 * ppy5_f; // pky6
        gr[15] = gk0 * dfz * ppy5_f; // pky7
        gr[16] = g_shy * p.lhy; // phy1
        gr[17] = g_shy * dfz * p.lhy; // phy2
        gr[18] = if self.is52 { g_shy * gs * p.lkyc } else { 0.0 }; // phy3
        let gv = g_svy * fz * p.lvy * lmuy;
        gr[19] = gv; // pvy1
        gr[20] = gv * dfz; // pvy2
        let gvg = g_svyg * fz * gs * p.lkyc * lmuy;
        gr[21] = gvg; // pvy3
        gr[22] = gvg * dfz; // pvy4
        gr[23] = g_k * p.pky1 * kya_rest * dpi; // ppy1
        gr[24] = -g_arg * arg * dpi / den2; // ppy2
        gr[25] = gm * m1 * dpi * m3; // ppy3
        gr[26] = gm * m1 * dpi * dpi * m3; // ppy4
        gr[27] = gk0 * (p.pky6 + p.pky7 * dfz) * dpi; // ppy5
        fy
    }

    /// Fx = Gxα·Fx0 (see the module doc) and ∂Fx/∂[`FX_KEYS`].
    fn fx(&self, c: &Conditions, w: Weights, grad: Option<&mut [f64]>) -> f64 {
        let p = &self.p;
        let fz = c.fz;
        let dfz = (fz - self.fz0p) * self.inv_fz0p; // 4.E2a
        let dpi = (c.p - p.nompres) * self.inv_nompres; // 4.E2b
        let gx = c.gamma * self.lgax;
        let lmux = p.lmux;
        let cx = p.pcx1 * p.lcx; // 4.E11
        let m1 = p.pdx1 + p.pdx2 * dfz;
        let m2 = p.ppx3 * dpi + p.ppx4 * dpi * dpi + 1.0;
        let m3 = -(p.pdx3 * gx * gx) + 1.0;
        let mut mux = m1 * m2 * m3 * lmux; // 4.E13
        if fz == 0.0 {
            mux = 0.0;
        }
        let dx = mux * fz * 1.0; // 4.E12
        let e = (p.pkx3 * dfz).exp();
        let l1 = p.pkx1 + p.pkx2 * dfz;
        let load = if p.pkx3 == 0.0 { fz * l1 } else { fz * l1 * e };
        let pp = p.ppx1 * dpi + p.ppx2 * dpi * dpi + 1.0;
        let kxk = load * pp * p.lkx; // 4.E15
        let den = cx * dx + EPS * sign1(dx);
        let bx = kxk / den; // 4.E16
        let shx = (p.phx1 + p.phx2 * dfz) * p.lhx * c.smooth; // 4.E17
        let svx = fz * (p.pvx1 + p.pvx2 * dfz) * p.lvx * lmux * 1.0 * c.smooth; // 4.E18
        let kx = shx + c.kappa; // 4.E10
        let s_kx = sign(kx);
        let x1 = p.pex1 + p.pex2 * dfz + p.pex3 * dfz * dfz;
        let x2 = -(p.pex4 * s_kx) + 1.0;
        let mut ex = x1 * x2 * p.lex; // 4.E14
        let capped = c.mode.limits && ex > 1.0;
        if capped {
            ex = 1.0;
        }
        let x = bx * kx;
        let ax = x.atan();
        let inner = if ex == 0.0 { x } else { x - ex * (x - ax) };
        let ai = inner.atan();
        // sin and cos of one angle in one call when both are needed (glibc's
        // sincos: the same values as sin, cos).
        let (s, co) = if grad.is_some() {
            (cx * ai).sin_cos()
        } else {
            ((cx * ai).sin(), f64::NAN)
        };
        let mut fx0 = dx * s + svx; // 4.E9
        let neg = c.vx < 0.0;
        if neg {
            fx0 = -fx0;
        }
        let fx = w.g * fx0; // 4.E50
        let Some(gr) = grad else { return fx };
        let gr = &mut gr[..FX_KEYS.len()];
        let inv_den = 1.0 / den;

        let f = if neg { -w.g } else { w.g };
        let f_in = f * dx * co * cx / (inner * inner + 1.0);
        let g_x = f_in * (1.0 - ex + ex / (x * x + 1.0));
        let g_ex = if capped { 0.0 } else { -f_in * (x - ax) };
        let g_bx = g_x * kx;
        let g_kx = g_x * bx;
        let g_kxk = g_bx * inv_den;
        let g_dx = f * s - g_bx * bx * cx * inv_den;
        let g_cx = f * dx * co * ai - g_bx * bx * dx * inv_den;
        let gm = if fz == 0.0 { 0.0 } else { g_dx * fz * lmux };
        gr[0] = g_cx * p.lcx; // pcx1
        gr[1] = gm * m2 * m3; // pdx1
        gr[2] = gm * dfz * m2 * m3; // pdx2
        gr[3] = -gm * m1 * m2 * gx * gx; // pdx3
        let ge = g_ex * p.lex;
        gr[4] = ge * x2; // pex1
        gr[5] = ge * dfz * x2; // pex2
        gr[6] = ge * dfz * dfz * x2; // pex3
        gr[7] = -ge * x1 * s_kx; // pex4
        let gk = g_kxk * pp * p.lkx;
        gr[8] = gk * fz * e; // pkx1
        gr[9] = gk * fz * dfz * e; // pkx2
        gr[10] = gk * fz * l1 * e * dfz; // pkx3
        let gh = g_kx * p.lhx * c.smooth;
        gr[11] = gh; // phx1
        gr[12] = gh * dfz; // phx2
        let gv = f * fz * p.lvx * lmux * c.smooth;
        gr[13] = gv; // pvx1
        gr[14] = gv * dfz; // pvx2
        let gl = g_kxk * load * p.lkx;
        gr[15] = gl * dpi; // ppx1
        gr[16] = gl * dpi * dpi; // ppx2
        gr[17] = gm * m1 * dpi * m3; // ppx3
        gr[18] = gm * m1 * dpi * dpi * m3; // ppx4
        fx
    }
}
