//! equations — the steady-state Magic Formula force and moment equations,
//! generic over the scalar type ([`Real`]) so that the fitter gets exact
//! parameter derivatives by forward-mode automatic differentiation from the
//! very code that evaluates the tyre.
//!
//! Sources: Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §4.3.2, eqs.
//! 4.E1–4.E78 (cited per line as "4.Exx"); the MF 6.1/6.2 equation set of
//! Besselink, Schmeitz & Pacejka, "An improved Magic Formula/Swift tyre model
//! that can handle inflation pressure changes", VSD 48 (2010) (cited "A.."),
//! and its draft for Mx; turn slip from Pacejka §4.3.3 (eqs. 4.75–4.106). Where
//! these sources differ, the choice follows MFeval 4.0 (M. Furlan), which was
//! validated against TNO MF-Tyre; those choices are noted where they are made.
//!
//! Must never: allocate, branch on anything but value parts, or evaluate a
//! term differently for `f64` and for dual numbers except for skipping terms
//! whose coefficient is exactly zero when no derivative is tracked.

use super::limits::{Clamped, Conditions, EPS};
use super::real::{abs, cap_one, cos_atan, pow, sign, sign1, Real};
use crate::tir::MfParams;
use std::f64::consts::PI;

/// Which family of equations a file is evaluated with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// MF 6.1 / 6.2 (FITTYP 61, 62).
    Mf6,
    /// MF-Tyre 5.2 forms (FITTYP 5, 6, 52): SHy, Kyγ0, My, Mz, patch, relaxation.
    Mf52,
    /// ADAMS PAC2002 (no FITTYP): MF 5.2 forms with the camber scalings
    /// LGAX, LGAY, LGAZ applied to γ in Fx, Fy and Mz.
    Pac2002,
}

/// Forces, moments and the by-products the outputs need, in scalar type `T`.
#[derive(Clone, Copy, Debug)]
pub struct Solution<T> {
    /// Longitudinal force Fx (N, ISO-W), combined slip: Gxα·Fx0 (4.E50).
    pub fx: T,
    /// Lateral force Fy (N, ISO-W), combined slip: Gyκ·Fy0 + SVyκ (4.E58).
    pub fy: T,
    /// Overturning moment Mx (N·m, ISO-W): the MF 6.1 form with QSX1–QSX14
    /// that MFeval uses (extends 4.E69).
    pub mx: T,
    /// Rolling resistance moment My (N·m, ISO-W, opposing rolling): paper
    /// eq. A48 for MF 6.x, the 4.E70 / MF-Tyre 5.2 form otherwise; NaN when
    /// not requested.
    pub my: T,
    /// Aligning moment Mz (N·m, ISO-W), combined slip: −t·Fy′ + Mzr + s·Fx
    /// (4.E71, 4.E72).
    pub mz: T,
    /// Longitudinal friction coefficient (4.E13).
    pub mux: T,
    /// Lateral friction coefficient (4.E23), sign as computed.
    pub muy: T,
    /// Longitudinal slip stiffness (4.E15).
    pub kxk: T,
    /// Cornering stiffness (4.E25).
    pub kya: T,
    /// Pneumatic trail (4.E73).
    pub t: T,
    /// Residual torque (4.E75).
    pub mzr: T,
    /// Curvature clamps that acted ([`Clamped`] bits).
    pub flags: u32,
}

/// Parameters prepared for evaluation in scalar type `T`: the `.tir`
/// coefficients plus the few combinations that depend only on them.
#[derive(Clone, Debug)]
pub struct Model<T: Real = f64> {
    /// The coefficients.
    pub p: MfParams<T>,
    /// Equation family.
    pub form: Form,
    /// Fz0′ = LFZO·FNOMIN (4.E1).
    fz0p: T,
    /// Reciprocals of parameters used as divisors (multiplication is cheaper).
    inv_fz0p: T,
    inv_fnomin: T,
    inv_nompres: T,
    inv_lmuy: T,
    inv_longvl: T,
    inv_fzmin: T,
    /// Camber scalings (1 except PAC2002).
    lgax: T,
    lgay: T,
    lgaz: T,
    /// Zero-coefficient shortcuts allowed (value-only evaluation).
    skip_pkx3: bool,
    /// QSY2 = 0: My does not depend on Fx (value-only).
    skip_qsy2: bool,
    skip_qsy7: bool,
    skip_qsy8: bool,
    /// Mx terms with zero coefficients (value-only evaluation).
    skip_mx_sin: bool,
    skip_mx_atan: bool,
    pky4_is_2: bool,
    skip_pky5: bool,
    rcx1_is_1: bool,
    rcy1_is_1: bool,
}

/// The pure-slip lateral force and the quantities the other equations reuse.
#[derive(Clone, Copy)]
struct Fy0<T> {
    fy0: T,
    muy: T,
    kya: T,
    /// The load shape of Kyα ([`Model::kya_shape`]).
    shape: T,
    shy: T,
    svy: T,
    by: T,
    cy: T,
    zeta2: T,
}

/// The pure-slip results [`Model::solve_mu`] builds on.
#[derive(Clone, Copy)]
struct Pure<T> {
    dfz: T,
    dpi: T,
    spin: Option<Spin<T>>,
    fx0: T,
    mux: T,
    kxk: T,
    f: Fy0<T>,
}

/// Turn-slip spin φ and camber reduction εγ (Pacejka eqs. 4.76, 4.90).
#[derive(Clone, Copy)]
struct Spin<T> {
    phi: T,
    eps_g: T,
}

impl Spin<f64> {
    fn lift<T: Real>(self) -> Spin<T> {
        Spin {
            phi: T::c(self.phi),
            eps_g: T::c(self.eps_g),
        }
    }
}

impl Fy0<f64> {
    fn lift<T: Real>(self) -> Fy0<T> {
        Fy0 {
            fy0: T::c(self.fy0),
            muy: T::c(self.muy),
            kya: T::c(self.kya),
            shape: T::c(self.shape),
            shy: T::c(self.shy),
            svy: T::c(self.svy),
            by: T::c(self.by),
            cy: T::c(self.cy),
            zeta2: T::c(self.zeta2),
        }
    }
}

impl Pure<f64> {
    fn lift<T: Real>(self) -> Pure<T> {
        Pure {
            dfz: T::c(self.dfz),
            dpi: T::c(self.dpi),
            spin: self.spin.map(Spin::lift),
            fx0: T::c(self.fx0),
            mux: T::c(self.mux),
            kxk: T::c(self.kxk),
            f: self.f.lift(),
        }
    }
}

