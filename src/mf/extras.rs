//! extras — the quantities beside the forces: effective rolling radius and
//! wheel-spin estimate, loaded radius / deflection / vertical stiffness,
//! contact patch, carcass stiffnesses and relaxation lengths.
//!
//! Sources: Besselink et al. 2010 (MF 6.1) eqs. 1, 4, 5, 7, 9, 10, 17–19;
//! the MF-Tyre/MF-Swift 6.2 equation manual for the 6.2 vertical force
//! (Fz as a function of the loaded radius); MF-Tyre 5.2 manual for the 5.2
//! contact length and relaxation lengths; Pacejka eq. A3.3. Numerical choices
//! (iteration of Re, guards) follow MFeval 4.0 so outputs compare exactly.
//!
//! Must never: allocate, loop without a bound, or turn an undefined value
//! (0/0, negative root) into a finite number that looks valid.

use super::limits::Conditions;
use crate::tir::MfParams;

/// Effective rolling radius Re, free-spinning radius Rω and wheel spin ω.
///
/// Re = Rω − (Fz0/Cz)·(DREFF·atan(BREFF·Fz/Fz0) + FREFF·Fz/Fz0) (paper eq. 7)
/// with Rω = R0·(Q_RE0 + Q_V1·(ω R0/V0)²) (eq. 1) and Cz = Cz0·(1 + PFZ1 dpi)
/// (eq. 5). When ω is not given (0), it is found by iterating
/// ω = (1 + κ)·Vx/Re (Pacejka eq. 2.5) from Re = 0.965 R0 until Re changes by
/// at most 1e-9 m (MFeval's rule; bounded here at 1000 steps).
pub fn effective_radius(p: &MfParams<f64>, c: &Conditions, omega_in: f64) -> (f64, f64, f64) {
    let dpi = (c.p - p.nompres) / p.nompres;
    let r0 = p.unloaded_radius;
    let cz = p.vertical_stiffness * (1.0 + p.pfz1 * dpi);
    let fzn = c.fz_u / p.fnomin;
    let defl = (p.fnomin / cz) * (p.dreff * (p.breff * fzn).atan() + p.freff * fzn);
    let romega_of = |w: f64| r0 * (p.q_re0 + p.q_v1 * ((w * r0) / p.longvl).powi(2));
    if omega_in != 0.0 {
        // ε added as MFeval does (keeps Rω defined at ω = 0).
        let w = omega_in + f64::EPSILON;
        let rw = romega_of(w);
        return (rw - defl, rw, w);
    }
    let mut omega = 0.0;
    let mut romega = romega_of(omega);
    let mut re = r0 * 0.965;
    let mut re_old = r0;
    let mut n = 0;
    while (re_old - re).abs() > 1e-9 && n < 1000 {
        re_old = re;
        omega = (c.kappa_u * c.vx + c.vx) / re;
        romega = romega_of(omega);
        re = romega - defl;
        n += 1;
    }
    (re, romega, omega)
}

/// Vertical force of MF 6.2 for a given loaded radius `rl` (MF-Tyre/MF-Swift
/// 6.2 equation manual; Pacejka A3.3 with camber deflection and the lateral
/// force correction). Returns (Fz, deflection ρz).
#[allow(clippy::too_many_arguments)]
pub fn fz62(
    p: &MfParams<f64>,
    gamma: f64,
    omega: f64,
    romega: f64,
    dpi: f64,
    rl: f64,
    fx: f64,
    fy: f64,
) -> (f64, f64) {
    let r0 = p.unloaded_radius;
    let fz0 = p.fnomin;
    let q_fz1 = ((p.vertical_stiffness * r0 / fz0).powi(2) - 4.0 * p.q_fz2).sqrt();
    let rr = rl / romega;
    let sfyg = (p.q_fys1 + p.q_fys2 * rr + p.q_fys3 * rr * rr) * gamma;
    let rho_fr = (romega - rl).max(0.0);
    let rtw = (1.075 - 0.5 * p.aspect_ratio) * p.width;
    let num = ((p.q_cam1 * rl + p.q_cam2 * rl * rl) * gamma).powi(2);
    let den = ((p.q_cam1 * romega + p.q_cam2 * romega * romega) * gamma).powi(2);
    let mut rho_g = num * (rtw / 8.0) * gamma.tan().abs() / den - p.q_cam3 * rho_fr * gamma.abs();
    if rho_g.is_nan() {
        rho_g = 0.0;
    }
    let rho = (rho_fr + rho_g).max(0.0);
    let fyc = (rho / r0).powf(p.q_fcy2) * (p.q_fcy * (fy - sfyg) / fz0);
    let fcorr =
        (1.0 + p.q_v2 * (r0 / p.longvl) * omega.abs() - (p.q_fcx * fx / fz0).powi(2) - fyc * fyc)
            * (1.0 + p.pfz1 * dpi);
    let x = rho / r0;
    (fcorr * (q_fz1 * x + p.q_fz2 * x * x) * fz0, rho)
}

