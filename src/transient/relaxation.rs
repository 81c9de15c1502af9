//! relaxation — the first-order relaxation model in deflection form, linear
//! and non-linear (the instantaneous relaxation length from the local slope
//! of the force curve), with the MF-Tyre low-speed damping and saturation
//! (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §7.2).
//!
//! Must never: divide by the speed (the decay rate is ∝ the speed, solved
//! exactly by [`relax_exact`]), or leave the deflections beyond what friction
//! holds below VXLOW.

use super::{relax_exact, Slip, StepCtx, TransientState, SLOT_PHI, SLOT_X, SLOT_Y};
use crate::mf::MfInput;

/// Non-linear variant: the instantaneous relaxation length is kept at or
/// above this fraction of the zero-slip one (at and beyond the force peak the
/// local slope vanishes or turns negative).
pub const NL_SIGMA_MIN_FRACTION: f64 = 0.05;
/// Non-linear variant: the largest change of κ' or tan α' per sub-step.
pub const NL_MAX_SLIP_CHANGE: f64 = 0.01;
/// Non-linear variant: the most sub-steps in one step.
pub const NL_MAX_SUBSTEPS: usize = 32;
/// Speed at which the contact deflections decay (the rate of rolled
/// distance): |Vx| (Pacejka's form) from VXLOW up, blended below VXLOW into
/// the rolling speed of the contact |Vx − Vsx| = |Ω·Re| (brush/stretched-string
/// theory: the tread is renewed by rolling). The two agree for a free-rolling
/// wheel; for a wheel that neither rolls nor slides (a parked car rocking on
/// its tyres, a locked wheel at rest) the rolling speed is 0, so the elastic
/// deflection cannot creep away however the body oscillates.
#[inline]
fn decay_speed(c: &StepCtx) -> f64 {
    let w = c.props.weight;
    (1.0 - w) * c.kin.vx_abs + w * c.kin.v_roll
}

/// Low-speed saturation of the deflections: below VXLOW a deflection beyond
/// what friction can hold (μ·Fz/C, times the friction scale) is not elastic
/// but sliding, so it is dropped: |u| ≤ u_max/w (no limit from VXLOW up,
/// where the slip model itself saturates the force). Without it, a wheel
/// that locks and stops keeps the deflection σκ·|κ'| ≈ σκ of full sliding
/// (tens of cm) and pushes the vehicle back by as much once at rest.
#[inline]
fn saturate(c: &StepCtx, u: f64, w: f64) -> (f64, f64) {
    let k = c.props.weight;
    if k <= 0.0 {
        return (u, w);
    }
    let lx = c.s * c.props.ux_max / k;
    let ly = c.s * c.props.uy_max / k;
    (u.clamp(-lx, lx), w.clamp(-ly, ly))
}

/// Linear relaxation in deflection form (Pacejka 3rd ed. §7.2.1, eqs 7.9–7.12,
/// with the MF-Tyre low-speed damping of §7.2.3):
///
/// ```text
///   du/dt = −Vsx − V·u/σκ        κ'     = (u + τx·w·du/dt)/σκ
///   dv/dt =  Vsy − V·v/σα        tan α' = (v + τy·w·dv/dt)/σα
///   dφ'/dt = (V/σα)·(φt − φ')    (turn slip, when used)
/// ```
/// with V = |Vx| from VXLOW up ([`decay_speed`] below), and the low-speed
/// saturation of [`saturate`].
/// τ = c/C (damping over carcass stiffness), w the low-speed blend. At rest
/// (|Vx| = 0) the deflection integrates the slip speed: the force is the
/// carcass spring C·u (+ damping), with no creep (the decay term is ∝ the rolling speed).
/// Returns the slips (κ', tan α') the Magic Formula is evaluated at.
pub(crate) fn relax_linear(c: &StepCtx, st: &mut TransientState, dt: f64) -> (f64, f64) {
    let (sx, sy) = (c.props.sigma_x, c.props.sigma_y);
    let v = decay_speed(c);
    let (rx, ry) = (v / sx, v / sy);
    let (u, w) = saturate(
        c,
        relax_exact(st.x[SLOT_X], rx, -c.kin.vsx, dt),
        relax_exact(st.x[SLOT_Y], ry, c.kin.vsy, dt),
    );
    st.x[SLOT_X] = u;
    st.x[SLOT_Y] = w;
    if c.mode.turn_slip {
        st.x[SLOT_PHI] = relax_exact(st.x[SLOT_PHI], ry, ry * c.base.phit, dt);
    }
    let du = -c.kin.vsx - rx * u;
    let dw = c.kin.vsy - ry * w;
    let kx = (u + c.props.damp_x / c.props.cx * du) / sx;
    let ky = (w + c.props.damp_y / c.props.cy * dw) / sy;
    (kx, ky)
}