/// The pure-slip part of one sample's solution ([`Model::pure_terms`]):
/// normalised load and pressure, Fx0 with μx and Kxκ (4.E9–4.E18), Fy0 with
/// its shifts and slopes (4.E19–4.E30), and Fy0 at γ = 0 for the aligning
/// torque (4.E74). No aligning-torque (QBZ…, QCZ…, QDZ…, QEZ…, QHZ…, PPZ…)
/// or combined-slip (R…, SSZ…) coefficient enters them, so a fit stage that
/// moves only those computes them once per sample in `f64`
/// ([`crate::fit::channels::eval_from`]) instead of
/// once per dual-number pass.
#[derive(Clone, Copy)]
pub struct PureTerms {
    r: Pure<f64>,
    f0: Fy0<f64>,
}

impl Model<f64> {
    /// The pure-slip terms of `c` (no friction scale, no step terms), the
    /// same bits as [`Model::solve`] computes on its way.
    pub fn pure_terms(&self, c: &Conditions) -> PureTerms {
        let mut fl = 0u32;
        let r = self.pure(c, 1.0, true, true, None, &mut fl);
        let f0 = self.fy0_upright(c, &r, self.p.lmuy, &mut fl);
        PureTerms { r, f0 }
    }
}

/// The slip-independent pure-slip terms of one load, pressure and camber:
/// μx (4.E13), Kxκ (4.E15, with its exp) and the load shape of Kyα (4.E25,
/// its sin(PKY4·atan(…))), as [`Model::zero_slip_terms`] computed them. A
/// transient step evaluates the MF several times at the same Fz, p, γ (its
/// zero-slip probe, the forces, slopes, cross terms): handing these to the
/// later evaluations ([`Model::solve_with`], [`Model::solve_fxfy`])
/// computes them once per step. They carry the conditioned Fz, p, γ, γ* and
/// friction scale they belong to and are used only where all match (else
/// computed afresh), so results are bit-identical either way. Not a cache:
/// built by each step's probe and dropped with it.
#[derive(Clone, Copy, Debug)]
pub struct LoadTerms<T> {
    fz: f64,
    p: f64,
    gamma: f64,
    gamma_star: f64,
    mu_scale: f64,
    mux: T,
    kxk: T,
    shape: T,
}

impl<T: Copy> LoadTerms<T> {
    /// These terms, if they belong to conditions `c` and friction scale `mu_scale`.
    #[inline(always)]
    fn for_conditions(&self, c: &Conditions, mu_scale: f64) -> Option<Self> {
        (self.fz == c.fz
            && self.p == c.p
            && self.gamma == c.gamma
            && self.gamma_star == c.gamma_star
            && self.mu_scale == mu_scale)
            .then_some(*self)
    }
}

impl<T: Real> Model<T> {
    /// Prepare the coefficients.
    pub fn new(p: MfParams<T>, form: Form) -> Model<T> {
        let one = T::c(1.0);
        let (lgax, lgay, lgaz) = if form == Form::Pac2002 {
            (p.lgax, p.lgay, p.lgaz)
        } else {
            (one, one, one)
        };
        let fz0p = p.lfzo * p.fnomin;
        let skip_pkx3 = !T::TRACKS_DERIVATIVES && p.pkx3.v() == 0.0;
        let zero = |x: T| !T::TRACKS_DERIVATIVES && x.v() == 0.0;
        let skip_qsy2 = zero(p.qsy2);
        let skip_qsy7 = zero(p.qsy7);
        let skip_qsy8 = zero(p.qsy8);
        let skip_mx_sin = zero(p.qsx4) || (zero(p.qsx7) && zero(p.qsx8));
        let skip_mx_atan = zero(p.qsx10);
        let pky4_is_2 = !T::TRACKS_DERIVATIVES && p.pky4.v() == 2.0;
        let skip_pky5 = zero(p.pky5);
        let rcx1_is_1 = !T::TRACKS_DERIVATIVES && p.rcx1.v() == 1.0;
        let rcy1_is_1 = !T::TRACKS_DERIVATIVES && p.rcy1.v() == 1.0;
        Model {
            inv_fz0p: fz0p.recip(),
            inv_fnomin: p.fnomin.recip(),
            inv_nompres: p.nompres.recip(),
            inv_lmuy: p.lmuy.recip(),
            inv_longvl: p.longvl.recip(),
            inv_fzmin: p.fzmin.recip(),
            p,
            form,
            fz0p,
            lgax,
            lgay,
            lgaz,
            skip_pkx3,
            skip_qsy2,
            skip_qsy7,
            skip_qsy8,
            skip_mx_sin,
            skip_mx_atan,
            pky4_is_2,
            skip_pky5,
            rcx1_is_1,
            rcy1_is_1,
        }
    }

    /// Whether the MF 5.2 forms apply (FITTYP 6/5/52 and PAC2002).
    #[inline(always)]
    fn is52(&self) -> bool {
        self.form != Form::Mf6
    }

    /// Turn-slip spin φ (Pacejka eqs. 4.75, 4.76, 4.90), with the contact
    /// speed held at ±VXLOW below VXLOW. The sign convention follows MFeval
    /// (z up), so no minus on the camber term's ω.
    fn spin(&self, c: &Conditions, dfz: T) -> Spin<T> {
        let p = &self.p;
        let eps_g = p.pecp1 * (dfz * p.pecp2 + 1.0);
        let vsy = -c.alpha.tan() * c.vx.abs();
        let mut vc = (c.vx * c.vx + vsy * vsy).sqrt();
        if c.vx.abs() < p.vxlow.v() {
            let s = if c.vx < 0.0 { -1.0 } else { 1.0 };
            vc = p.vxlow.v() * s;
        }
        let psi_dot = -c.phit * vc;
        let phi = (-(-eps_g + 1.0) * (c.omega * c.gamma.sin()) + psi_dot) * (1.0 / vc);
        Spin { phi, eps_g }
    }

