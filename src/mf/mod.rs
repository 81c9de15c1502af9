//! mf — the steady-state Magic Formula (MF 6.1/6.2, MF 5.2, PAC2002): forces and
//! moments for pure and combined slip, plus the derived quantities (radii,
//! contact patch, trail, friction, stiffnesses, relaxation lengths).
//! ISO-W axes, SI units.
//!
//! Must never: allocate in [`Tyre::evaluate`] / [`Tyre::forces`], hold global
//! state, or return a finite number where the equations are undefined.
//!
//! STUB (to be replaced by the Magic Formula work of issue #2): the API below is
//! the contract other modules build on; the numbers are a crude placeholder.

use crate::tir::{MfVersion, TyreParams};

/// MFeval-style use mode: hundreds = limit checks (1 on, 2 off), tens = α*
/// definition (1 off, 2 on), units = turn slip (1 off, 2 on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UseMode {
    /// Apply the `.tir` range limits and the low-speed model.
    pub limits: bool,
    /// Use α* = tan α · sign(Vx) (Pacejka's book) instead of α.
    pub alpha_star: bool,
    /// Evaluate turn slip (φt).
    pub turn_slip: bool,
}

impl UseMode {
    /// Parse a three-digit use mode (111, 121, 211, 221, 112 …).
    pub fn from_code(code: u32) -> Option<UseMode> {
        let (h, t, u) = (code / 100, (code / 10) % 10, code % 10);
        if code > 999 || !(1..=2).contains(&h) || !(1..=2).contains(&t) || !(1..=2).contains(&u) {
            return None;
        }
        Some(UseMode {
            limits: h == 1,
            alpha_star: t == 2,
            turn_slip: u == 2,
        })
    }
    /// The three-digit code.
    pub fn code(&self) -> u32 {
        100 * (if self.limits { 1 } else { 2 })
            + 10 * (if self.alpha_star { 2 } else { 1 })
            + if self.turn_slip { 2 } else { 1 }
    }
}

impl Default for UseMode {
    /// 111: limit checks on, no α*, no turn slip.
    fn default() -> Self {
        UseMode {
            limits: true,
            alpha_star: false,
            turn_slip: false,
        }
    }
}

/// Inputs of one evaluation (MFeval's 8 input columns), ISO-W, SI.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MfInput {
    /// Normal load (N), positive pressing the tyre on the road.
    pub fz: f64,
    /// Longitudinal slip ratio (–).
    pub kappa: f64,
    /// Slip angle (rad).
    pub alpha: f64,
    /// Inclination angle (rad).
    pub gamma: f64,
    /// Turn slip (1/m).
    pub phit: f64,
    /// Longitudinal speed of the wheel centre (m/s).
    pub vx: f64,
    /// Inflation pressure (Pa); 0 or NaN means the file's INFLPRES.
    pub p: f64,
    /// Wheel spin (rad/s); 0 or NaN means "estimate it from κ, Vx and Re" as MFeval does.
    pub omega: f64,
}

/// Forces and moments only (the hot-path result), ISO-W, SI.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Forces {
    pub fx: f64,
    pub fy: f64,
    pub mx: f64,
    pub my: f64,
    pub mz: f64,
}

/// Names of the 30 output columns, in MFeval's order.
pub const OUTPUT_COLUMNS: [&str; 30] = [
    "Fx", "Fy", "Fz", "Mx", "My", "Mz", "kappa", "alpha", "gamma", "phit", "Vx", "P", "Re", "rho",
    "2a", "t", "mux", "muy", "omega", "Rl", "2b", "Mzr", "Cx", "Cy", "Cz", "Kya", "sigmax",
    "sigmay", "instKya", "Kxk",
];

/// All outputs of one evaluation, in MFeval's order ([`OUTPUT_COLUMNS`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[allow(missing_docs)]
pub struct MfOutput {
    pub fx: f64,
    pub fy: f64,
    pub fz: f64,
    pub mx: f64,
    pub my: f64,
    pub mz: f64,
    pub kappa: f64,
    pub alpha: f64,
    pub gamma: f64,
    pub phit: f64,
    pub vx: f64,
    pub p: f64,
    pub re: f64,
    pub rho: f64,
    pub a2: f64,
    pub t: f64,
    pub mux: f64,
    pub muy: f64,
    pub omega: f64,
    pub rl: f64,
    pub b2: f64,
    pub mzr: f64,
    pub cx: f64,
    pub cy: f64,
    pub cz: f64,
    pub kya: f64,
    pub sigmax: f64,
    pub sigmay: f64,
    pub inst_kya: f64,
    pub kxk: f64,
}