/// Loaded radius, deflection and Cz = Fz/ρ.
///
/// MF 6.1: the quadratic of Pacejka A3.3 solved for ρ (Q_FZ1 from
/// Cz0 = (Fz0/R0)·sqrt(Q_FZ1² + 4 Q_FZ2), paper eq. 4), at the FZMIN-limited
/// load in use mode 1xx; Q_FZ2 = 0 gives 0/0 → ρ = 0 and Cz = ∞ as in MFeval.
///
/// MF 6.2 / 5.2: the exact root of [`fz62`]`(Rl) = Fz` below Rω (MFeval uses a
/// Nelder–Mead search that can stall; see the reference README). For Fz = 0,
/// Rl = Rω. ρ = 1e-6 where the load is 0 (MFeval's guard).
#[allow(clippy::too_many_arguments)]
pub fn loaded_radius(
    p: &MfParams<f64>,
    is61: bool,
    c: &Conditions,
    omega: f64,
    romega: f64,
    fx: f64,
    fy: f64,
) -> (f64, f64, f64) {
    let dpi = (c.p - p.nompres) / p.nompres;
    if is61 {
        let fz = if c.mode.limits && c.fz < p.fzmin {
            p.fzmin
        } else {
            c.fz
        };
        let r0 = p.unloaded_radius;
        let fz0 = p.fnomin;
        let q_fz1 = ((p.vertical_stiffness * r0 / fz0).powi(2) - 4.0 * p.q_fz2).sqrt();
        let ext = (1.0 + p.q_v2 * (r0 / p.longvl) * omega.abs()
            - (p.q_fcx * fx / fz0).powi(2)
            - (p.q_fcy * fy / fz0).powi(2))
            * (1.0 + p.pfz1 * dpi)
            * fz0;
        let (a, b, cc) = (p.q_fz2, q_fz1, -(fz / ext));
        let x = (-b + (b * b - 4.0 * a * cc).sqrt()) / (2.0 * a);
        let rho_fr = (x * r0).max(0.0); // NaN (0/0) → 0, as MATLAB's max
        let rl = (romega - rho_fr).max(0.0);
        let rho = if fz == 0.0 { 1e-6 } else { rho_fr };
        return (rl, rho, fz / rho);
    }
    let fz = c.fz;
    let rl = if fz > 0.0 {
        root_rl(p, c.gamma, omega, romega, dpi, fz, fx, fy)
    } else {
        romega
    };
    let (_, rho) = fz62(p, c.gamma, omega, romega, dpi, rl, fx, fy);
    let rho = if fz == 0.0 { 1e-6 } else { rho };
    (rl, rho, fz / rho)
}