    /// Pure longitudinal force Fx0 (4.E9–4.E18), with μx and Kxκ. With
    /// `force = false` only μx and Kxκ are computed (Fx0 is NaN).
    #[allow(clippy::too_many_arguments)]
    fn fx0(
        &self,
        c: &Conditions,
        dfz: T,
        dpi: T,
        zeta1: T,
        gx: T,
        lmux: T,
        known: Option<(T, T)>,
        force: bool,
        fl: &mut u32,
    ) -> (T, T, T) {
        let p = &self.p;
        let fz = T::c(c.fz);
        let cx = p.pcx1 * p.lcx; // 4.E11
        let (mux, kxk) = match known {
            Some(mk) => mk,
            None => self.mux_kxk(c, dfz, dpi, gx, lmux),
        };
        let dx = mux * fz * zeta1; // 4.E12
        if !force {
            return (T::c(f64::NAN), mux, kxk);
        }
        let bx = kxk / (cx * dx + EPS * sign1(dx)); // 4.E16
        let shx = (p.phx1 + p.phx2 * dfz) * p.lhx * c.smooth; // 4.E17
        let svx = fz * (p.pvx1 + p.pvx2 * dfz) * p.lvx * lmux * zeta1 * c.smooth; // 4.E18
        let kx = shx + c.kappa; // 4.E10
        let ex =
            (p.pex1 + p.pex2 * dfz + p.pex3 * dfz * dfz) * (-(p.pex4 * sign(kx)) + 1.0) * p.lex; // 4.E14
        let (ex, hit) = cap_one(ex, c.mode.limits);
        if hit {
            *fl |= Clamped::EX;
        }
        let bk = bx * kx;
        let mut fx0 = dx * (cx * curved(bk, ex).arctan()).sin() + svx; // 4.E9
        if c.vx < 0.0 {
            fx0 = -fx0;
        }
        (fx0, mux, kxk)
    }

    /// μx (4.E13) and Kxκ (4.E15): the slip-independent part of [`Model::fx0`].
    #[inline(always)]
    fn mux_kxk(&self, c: &Conditions, dfz: T, dpi: T, gx: T, lmux: T) -> (T, T) {
        let p = &self.p;
        let fz = T::c(c.fz);
        let mut mux = (p.pdx1 + p.pdx2 * dfz)
            * (p.ppx3 * dpi + p.ppx4 * dpi * dpi + 1.0)
            * (-(p.pdx3 * gx * gx) + 1.0)
            * lmux; // 4.E13
        if c.fz == 0.0 {
            mux = T::c(0.0);
        }
        let load = if self.skip_pkx3 {
            fz * (p.pkx1 + p.pkx2 * dfz)
        } else {
            fz * (p.pkx1 + p.pkx2 * dfz) * (p.pkx3 * dfz).exp()
        };
        let kxk = load * (p.ppx1 * dpi + p.ppx2 * dpi * dpi + 1.0) * p.lkx; // 4.E15
        (mux, kxk)
    }

    /// The load shape sin(PKY4·atan(…)) of Kyα (4.E25) at camber `gs`.
    #[inline(always)]
    fn kya_shape(&self, fz: T, dpi: T, gs: T) -> T {
        let p = &self.p;
        let arg = (fz * self.inv_fz0p) / ((p.pky2 + p.pky5 * gs * gs) * (p.ppy2 * dpi + 1.0));
        // sin(2 atan x) = 2x/(1 + x²) for the usual PKY4 = 2 (value-only shortcut).
        if self.pky4_is_2 {
            arg * 2.0 / (arg * arg + 1.0)
        } else {
            (p.pky4 * arg.arctan()).sin()
        }
    }

    /// Cornering stiffness Kyα (4.E25) at camber `gs`.
    #[inline(always)]
    fn kya(&self, fz: T, dpi: T, gs: T, zeta3: T) -> T {
        self.kya_from_shape(dpi, gs, zeta3, self.kya_shape(fz, dpi, gs))
    }

    /// Kyα (4.E25) from its load shape ([`Model::kya_shape`]).
    #[inline(always)]
    fn kya_from_shape(&self, dpi: T, gs: T, zeta3: T, shape: T) -> T {
        let p = &self.p;
        p.pky1
            * self.fz0p
            * (p.ppy1 * dpi + 1.0)
            * (-(p.pky3 * abs(gs)) + 1.0)
            * shape
            * zeta3
            * p.lky
    }

    /// Pure lateral force Fy0 (4.E19–4.E30) at camber `gs` (γ*, scaled by LGAY
    /// for PAC2002), with turn slip ζ2, ζ3, ζ4 when `spin` is given. With
    /// `force = false` the final 4.E19 (Fy0 itself) is skipped (NaN); μy, Kyα
    /// and the shifts are computed all the same.
    #[allow(clippy::too_many_arguments)]
    fn fy0(
        &self,
        c: &Conditions,
        dfz: T,
        dpi: T,
        gs: T,
        spin: Option<Spin<T>>,
        lmuy: T,
        shape: Option<T>,
        force: bool,
        fl: &mut u32,
    ) -> Fy0<T> {
        let p = &self.p;
        let one = T::c(1.0);
        let fz = T::c(c.fz);
        let r0 = p.unloaded_radius;
        let (zeta2, zeta3) = match spin {
            Some(s) => {
                let z3 = cos_atan(p.pkyp1 * r0 * r0 * s.phi * s.phi); // 4.79
                let byp = p.pdyp1 * (p.pdyp2 * dfz + 1.0) * cos_atan(p.pdyp3 * c.alpha.tan()); // 4.78
                let rphi = r0 * abs(s.phi);
                let z2 = cos_atan(byp * (rphi + p.pdyp4 * rphi.sqrt())); // 4.77
                (z2, z3)
            }
            None => (one, one),
        };
        let shape = shape.unwrap_or_else(|| self.kya_shape(fz, dpi, gs));
        let kya = self.kya_from_shape(dpi, gs, zeta3, shape);
        let svyg = fz * (p.pvy3 + p.pvy4 * dfz) * gs * p.lkyc * lmuy * zeta2; // 4.E28
        let kyg0 = if self.is52() {
            // MF-Tyre 5.2: camber stiffness from PHY3 and PVY3/4.
            let kya0 =
                p.pky1 * self.fz0p * (p.pky4 * (fz / (p.pky2 * self.fz0p)).arctan()).sin() * p.lkyc;
            (p.phy3 * kya0 + fz * (p.pvy3 + p.pvy4 * dfz)) * p.lkyc
        } else {
            fz * (p.pky6 + p.pky7 * dfz) * (p.ppy5 * dpi + 1.0) * p.lkyc // 4.E30
        };
        let (zeta0, zeta4) = match spin {
            Some(s) => {
                let kya0 = self.kya(fz, dpi, T::c(0.0), one);
                let kya_p = kya + EPS * sign1(kya); // 4.E39
                let kya0_p = kya0 + EPS * sign1(kya0);
                let chyp = p.phyp1; // 4.85
                let dhyp = (p.phyp2 + p.phyp3 * dfz) * sign(c.vx); // 4.86
                let (ehyp, hit) = cap_one(p.phyp4, c.mode.limits); // 4.87
                if hit {
                    *fl |= Clamped::EHYP;
                }
                let kyrp0 = kyg0 / (-s.eps_g + 1.0); // 4.89
                let bhyp = kyrp0 / (chyp * dhyp * kya0_p); // 4.88
                let x = bhyp * r0 * s.phi;
                let shyp = dhyp * (chyp * curved(x, ehyp).arctan()).sin() * sign(c.vx); // 4.80
                (T::c(0.0), shyp + 1.0 - svyg / kya_p) // 4.83, 4.84
            }
            None => (one, one),
        };
        let shy = if self.is52() {
            (p.phy1 + p.phy2 * dfz) * p.lhy + p.phy3 * gs * p.lkyc
        } else {
            // 4.E27; the +ζ4 − 1 is kept in this order (as evaluated by MFeval).
            (p.phy1 + p.phy2 * dfz) * p.lhy
                + (kyg0 * gs - svyg) / (kya + EPS * sign1(kya)) * zeta0
                + zeta4
                - 1.0
        };
        let svy = fz * (p.pvy1 + p.pvy2 * dfz) * p.lvy * lmuy * zeta2 + svyg; // 4.E29
        let (shy, svy) = (shy * c.smooth, svy * c.smooth);
        let ay = shy + c.alpha_star; // 4.E20
        let cy = p.pcy1 * p.lcy; // 4.E21
        let mut muy = (p.pdy1 + p.pdy2 * dfz)
            * (p.ppy3 * dpi + p.ppy4 * dpi * dpi + 1.0)
            * (-(p.pdy3 * gs * gs) + 1.0)
            * lmuy; // 4.E23
        let dy = muy * fz * zeta2; // 4.E22
        let ey = (p.pey1 + p.pey2 * dfz)
            * (p.pey5 * gs * gs + 1.0 - (p.pey3 + p.pey4 * gs) * sign1(ay))
            * p.ley; // 4.E24
        let (ey, hit) = cap_one(ey, c.mode.limits);
        if hit {
            *fl |= Clamped::EY;
        }
        let by = kya / (cy * dy + EPS * sign1(dy)); // 4.E26
        let mut fy0 = if force {
            dy * (cy * curved(by * ay, ey).arctan()).sin() + svy // 4.E19
        } else {
            T::c(f64::NAN)
        };
        if c.mode.alpha_star && c.vx < 0.0 {
            fy0 = -fy0;
        }
        if c.fz == 0.0 {
            muy = T::c(0.0);
        }
        Fy0 {
            fy0,
            muy,
            kya,
            shape,
            shy,
            svy,
            by,
            cy,
            zeta2,
        }
    }