/// Instantaneous relaxation lengths at slips (κ', tan α'):
/// σ = σ0·|∂F/∂slip|/|K0| with K0 the MF's slip stiffness at zero slip (so
/// that σ = σ0 at zero slip whichever formula gave σ0), or |∂F/∂slip|/C when
/// the MF gives no K0; forward differences of the Magic Formula; kept within
/// [NL_SIGMA_MIN_FRACTION·σ0, 2·σ0].
fn inst_sigma(c: &StepCtx, k: f64, t: f64) -> (f64, f64) {
    const H: f64 = 1e-5;
    let mut mi = c.base;
    let f = |mi: &mut MfInput, kk: f64, tt: f64| c.forces_xy(mi, Slip::new(kk, tt));
    let f0 = f(&mut mi, k, t);
    let fk = f(&mut mi, k + H, t);
    let ft = f(&mut mi, k, t + H);
    let (s0x, s0y) = (c.props.sigma_x, c.props.sigma_y);
    let clamp = |s: f64, s0: f64| {
        if s.is_finite() {
            s.clamp(NL_SIGMA_MIN_FRACTION * s0, 2.0 * s0)
        } else {
            s0
        }
    };
    let scale = |k0: f64, s0: f64, cc: f64| {
        if k0.is_finite() && k0 != 0.0 {
            s0 / k0.abs()
        } else {
            1.0 / cc
        }
    };
    let sx = ((fk.0 - f0.0) / H).abs() * scale(c.props.kxk, s0x, c.props.cx);
    let sy = ((ft.1 - f0.1) / H).abs() * scale(c.props.kya, s0y, c.props.cy);
    (clamp(sx, s0x), clamp(sy, s0y))
}

/// Non-linear relaxation (Pacejka 3rd ed. §7.2.2): the carcass stays a linear
/// spring C while the contact slip follows the force curve, which gives the
/// relaxation length σ(κ') = C_Fκ(κ')/C from the local slope. With the state
/// scaled as in the linear model (κ' = u/σκ0):
/// `du/dt = (σκ0/σκ(κ'))·(−Vsx − |Vx|·u/σκ0)`, likewise laterally. σ is frozen
/// over each sub-step at its exponential-midpoint value (solved exactly, second
/// order in the sub-step; a step whose slips change by less than a tenth of
/// that keeps σ of its start); the number of sub-steps keeps the
/// change of κ' and tan α' per sub-step below [`NL_MAX_SLIP_CHANGE`].
pub(crate) fn relax_nonlinear(c: &StepCtx, st: &mut TransientState, dt: f64) -> (f64, f64) {
    let (s0x, s0y) = (c.props.sigma_x, c.props.sigma_y);
    let v = decay_speed(c);
    let adv = |u: f64, w: f64, sx: f64, sy: f64, h: f64| {
        (
            relax_exact(u, v / sx, -c.kin.vsx * s0x / sx, h),
            relax_exact(w, v / sy, c.kin.vsy * s0y / sy, h),
        )
    };
    let (u0, w0) = (st.x[SLOT_X], st.x[SLOT_Y]);
    // Trial: σ frozen at the start. Small slip changes keep it (the error is
    // second order in a change below NL_MAX_SLIP_CHANGE/10); otherwise
    // sub-steps with σ at each sub-step's exponential midpoint (predicted with
    // σ at its start): second order in the sub-step.
    let (sx0, sy0) = inst_sigma(c, u0 / s0x, w0 / s0y);
    let (mut u, mut w) = adv(u0, w0, sx0, sy0, dt);
    let (mut sx, mut sy) = (sx0, sy0);
    let change = ((u - u0) / s0x).abs().max(((w - w0) / s0y).abs());
    if change > 0.1 * NL_MAX_SLIP_CHANGE {
        let n = ((change / NL_MAX_SLIP_CHANGE).ceil() as usize).clamp(1, NL_MAX_SUBSTEPS);
        let h = dt / n as f64;
        (u, w) = (u0, w0);
        for i in 0..n {
            let (ssx, ssy) = if i == 0 {
                (sx0, sy0)
            } else {
                inst_sigma(c, u / s0x, w / s0y)
            };
            let (um, wm) = adv(u, w, ssx, ssy, 0.5 * h);
            (sx, sy) = inst_sigma(c, um / s0x, wm / s0y);
            (u, w) = adv(u, w, sx, sy, h);
        }
    }
    (u, w) = saturate(c, u, w);
    st.x[SLOT_X] = u;
    st.x[SLOT_Y] = w;
    if c.mode.turn_slip {
        let ry = v / s0y;
        st.x[SLOT_PHI] = relax_exact(st.x[SLOT_PHI], ry, ry * c.base.phit, dt);
    }
    let du = (s0x / sx) * (-c.kin.vsx - v * u / s0x);
    let dw = (s0y / sy) * (c.kin.vsy - v * w / s0y);
    let kx = (u + c.props.damp_x / c.props.cx * du) / s0x;
    let ky = (w + c.props.damp_y / c.props.cy * dw) / s0y;
    (kx, ky)
}