/// Physical root of Fz62(Rl) = Fz in (0, Rω): the sign change nearest below
/// Rω (a scan in 256 steps from Rω downwards, then bisection to 1e-15 m).
/// NaN when there is none.
#[allow(clippy::too_many_arguments)]
fn root_rl(
    p: &MfParams<f64>,
    gamma: f64,
    omega: f64,
    romega: f64,
    dpi: f64,
    fz: f64,
    fx: f64,
    fy: f64,
) -> f64 {
    let f = |rl: f64| fz62(p, gamma, omega, romega, dpi, rl, fx, fy).0 - fz;
    if romega.is_nan() || romega <= 0.0 {
        return f64::NAN;
    }
    const N: usize = 256;
    // At Rl = Rω the free-rolling deflection is 0 and so is Fz62 (the camber
    // term aside); use −Fz there so that 0·∞ in (ρ/R0)^Q_FCY2 cannot hide it.
    let mut hi = romega;
    let mut fhi = f(hi);
    if (fhi.is_nan() || fhi >= 0.0) && gamma == 0.0 {
        fhi = -fz;
    }
    let mut lo = f64::NAN;
    for i in 1..=N {
        let x = romega * (1.0 - 0.99 * i as f64 / N as f64);
        let fx_ = f(x);
        if fx_ >= 0.0 && fhi < 0.0 {
            lo = x;
            break;
        }
        hi = x;
        fhi = fx_;
    }
    if lo.is_nan() {
        return f64::NAN;
    }
    // Invariant: f(lo) ≥ 0 > f(hi).
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi || hi - lo < 1e-15 {
            break;
        }
        if f(mid) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Contact patch half length a and half width b.
///
/// MF 6.x (paper eqs. 9, 10), with x = Fz/(Cz R0):
/// a = R0·(Q_RA2·x + Q_RA1·sqrt(x)) and b = w·(Q_RB2·x + Q_RB1·x^(1/3)).
/// MF 5.2: a = R0·(Q_A2·Fz/Fz0 + Q_A1·sqrt(Fz/Fz0)) and b = w/2; when the file
/// has neither Q_A1 nor Q_A2,
/// MFeval's empirical defaults from log10(R0 Cz0/Fz0). Beyond bottoming
/// (R0 − Fz/Cz below RIM_RADIUS + BOTTOM_OFFST) the load is held at the
/// bottoming load.
pub fn contact_patch(p: &MfParams<f64>, is52: bool, c: &Conditions) -> (f64, f64) {
    let dpi = (c.p - p.nompres) / p.nompres;
    let r0 = p.unloaded_radius;
    let ncz = p.vertical_stiffness * (1.0 + p.pfz1 * dpi);
    let mut fz = c.fz_u;
    if r0 - fz / ncz - (p.rim_radius + p.bottom_offst) < 0.0 {
        fz = (r0 - p.rim_radius - p.bottom_offst) * ncz;
    }
    if is52 {
        let (mut qa1, mut qa2) = (p.q_a1, p.q_a2);
        if qa1 == 0.0 && qa2 == 0.0 {
            let y = (r0 * (p.vertical_stiffness / p.fnomin)).log10();
            qa1 = -0.0388 * y.powi(3) + 0.2509 * y.powi(2) + -0.6283 * y + 0.6279;
            qa2 = 1.693 * qa1 * qa1;
        }
        let a = r0 * (qa2 * (fz / p.fnomin) + qa1 * (fz / p.fnomin).sqrt());
        (a, p.width / 2.0)
    } else {
        let x = fz / (ncz * r0);
        let a = r0 * (p.q_ra2 * x + p.q_ra1 * x.sqrt());
        let b = p.width * (p.q_rb2 * x + p.q_rb1 * x.powf(1.0 / 3.0));
        (a, b)
    }
}

/// Carcass stiffnesses Cx, Cy (paper eqs. 17, 18) and relaxation lengths
/// σx = |Kxκ/Cx|, σy = |Kyα/Cy| (eq. 19); MF 5.2 uses its own σ formulas
/// (PTX1–3, PTY1–2).
pub fn relaxation(
    p: &MfParams<f64>,
    is52: bool,
    c: &Conditions,
    kxk: f64,
    kya: f64,
) -> (f64, f64, f64, f64) {
    let fz0p = p.lfzo * p.fnomin;
    let dfz = (c.fz - fz0p) / fz0p;
    let dpi = (c.p - p.nompres) / p.nompres;
    let cx = p.longitudinal_stiffness
        * (1.0 + p.pcfx1 * dfz + p.pcfx2 * dfz * dfz)
        * (1.0 + p.pcfx3 * dpi);
    let cy =
        p.lateral_stiffness * (1.0 + p.pcfy1 * dfz + p.pcfy2 * dfz * dfz) * (1.0 + p.pcfy3 * dpi);
    let (sx, sy) = if is52 {
        let r0 = p.unloaded_radius;
        let sx = (p.ptx1 + p.ptx2 * dfz) * (-p.ptx3 * dfz).exp() * p.lsgkp * r0 * c.fz / p.fnomin;
        let sy = p.pty1
            * (2.0 * (c.fz / (p.pty2 * fz0p)).atan()).sin()
            * (1.0 - p.pky3 * c.gamma.abs())
            * r0
            * p.lfzo
            * p.lsgal;
        (sx, sy)
    } else {
        ((kxk / cx).abs(), (kya / cy).abs())
    };
    (cx, cy, sx, sy)
}