    /// Combined-slip weighting Gyκ (4.E59–4.E65) and the κ-induced side
    /// force SVyκ per unit of μy·ζ2 (4.E66, 4.E67; SVyκ is linear in μy, so one
    /// evaluation serves both the γ and the γ = 0 lateral force).
    fn gyk(&self, c: &Conditions, dfz: T, gs: T, fl: &mut u32) -> (T, T) {
        let p = &self.p;
        let fz = T::c(c.fz);
        let dvyk = fz * (p.rvy1 + p.rvy2 * dfz + p.rvy3 * gs) * cos_atan(p.rvy4 * c.alpha_star); // 4.E67 / (μy ζ2)
        let svyk = if !T::TRACKS_DERIVATIVES && dvyk.v() == 0.0 {
            T::c(0.0) // value-only: no κ-induced side force
        } else {
            dvyk * (p.rvy5 * (p.rvy6 * c.kappa).arctan()).sin() * p.lvyka * c.smooth
            // 4.E66
        };
        let shyk = p.rhy1 + p.rhy2 * dfz; // 4.E65
        let (eyk, hit) = cap_one(p.rey1 + p.rey2 * dfz, c.mode.limits); // 4.E64
        if hit {
            *fl |= Clamped::EYK;
        }
        let cyk = p.rcy1; // 4.E63
        let byk =
            (p.rby1 + p.rby4 * gs * gs) * cos_atan(p.rby2 * (-p.rby3 + c.alpha_star)) * p.lyka; // 4.E62
        let ks = shyk + c.kappa; // 4.E61
        let gyk0 = if !T::TRACKS_DERIVATIVES && shyk.v() == 0.0 {
            T::c(1.0) // cos(0)
        } else {
            weight(self.rcy1_is_1, cyk, byk * shyk, eyk) // 4.E60
        };
        let gyk = weight(self.rcy1_is_1, cyk, byk * ks, eyk) / gyk0; // 4.E59
        (gyk, svyk)
    }

    /// Combined-slip weighting Gxα (4.E50–4.E57).
    fn gxa(&self, c: &Conditions, dfz: T, gsx: T, fl: &mut u32) -> T {
        let p = &self.p;
        let cxa = p.rcx1; // 4.E55
        let (exa, hit) = cap_one(p.rex1 + p.rex2 * dfz, c.mode.limits); // 4.E56
        if hit {
            *fl |= Clamped::EXA;
        }
        let shxa = p.rhx1; // 4.E57
        let bxa = (p.rbx1 + p.rbx3 * gsx * gsx) * cos_atan(p.rbx2 * c.kappa) * p.lxal; // 4.E54
        let a_s = shxa + c.alpha_star; // 4.E53
        let gxa0 = if !T::TRACKS_DERIVATIVES && shxa.v() == 0.0 {
            T::c(1.0) // cos(0)
        } else {
            weight(self.rcx1_is_1, cxa, bxa * shxa, exa) // 4.E52
        };
        weight(self.rcx1_is_1, cxa, bxa * a_s, exa) / gxa0 // 4.E51
    }

    /// Overturning moment: eq. (49) of Besselink's draft MF 6.1 paper (with
    /// QSX12–QSX14), the choice MFeval made to match TNO; load reduced as
    /// Fz·(Fz/FZMIN)² below FZMIN.
    fn mx(&self, c: &Conditions, dpi: T, fy: T) -> T {
        let p = &self.p;
        let mut fz = T::c(c.fz);
        if c.fz < p.fzmin.v() {
            let r = fz * self.inv_fzmin;
            fz = fz * r * r;
        }
        let g = T::c(c.gamma);
        let r0 = p.unloaded_radius;
        let fyn = fy * self.inv_fnomin;
        let fzn = fz * self.inv_fnomin;
        let q6 = p.qsx6 * fzn;
        // Terms with a zero coefficient are exactly 0 (skipped when no
        // derivative is tracked).
        let sin_term = if self.skip_mx_sin {
            T::c(0.0)
        } else {
            p.qsx4
                * (p.qsx5 * (q6 * q6).arctan()).cos()
                * (p.qsx7 * g + p.qsx8 * (p.qsx9 * fyn).arctan()).sin()
        };
        let atan_term = if self.skip_mx_atan {
            T::c(0.0)
        } else {
            p.qsx10 * (p.qsx11 * fzn).arctan() * g
        };
        r0 * fz
            * p.lmx
            * (p.qsx1 * p.lvmx - p.qsx2 * g * (p.ppmx1 * dpi + 1.0) - p.qsx12 * g * c.gamma.abs()
                + p.qsx3 * fyn
                + sin_term
                + atan_term)
            + r0 * fy * p.lmx * (p.qsx13 + p.qsx14 * c.gamma.abs())
    }

