//! props — the tyre's per-step properties from one zero-slip Magic Formula
//! evaluation (the "probe"): rolling radius, carcass stiffnesses, relaxation
//! lengths, low-speed damping and the friction hold of the deflections.
//!
//! Must never: return a non-finite or non-positive stiffness or relaxation
//! length (each falls back to the file's value or a stated default).

use super::{SIGMA_MAX, SIGMA_MIN};
use crate::mf::{SlipProps, Tyre};
use crate::tir::MfVersion;

/// Per-step tyre properties, from one Magic Formula evaluation at zero slip
/// (the "probe"): radius, carcass stiffnesses, relaxation lengths, damping.
#[derive(Clone, Copy, Debug, Default)]
pub struct TyreProps {
    /// Effective rolling radius (m).
    pub re: f64,
    /// Longitudinal carcass stiffness Cx (N/m): the MF's (MF 6.1/6.2,
    /// PCFX*), else LONGITUDINAL_STIFFNESS of the file.
    pub cx: f64,
    /// Lateral carcass stiffness Cy (N/m): the MF's (MF 6.1/6.2, PCFY*),
    /// else LATERAL_STIFFNESS of the file.
    pub cy: f64,
    /// Longitudinal relaxation length σκ at zero slip (m), = Kxκ/Cx
    /// (Pacejka 3rd ed. §7.2) or the file's MF 5.2 PTX form; clamped to
    /// [`SIGMA_MIN`]..[`SIGMA_MAX`].
    pub sigma_x: f64,
    /// Lateral relaxation length σα at zero slip (m), = Kyα/Cy (Pacejka
    /// 3rd ed. §7.2) or the file's MF 5.2 PTY form; clamped likewise.
    pub sigma_y: f64,
    /// Longitudinal low-speed damping (N·s/m), already weighted by the
    /// speed blend `weight` (zero from VXLOW up).
    pub damp_x: f64,
    /// Lateral low-speed damping (N·s/m), weighted like `damp_x`.
    pub damp_y: f64,
    /// Low-speed blend w(|Vx|) (1 at rest, 0 from VXLOW up).
    pub weight: f64,
    /// Longitudinal deflection friction can hold, μx·Fz/Cx (m); infinite
    /// when the MF gives no μ; before the friction scale.
    pub ux_max: f64,
    /// Lateral deflection friction can hold, μy·Fz/Cy (m); as `ux_max`.
    pub uy_max: f64,
    /// Unweighted longitudinal damping (N·s/m),
    /// `DAMP_VLOW·Cx + 2·DAMP_LONG·√(Cx·BELT_MASS)` (LuGre σ1 default).
    pub damp_x_full: f64,
    /// Unweighted lateral damping (N·s/m),
    /// `DAMP_VLOW·Cy + 2·DAMP_LAT·√(Cy·BELT_MASS)` (LuGre σ1 default).
    pub damp_y_full: f64,
    /// The MF's longitudinal friction coefficient μx (–, slip-independent,
    /// Pacejka 3rd ed. eq. 4.E13), before the friction scale.
    pub mux: f64,
    /// The MF's lateral friction coefficient μy (–, slip-independent,
    /// Pacejka 3rd ed. eq. 4.E23), before the friction scale.
    pub muy: f64,
    /// MF longitudinal force Fx at zero slip (N) at the actual speed (0 if
    /// not finite, or not computed: the step's probe skips it where unused).
    pub fx0: f64,
    /// MF lateral force Fy at zero slip (N), as `fx0` (shifts, camber thrust).
    pub fy0: f64,
    /// Longitudinal slip stiffness Kxκ at zero slip (N per unit κ), from the MF.
    pub kxk: f64,
    /// Cornering stiffness Kyα at zero slip (N/rad), from the MF, with its
    /// sign (negative in ISO-W for the usual negative PKY1).
    pub kya: f64,
}

/// Relaxation length from a slip stiffness and a carcass stiffness, with the
/// guards documented at [`SIGMA_MIN`]/[`SIGMA_MAX`].
#[inline]
fn sigma_from(k: f64, c: f64) -> f64 {
    let s = k.abs() / c;
    if s.is_finite() {
        s.clamp(SIGMA_MIN, SIGMA_MAX)
    } else {
        SIGMA_MIN
    }
}

/// Low-speed blend w(|Vx|) = ½(1 + cos(π|Vx|/VXLOW)) below VXLOW, 0 above
/// (the smooth switch of the MF-Tyre low-speed damping, Pacejka 3rd ed. §7.2.3 / §8.6).
#[inline]
pub fn low_speed_weight(vx_abs: f64, vxlow: f64) -> f64 {
    let vl = if vxlow > 0.0 { vxlow } else { 1.0 };
    if vx_abs >= vl {
        0.0
    } else {
        0.5 * (1.0 + (std::f64::consts::PI * vx_abs / vl).cos())
    }
}