impl MfOutput {
    /// The outputs as an array in [`OUTPUT_COLUMNS`] order.
    pub fn to_array(&self) -> [f64; 30] {
        [
            self.fx,
            self.fy,
            self.fz,
            self.mx,
            self.my,
            self.mz,
            self.kappa,
            self.alpha,
            self.gamma,
            self.phit,
            self.vx,
            self.p,
            self.re,
            self.rho,
            self.a2,
            self.t,
            self.mux,
            self.muy,
            self.omega,
            self.rl,
            self.b2,
            self.mzr,
            self.cx,
            self.cy,
            self.cz,
            self.kya,
            self.sigmax,
            self.sigmay,
            self.inst_kya,
            self.kxk,
        ]
    }
}

/// A tyre ready to evaluate: the property file plus whatever can be
/// precomputed from it. Immutable and `Send + Sync`: share it between threads.
#[derive(Clone, Debug)]
pub struct Tyre {
    params: TyreParams,
}

impl Tyre {
    /// Prepare a tyre from loaded parameters.
    pub fn new(params: TyreParams) -> crate::Result<Tyre> {
        Ok(Tyre { params })
    }
    /// Load a `.tir` file and prepare it.
    pub fn from_file(path: &std::path::Path) -> crate::Result<Tyre> {
        Tyre::new(TyreParams::from_file(path)?)
    }
    /// The built-in default tyre.
    pub fn builtin() -> Tyre {
        Tyre {
            params: TyreParams::builtin(),
        }
    }
    /// The parameters this tyre was built from.
    pub fn params(&self) -> &TyreParams {
        &self.params
    }
    /// Equation set in use.
    pub fn version(&self) -> MfVersion {
        self.params.version
    }

    /// Full evaluation (all 30 outputs). Allocation-free.
    pub fn evaluate(&self, inp: &MfInput, mode: UseMode) -> MfOutput {
        let _ = mode;
        let p = &self.params.p;
        let fz = inp.fz.max(0.0);
        let dfz = (fz - p.fnomin) / p.fnomin;
        let mux = p.pdx1 + p.pdx2 * dfz;
        let muy = p.pdy1 + p.pdy2 * dfz;
        let kx = fz * (p.pkx1 + p.pkx2 * dfz);
        let ky = p.pky1 * p.fnomin * (2.0 * (fz / (p.pky2 * p.fnomin)).atan()).sin();
        let fx = mux * fz * (p.pcx1 * (kx / (p.pcx1 * mux * fz + 1e-9) * inp.kappa).atan()).sin();
        let fy = muy * fz * (p.pcy1 * (ky / (p.pcy1 * muy * fz + 1e-9) * inp.alpha).atan()).sin();
        MfOutput {
            fx,
            fy,
            fz,
            kappa: inp.kappa,
            alpha: inp.alpha,
            gamma: inp.gamma,
            vx: inp.vx,
            mux,
            muy,
            kya: ky,
            kxk: kx,
            re: p.unloaded_radius,
            ..Default::default()
        }
    }

    /// Forces and moments only: the hot path. Allocation-free.
    pub fn forces(&self, inp: &MfInput, mode: UseMode) -> Forces {
        let o = self.evaluate(inp, mode);
        Forces {
            fx: o.fx,
            fy: o.fy,
            mx: o.mx,
            my: o.my,
            mz: o.mz,
        }
    }

    /// Batch evaluation over slices (`out.len()` must equal `inp.len()`).
    pub fn evaluate_batch(&self, inp: &[MfInput], mode: UseMode, out: &mut [MfOutput]) {
        for (i, o) in inp.iter().zip(out.iter_mut()) {
            *o = self.evaluate(i, mode);
        }
    }
}