    /// Rolling resistance moment: paper eq. A48 for MF 6.x, the MF-Tyre 5.2
    /// manual form otherwise; load reduced as Fz·(Fz/FZMIN) below FZMIN; sign
    /// flipped for Vx < 0; MFeval's low-speed shaping around κ = −1.
    fn my(&self, c: &Conditions, fx: T) -> T {
        let p = &self.p;
        let mut fz = T::c(c.fz_u);
        if c.fz_u < p.fzmin.v() {
            fz = fz * (fz * self.inv_fzmin);
        }
        let fz0 = p.fnomin;
        let vr = T::c(c.vx) * self.inv_longvl;
        let vr2 = vr * vr;
        // With QSY2 = 0 the Fx term is exactly 0 (skipped, value-only), so
        // that My needs no Fx then (the zero-slip probe skips its Fx0).
        let fx_term = if self.skip_qsy2 {
            T::c(0.0)
        } else {
            p.qsy2 * (fx * self.inv_fnomin)
        };
        let speed = p.qsy1 + fx_term + p.qsy3 * abs(vr) + p.qsy4 * (vr2 * vr2);
        let mut my = if self.is52() {
            -(p.unloaded_radius * fz * p.lmy * speed)
        } else {
            let g2 = c.gamma * c.gamma;
            let inner = speed + (p.qsy5 + p.qsy6 * (fz * self.inv_fnomin)) * g2;
            // Zero exponents give exactly 1 (0^0 = 1 as in MATLAB).
            let load = if self.skip_qsy7 {
                T::c(1.0)
            } else {
                pow(fz * self.inv_fnomin, p.qsy7)
            };
            let press = if self.skip_qsy8 {
                T::c(1.0)
            } else {
                pow(T::c(c.p) * self.inv_nompres, p.qsy8)
            };
            let scale = load * press;
            -(p.unloaded_radius * fz0 * p.lmy * inner * scale)
        };
        if c.vx < 0.0 {
            my = -my;
        }
        let vxlow = p.vxlow.v();
        let high = vxlow / c.vx.abs() - 1.0;
        let low = -1.0 - vxlow - high;
        let k = c.kappa_u;
        if k >= low && k <= high {
            // Linear ramp from 0 at κ = −1 to π/2 at κ = `high`.
            let red = (0.0 * (high - k) + PI / 2.0 * (k + 1.0)) / (high + 1.0);
            my *= red.sin();
        }
        if k < low {
            my = -my;
        }
        if c.vx == 0.0 {
            my = T::c(0.0);
        }
        my
    }

    /// The pure-slip part shared by [`Model::solve_mu`] and
    /// [`Model::zero_slip`]: normalised load and pressure (4.E2a, 4.E2b),
    /// turn-slip spin and ζ1 (4.105, 4.106), Fx0 (4.E9) and Fy0 (4.E19) —
    /// the forces themselves only when `fx`/`fy` ask for them (NaN otherwise).
    /// `pre`: the slip-independent terms of an earlier evaluation of this
    /// step ([`LoadTerms`]), used when they belong to `c`.
    #[inline(always)]
    fn pure(
        &self,
        c: &Conditions,
        mu_scale: f64,
        fx: bool,
        fy: bool,
        pre: Option<&LoadTerms<T>>,
        fl: &mut u32,
    ) -> Pure<T> {
        let pre = pre.and_then(|t| t.for_conditions(c, mu_scale));
        let p = &self.p;
        let fz = T::c(c.fz);
        let dfz = (fz - self.fz0p) * self.inv_fz0p; // 4.E2a
        let dpi = (T::c(c.p) - p.nompres) * self.inv_nompres; // 4.E2b
        let gs_y = T::c(c.gamma_star) * self.lgay;
        let gx = T::c(c.gamma) * self.lgax;
        let spin = if c.mode.turn_slip {
            Some(self.spin(c, dfz))
        } else {
            None
        };
        let zeta1 = match spin {
            Some(s) => {
                let bxp = p.pdxp1 * (p.pdxp2 * dfz + 1.0) * cos_atan(p.pdxp3 * c.kappa); // 4.106
                cos_atan(bxp * p.unloaded_radius * s.phi) // 4.105
            }
            None => T::c(1.0),
        };
        let known = pre.map(|t| (t.mux, t.kxk));
        let (fx0, mux, kxk) = self.fx0(c, dfz, dpi, zeta1, gx, p.lmux * mu_scale, known, fx, fl);
        let shape = pre.map(|t| t.shape);
        let f = self.fy0(c, dfz, dpi, gs_y, spin, p.lmuy * mu_scale, shape, fy, fl);
        Pure {
            dfz,
            dpi,
            spin,
            fx0,
            mux,
            kxk,
            f,
        }
    }

    /// The zero-slip evaluation the transient models probe every step:
    /// (μx, μy, Kxκ, Kyα, Fx, Fy, My) for conditions with κ = α = 0, equal
    /// (as numbers; a zero may differ in sign) to [`Model::solve_mu`]'s —
    /// at zero slip the combined-slip weights are exactly 1 and the
    /// κ-induced side force SVyκ is 0 (Pacejka 3rd ed. 4.E51, 4.E59, 4.E66),
    /// so Fx = Fx0, Fy = Fy0 — without the weights and the Mx, Mz equations.
    pub fn zero_slip(&self, c: &Conditions, mu_scale: f64) -> [T; 7] {
        self.zero_slip_terms(c, mu_scale, true, true).0
    }