/// Tyre properties for this step from the zero-slip probe `o` ([`Tyre::slip_properties`]; see [`TyreProps`]).
///
/// * Carcass stiffnesses: the MF's Cx, Cy (MF 6.1/6.2 load and pressure
///   dependent, PCFX*/PCFY*); when the MF gives none, LONGITUDINAL_STIFFNESS /
///   LATERAL_STIFFNESS of the file.
/// * Relaxation lengths (Pacejka 3rd ed. §7.2, eqs 7.9–7.12; MF-Tyre 6.x):
///   the MF's `sigmax`/`sigmay` when it gives them (MF 6.x: σκ = Kxκ/Cx,
///   σα = Kyα/Cy; MF 5.2/PAC2002: PTX1..3, PTY1..2). When it does not
///   (placeholder MF), MF 5.2/PAC2002 files use their PTX/PTY forms here and
///   all others σ = |K|/C from the MF's slip stiffnesses; both clamped to
///   [`SIGMA_MIN`]..[`SIGMA_MAX`].
/// * Low-speed damping (N s/m): `DAMP_VLOW·C + 2·DAMP_LONG·√(C·BELT_MASS)`
///   (the low-speed damping proportional to stiffness plus the carcass' own
///   relative damping on the belt mass), blended in below VXLOW.
pub fn tyre_props(tyre: &Tyre, o: &SlipProps, fz: f64, vx_abs: f64) -> TyreProps {
    let p = &tyre.params().p;
    let pos = |x: f64, fb: f64| if x.is_finite() && x > 0.0 { x } else { fb };
    let cx = pos(o.cx, pos(p.longitudinal_stiffness, 3e5));
    let cy = pos(o.cy, pos(p.lateral_stiffness, 1e5));
    let fz0 = pos(p.fnomin * p.lfzo, 4000.0);
    let dfz = (fz - fz0) / fz0;
    let r0 = pos(p.unloaded_radius, 0.3);
    let legacy = matches!(tyre.version(), MfVersion::Mf52 | MfVersion::Pac2002);
    let sigma_x = if o.sigmax.is_finite() && o.sigmax > 0.0 {
        o.sigmax.clamp(SIGMA_MIN, SIGMA_MAX)
    } else if legacy && p.ptx1 != 0.0 {
        // MF 5.2: σκ = Fz·(PTX1 + PTX2·dfz)·exp(−PTX3·dfz)·(R0/Fz0)·LSGKP
        let s = fz * (p.ptx1 + p.ptx2 * dfz) * (-p.ptx3 * dfz).exp() * (r0 / fz0) * p.lsgkp;
        sigma_from(s, 1.0)
    } else {
        sigma_from(o.kxk, cx)
    };
    let sigma_y = if o.sigmay.is_finite() && o.sigmay > 0.0 {
        o.sigmay.clamp(SIGMA_MIN, SIGMA_MAX)
    } else if legacy && p.pty1 != 0.0 && p.pty2 != 0.0 {
        // MF 5.2: σα = PTY1·sin(2·atan(Fz/(PTY2·Fz0)))·(1 − PKY3·|γ|)·R0·LFZO·LSGAL
        let s = p.pty1
            * (2.0 * (fz / (p.pty2 * fz0)).atan()).sin()
            * (1.0 - p.pky3 * o.gamma.abs())
            * r0
            * p.lfzo
            * p.lsgal;
        sigma_from(s, 1.0)
    } else {
        sigma_from(o.kya, cy)
    };
    let mb = if p.belt_mass.is_finite() && p.belt_mass > 0.0 {
        p.belt_mass
    } else {
        0.0
    };
    let nn = |x: f64| if x.is_finite() && x > 0.0 { x } else { 0.0 };
    let damp_x_full = nn(p.damp_vlow) * cx + 2.0 * nn(p.damp_long) * (cx * mb).sqrt();
    let damp_y_full = nn(p.damp_vlow) * cy + 2.0 * nn(p.damp_lat) * (cy * mb).sqrt();
    let w = low_speed_weight(vx_abs, p.vxlow);
    let hold = |mu: f64, c: f64| {
        let u = mu.abs() * fz / c;
        if u.is_finite() && u > 0.0 {
            u
        } else {
            f64::INFINITY
        }
    };
    TyreProps {
        re: rolling_radius(tyre, o.re),
        cx,
        cy,
        sigma_x,
        sigma_y,
        weight: w,
        ux_max: hold(o.mux, cx),
        uy_max: hold(o.muy, cy),
        damp_x: w * damp_x_full,
        damp_y: w * damp_y_full,
        damp_x_full,
        damp_y_full,
        mux: o.mux,
        muy: o.muy,
        fx0: if o.fx.is_finite() { o.fx } else { 0.0 },
        fy0: if o.fy.is_finite() { o.fy } else { 0.0 },
        kxk: o.kxk,
        kya: o.kya,
    }
}

/// The effective rolling radius in use: the MF's Re when it is a positive
/// number, else UNLOADED_RADIUS (else 0.3 m).
#[inline]
pub(crate) fn rolling_radius(tyre: &Tyre, re: f64) -> f64 {
    let pos = |x: f64, fb: f64| if x.is_finite() && x > 0.0 { x } else { fb };
    pos(re, pos(tyre.params().p.unloaded_radius, 0.3))
}