    /// [`Model::zero_slip`] computing only what is asked for, and the
    /// slip-independent terms it computed, for the step's later evaluations
    /// ([`LoadTerms`]): μx, μy, Kxκ, Kyα always; Fx, Fy at zero slip only
    /// with `forces`, My only with `my` (the others are NaN). What is
    /// computed has the same bits as in [`Model::zero_slip`] (the same
    /// operations on the same operands); the skipped parts are the Magic
    /// Formula's sin(C·atan(…)) of 4.E9/4.E19 and the rolling-resistance
    /// powers — most of the probe's cost.
    pub fn zero_slip_terms(
        &self,
        c: &Conditions,
        mu_scale: f64,
        forces: bool,
        my: bool,
    ) -> ([T; 7], LoadTerms<T>) {
        let mut fl = 0u32;
        // My needs Fx (its QSY2 term) unless QSY2 = 0 (value-only).
        let fx = forces || (my && !self.skip_qsy2);
        let r = self.pure(c, mu_scale, fx, forces, None, &mut fl);
        let my = if my {
            self.my(c, r.fx0)
        } else {
            T::c(f64::NAN)
        };
        let terms = LoadTerms {
            fz: c.fz,
            p: c.p,
            gamma: c.gamma,
            gamma_star: c.gamma_star,
            mu_scale,
            mux: r.mux,
            kxk: r.kxk,
            shape: r.f.shape,
        };
        ([r.mux, r.f.muy, r.kxk, r.f.kya, r.fx0, r.f.fy0, my], terms)
    }

    /// Combined-slip Fx, Fy (4.E50, 4.E58) from the pure-slip part, with the
    /// weight Gyκ and the unit κ-induced side force the aligning torque reuses.
    #[inline(always)]
    fn combined(&self, c: &Conditions, r: &Pure<T>, fl: &mut u32) -> (T, T, T, T) {
        let gs = T::c(c.gamma_star);
        let (gyk, svyk_unit) = self.gyk(c, r.dfz, gs * self.lgay, fl);
        let gxa = self.gxa(c, r.dfz, gs * self.lgax, fl);
        let fx = gxa * r.fx0; // 4.E50
        let fy = gyk * r.f.fy0 + svyk_unit * r.f.muy * r.f.zeta2; // 4.E58
        (fx, fy, gyk, svyk_unit)
    }

    /// Combined-slip Fx and Fy only, without the moments (for callers that
    /// need no more: finite-difference slopes, the transient models'
    /// zero-slip offsets and LuGre's cross terms): the same operations as
    /// [`Model::solve_mu`]'s Fx, Fy, so the same bits, at well under its cost
    /// (no Mz ingredients, no second Fy0 at γ = 0, no Mx, My). `pre`: the
    /// step's [`LoadTerms`] where they belong to the same Fz, p, γ (same
    /// bits either way).
    pub fn solve_fxfy(&self, c: &Conditions, mu_scale: f64, pre: Option<&LoadTerms<T>>) -> (T, T) {
        let mut fl = 0u32;
        let r = self.pure(c, mu_scale, true, true, pre, &mut fl);
        let (fx, fy, _, _) = self.combined(c, &r, &mut fl);
        (fx, fy)
    }

    /// Single channels of [`Model::solve`] (same operations, so the same
    /// values) for the fitter, which needs one channel per stage:
    /// `fy` = Gyκ·Fy0 + SVyκ (4.E58), `fx` = Gxα·Fx0 (4.E50), and Mx, My from
    /// them. Turn slip is not evaluated (the fitter's use mode has none).
    pub(crate) fn fx_only(&self, c: &Conditions) -> T {
        let mut fl = 0u32;
        let (dfz, dpi) = self.load_pressure(c);
        let gx = T::c(c.gamma) * self.lgax;
        let (fx0, _, _) = self.fx0(c, dfz, dpi, T::c(1.0), gx, self.p.lmux, None, true, &mut fl);
        self.gxa(c, dfz, T::c(c.gamma_star) * self.lgax, &mut fl) * fx0
    }

    /// See [`Model::fx_only`].
    pub(crate) fn fy_only(&self, c: &Conditions) -> T {
        let mut fl = 0u32;
        let (dfz, dpi) = self.load_pressure(c);
        let gs_y = T::c(c.gamma_star) * self.lgay;
        let f = self.fy0(c, dfz, dpi, gs_y, None, self.p.lmuy, None, true, &mut fl);
        let (gyk, svyk_unit) = self.gyk(c, dfz, gs_y, &mut fl);
        gyk * f.fy0 + svyk_unit * f.muy * f.zeta2
    }

    /// The combined-slip factors of [`Model::fy_only`] (Gyκ, SVyκ per unit
    /// μy·ζ2) and of [`Model::fx_only`] (Gxα): they hold no pure-slip
    /// coefficient, so the fitter's analytic pure-slip gradients
    /// (`fit::grad_pure`) compute them once per sample.
    pub(crate) fn slip_weights(&self, c: &Conditions) -> (T, T, T) {
        let mut fl = 0u32;
        let (dfz, _) = self.load_pressure(c);
        let gs = T::c(c.gamma_star);
        let (gyk, svyk_unit) = self.gyk(c, dfz, gs * self.lgay, &mut fl);
        (gyk, svyk_unit, self.gxa(c, dfz, gs * self.lgax, &mut fl))
    }

    /// See [`Model::fx_only`].
    pub(crate) fn mx_only(&self, c: &Conditions) -> T {
        self.mx_with_fy(c, self.fy_only(c))
    }

    /// See [`Model::fx_only`].
    pub(crate) fn my_only(&self, c: &Conditions) -> T {
        self.my_with_fx(c, self.fx_only(c))
    }

    /// Mx given the combined-slip Fy ([`Model::fy_only`]'s value): the
    /// fitter's Mx stage moves no Fy coefficient, so it computes Fy once per
    /// sample instead of once per dual-number pass.
    pub(crate) fn mx_with_fy(&self, c: &Conditions, fy: T) -> T {
        self.mx(c, self.load_pressure(c).1, fy)
    }

    /// My given the combined-slip Fx ([`Model::fx_only`]'s value); see
    /// [`Model::mx_with_fy`].
    pub(crate) fn my_with_fx(&self, c: &Conditions, fx: T) -> T {
        self.my(c, fx)
    }

    /// Combined-slip Fx from the sample's pure-slip terms
    /// ([`Model::pure_terms`], computed with the same coefficients): the
    /// same value as [`Model::fx_only`] (in `f64` the same bits), with only
    /// Gxα (4.E50–4.E57) evaluated in `T`.
    pub(crate) fn fx_from(&self, c: &Conditions, t: &PureTerms) -> T {
        let mut fl = 0u32;
        let r: Pure<T> = t.r.lift();
        self.gxa(c, r.dfz, T::c(c.gamma_star) * self.lgax, &mut fl) * r.fx0
    }

    /// Combined-slip Fy from the pure-slip terms, as [`Model::fy_only`]:
    /// only Gyκ and SVyκ (4.E58–4.E67) evaluated in `T`.
    pub(crate) fn fy_from(&self, c: &Conditions, t: &PureTerms) -> T {
        let mut fl = 0u32;
        let r: Pure<T> = t.r.lift();
        let (gyk, svyk_unit) = self.gyk(c, r.dfz, T::c(c.gamma_star) * self.lgay, &mut fl);
        gyk * r.f.fy0 + svyk_unit * r.f.muy * r.f.zeta2
    }

    /// The aligning torque from the pure-slip terms: [`Model::solve`]'s Mz
    /// (without My; in `f64` the same bits), evaluating in `T` only what
    /// follows the pure-slip forces.
    pub(crate) fn mz_from(&self, c: &Conditions, t: &PureTerms) -> T {
        let (r, f0): (Pure<T>, Fy0<T>) = (t.r.lift(), t.f0.lift());
        self.finish(c, 1.0, false, &r, &f0, 0).mz
    }

    /// Normalised load and pressure change (4.E2a, 4.E2b), as in `pure`.
    #[inline(always)]
    fn load_pressure(&self, c: &Conditions) -> (T, T) {
        let dfz = (T::c(c.fz) - self.fz0p) * self.inv_fz0p;
        let dpi = (T::c(c.p) - self.p.nompres) * self.inv_nompres;
        (dfz, dpi)
    }

    /// Forces and moments for combined slip (and the by-products).
    #[inline]
    pub fn solve(&self, c: &Conditions) -> Solution<T> {
        self.solve_mu(c, 1.0)
    }

    /// [`Model::solve`] on a road whose friction is `mu_scale` times the one
    /// the coefficients describe: LMUX and LMUY are multiplied by `mu_scale`
    /// wherever they appear (μx, μy 4.E13/4.E23; SVx, SVy, SVyγ 4.E18,
    /// 4.E28/29; Bt A58 and Br 4.E45 through 1/λμy; Dr 4.E47), which is how
    /// MF-Tyre models a road friction change (Pacejka §4.3.2: λμ* is the
    /// road-dependent friction scaling). Kxκ and Kyα (4.E15, 4.E25) do not
    /// contain λμ, so the small-slip stiffness is unchanged. `mu_scale = 1`
    /// gives bit-identical results to [`Model::solve`] (×1 is exact).
    pub fn solve_mu(&self, c: &Conditions, mu_scale: f64) -> Solution<T> {
        self.solve_with(c, mu_scale, true, None)
    }

    /// [`Model::solve_mu`] with My only when `my` (NaN otherwise; the
    /// transient models take My from their zero-slip probe, the fitter's Mz
    /// stage needs none), reusing the step's [`LoadTerms`] `pre` where they
    /// belong to the same Fz, p, γ; every other field the same bits (the
    /// same operations).
    pub fn solve_with(
        &self,
        c: &Conditions,
        mu_scale: f64,
        my: bool,
        pre: Option<&LoadTerms<T>>,
    ) -> Solution<T> {
        let mut fl = 0u32;
        let r = self.pure(c, mu_scale, true, true, pre, &mut fl);
        let f0 = self.fy0_upright(c, &r, self.p.lmuy * mu_scale, &mut fl);
        self.finish(c, mu_scale, my, &r, &f0, fl)
    }

    /// Fy0 at γ = 0 (with Gyκ at the original γ*, as MFeval does to match
    /// TNO) for the aligning torque's Fy' (4.E74): the pure lateral force
    /// already computed when γ* = 0.
    #[inline(always)]
    fn fy0_upright(&self, c: &Conditions, r: &Pure<T>, lmuy: T, fl: &mut u32) -> Fy0<T> {
        if c.gamma_star == 0.0 {
            r.f
        } else {
            // With PKY5 = 0 the load shape of Kyα does not depend on γ
            // (value-only: the same operands give the same bits).
            let shape = if self.skip_pky5 {
                Some(r.f.shape)
            } else {
                None
            };
            // The MF-Tyre 5.2 Mz takes only μy at γ = 0 from it, not Fy0.
            let force = !self.is52();
            self.fy0(c, r.dfz, r.dpi, T::c(0.0), r.spin, lmuy, shape, force, fl)
        }
    }

    /// [`Model::solve_with`] from its pure-slip part `r` and the upright
    /// Fy0 `f0`: the combined-slip forces (4.E50–4.E67), the aligning
    /// torque (4.E31–4.E49, 4.E71–4.E78) and Mx, My.
    #[inline(always)]
    fn finish(
        &self,
        c: &Conditions,
        mu_scale: f64,
        my: bool,
        r: &Pure<T>,
        f0: &Fy0<T>,
        mut fl: u32,
    ) -> Solution<T> {
        let p = &self.p;
        let lmuy = p.lmuy * mu_scale;
        let inv_lmuy = self.inv_lmuy * (1.0 / mu_scale);
        let one = T::c(1.0);
        let (dfz, dpi, spin, mux, kxk, f) = (r.dfz, r.dpi, r.spin, r.mux, r.kxk, r.f);
        let gs = T::c(c.gamma_star);
        let g = T::c(c.gamma);
        let (gs_z, g_z) = (gs * self.lgaz, g * self.lgaz);
        let r0 = p.unloaded_radius;

        // Aligning-torque ingredients (4.E31–4.E47, Dt and Bt per paper A60, A58).
        let fzm = T::c(c.fz_mz);
        let sht = p.qhz1 + p.qhz2 * dfz + (p.qhz3 + p.qhz4 * dfz) * gs_z; // 4.E35
        let kya_p = f.kya + EPS * sign1(f.kya); // 4.E39
        let shf = f.shy + f.svy / kya_p; // 4.E38
        let alphar = shf + c.alpha_star; // 4.E37
        let alphat = sht + c.alpha_star; // 4.E34
        let zeta5 = match spin {
            Some(s) => cos_atan(p.qdtp1 * r0 * s.phi), // 4.91
            None => one,
        };
        let dt = (p.qdz1 + p.qdz2 * dfz)
            * (-(p.ppz1 * dpi) + 1.0)
            * (p.qdz3 * g_z + p.qdz4 * g_z * g_z + 1.0)
            * fzm
            * (r0 * self.inv_fz0p)
            * p.ltr
            * zeta5; // A60
        let bt = (p.qbz1 + p.qbz2 * dfz + p.qbz3 * dfz * dfz)
            * (p.qbz4 * g_z + p.qbz5 * abs(g_z) + 1.0)
            * p.lky
            * inv_lmuy; // A58
        let ct = p.qcz1; // 4.E41
        let qez45 = p.qez4 + p.qez5 * gs_z;
        let et_shape = if !T::TRACKS_DERIVATIVES && qez45.v() == 0.0 {
            T::c(1.0) // value-only: the atan term is multiplied by 0
        } else {
            qez45 * (2.0 / PI) * (bt * ct * alphat).arctan() + 1.0
        };
        let et = (p.qez1 + p.qez2 * dfz + p.qez3 * dfz * dfz) * et_shape; // 4.E44
        let (et, hit) = cap_one(et, c.mode.limits);
        if hit {
            fl |= Clamped::ET;
        }

        let (fx, fy, gyk, svyk_unit) = self.combined(c, r, &mut fl);

        let (zeta0, zeta6, zeta7, zeta8) = match spin {
            Some(s) => {
                let z6 = cos_atan(p.qbrp1 * r0 * s.phi); // 4.102
                let mut mzp_inf =
                    p.qcrp1 * abs(f.muy) * r0 * fzm * (fzm / self.fz0p).sqrt() * p.lmp; // 4.95
                if mzp_inf.v() < 0.0 {
                    mzp_inf = T::c(1e-6);
                }
                let cdrp = p.qdrp1; // 4.96
                let ddrp = mzp_inf / (cdrp * (0.5 * PI)).sin(); // 4.94

                // As in MFeval: QDZ8·QDZ9·dfz (product) and |γ| unscaled (4.99).
                let kzgr0 = fzm
                    * r0
                    * (p.qdz8 * p.qdz9 * dfz + (p.qdz10 + p.qdz11 * dfz * c.gamma.abs()))
                    * p.lkzc;
                let bdrp = kzgr0 / (cdrp * ddrp * (-s.eps_g + 1.0));
                let drp = ddrp * (cdrp * (bdrp * r0 * c.phit).arctan()).sin();
                let mzp90 = mzp_inf * (2.0 / PI) * (p.qcrp2 * r0 * c.phit.abs()).arctan() * gyk; // 4.103

                // At φt = 0 both are 0; use the limit φt → 0 of the ratio
                // (MFeval gives 0/0 = NaN there: a deliberate difference).
                let ratio = if drp.v() == 0.0 && c.phit == 0.0 {
                    mzp_inf * (2.0 / PI) * p.qcrp2 * gyk / abs(ddrp * cdrp * bdrp)
                } else {
                    mzp90 / abs(drp)
                };
                // MATLAB's real(acos(x)) outside [−1, 1] is 0 or π.
                let z7 = if ratio.v() > 1.0 {
                    T::c(0.0)
                } else if ratio.v() < -1.0 {
                    T::c(1.0 * 2.0)
                } else {
                    ratio.acos() * (2.0 / PI)
                };
                (T::c(0.0), z6, z7, drp + 1.0)
            }
            None => (one, one, one, one),
        };
        let zeta2_mz = if spin.is_some() { f.zeta2 } else { one };
        let dr = fzm
            * r0
            * ((p.qdz6 + p.qdz7 * dfz) * p.lres * zeta2_mz
                + ((p.qdz8 + p.qdz9 * dfz) * (p.ppz2 * dpi + 1.0)
                    + (p.qdz10 + p.qdz11 * dfz) * abs(gs_z))
                    * gs_z
                    * p.lkzc
                    * zeta0)
            * lmuy
            * sign(c.vx)
            * c.cos_alpha_star
            + zeta8
            - 1.0; // 4.E47
        let br = (p.qbz9 * p.lky * inv_lmuy + p.qbz10 * f.by * f.cy) * zeta6; // 4.E45
        let cr = zeta7; // 4.E46

        // Combined-slip aligning torque (4.E71–4.E78 with paper A54–A56).
        let kr = kxk / kya_p;
        let kk2 = kr * kr * (c.kappa * c.kappa);
        let ar_eq = (alphar.tangent() * alphar.tangent() + kk2).sqrt().arctan() * sign(alphar); // A54
        let at_eq = (alphat.tangent() * alphat.tangent() + kk2).sqrt().arctan() * sign(alphat); // A55
        let s =
            r0 * (p.ssz1 + p.ssz2 * (fy * self.inv_fnomin) + (p.ssz3 + p.ssz4 * dfz) * g_z) * p.ls; // A56

        // Without turn slip Cr = 1 exactly, and cos(atan z) = 1/sqrt(1 + z²).
        let mzr = if spin.is_none() {
            dr * cos_atan(br * ar_eq)
        } else {
            dr * (cr * (br * ar_eq).arctan()).cos()
        } * c.smooth; // 4.E75
                      // Fy at γ = 0: `f0` (`fy0_upright`).
        let svyk0 = svyk_unit * f0.muy;
        let fy_prime = gyk * f0.fy0; // 4.E74
        let bat = bt * at_eq;
        // 4.E73, multiplied by LFZO as TNO's solver does (found by MFeval).
        let t = dt * (ct * curved(bat, et).arctan()).cos() * c.cos_alpha_prime * p.lfzo * c.smooth;
        let mz = if self.is52() {
            -t * (fy - svyk0) + mzr + s * fx // MF-Tyre 5.2 manual
        } else {
            -t * fy_prime + mzr + s * fx // 4.E71, 4.E72
        };

        let mx = self.mx(c, dpi, fy);
        let my = if my { self.my(c, fx) } else { T::c(f64::NAN) };
        Solution {
            fx,
            fy,
            mx,
            my,
            mz,
            mux,
            muy: f.muy,
            kxk,
            kya: f.kya,
            t,
            mzr,
            flags: fl,
        }
    }
}

/// The combined-slip weighting function cos(C·atan(B − E·(B − atan B)))
/// (Pacejka eqs. 4.E51, 4.E59); with C = 1 (`unit_c`, a value-only shortcut)
/// it is 1/sqrt(1 + y²) of the inner argument y.
#[inline(always)]
fn weight<T: Real>(unit_c: bool, c: T, b: T, e: T) -> T {
    let y = curved(b, e);
    if unit_c {
        cos_atan(y)
    } else {
        (c * y.arctan()).cos()
    }
}

/// The Magic Formula's curvature-modified argument B·x − E·(B·x − atan(B·x))
/// (`bx` = B·x); with E = 0 exactly it is B·x (a value-only shortcut that
/// saves the inner atan).
#[inline(always)]
fn curved<T: Real>(bx: T, e: T) -> T {
    if !T::TRACKS_DERIVATIVES && e.v() == 0.0 {
        bx
    } else {
        bx - e * (bx - bx.arctan())
    }
}
