//! mf — the steady-state Magic Formula (MF 6.1/6.2, MF 5.2, PAC2002): forces and
//! moments for pure and combined slip, plus the derived quantities (radii,
//! contact patch, trail, friction, stiffnesses, relaxation lengths).
//! ISO-W axes, SI units.
//!
//! Must never: allocate in [`Tyre::evaluate`] / [`Tyre::forces`], hold global
//! state, or return a finite number where the equations are undefined.
//!
//! Layout: `limits.rs` conditions the inputs (range limits, low speed, α*),
//! `equations.rs` holds the force/moment equations generic over the scalar
//! type (`real.rs`; dual numbers give the fitter exact derivatives),
//! `extras.rs` the radii, contact patch, stiffnesses and relaxation lengths.
//! The numbers reproduce MFeval 4.0 (see `tests/mfeval_reference.rs`).
//!
//! Exact parameter derivatives (for the fitter): seed the parameters of
//! interest as dual numbers and solve with the same conditioned inputs:
//!
//! ```
//! use tyrekit::mf::num_dual::{Dual64, DualNum};
//! use tyrekit::mf::{MfInput, Model, Tyre, UseMode};
//! let tyre = Tyre::builtin();
//! let k = tyrekit::tir::keys::key_index("PDY1").unwrap();
//! let p = tyre.params().p.map(|i, v| if i == k { Dual64::new(v, 1.0) } else { Dual64::from(v) });
//! let model = Model::new(p, tyre.model().form);
//! let x = MfInput { fz: 4000.0, alpha: 0.1, vx: 20.0, ..Default::default() };
//! let (cond, _) = tyre.conditions(&x, UseMode::default());
//! let s = model.solve(&cond);
//! let fy = tyre.forces(&x, UseMode::default()).fy; // same value, f64 fast path
//! assert!((s.fy.re - fy).abs() <= 1e-12 * fy.abs());
//! let dfy_dpdy1 = s.fy.eps; // ∂Fy/∂PDY1
//! assert!(dfy_dpdy1 < 0.0);
//! ```
//!
//! Road friction: [`Tyre::evaluate_mu`] / [`Tyre::forces_mu`] (and
//! [`Model::solve_mu`]) take a road friction scale `mu_scale` that multiplies
//! LMUX and LMUY wherever they enter the equations — μx, μy, the vertical
//! shifts, Bt and Br (through 1/λμy) and Dr — the way MF-Tyre treats a road
//! friction change. The slip stiffnesses Kxκ (4.E15) and Kyα (4.E25) contain
//! no λμ, so the small-slip response is unchanged while the peaks scale.
//! `mu_scale = 1` is bit-identical to the plain calls. Nothing allocates.
//!
//! Zero-slip properties: [`Tyre::slip_properties`] returns Re, Cx, Cy, Kxκ,
//! Kyα, σx, σy, μx, μy of an evaluation at κ = α = 0 (bit-identical to
//! [`Tyre::evaluate`]'s) without the combined-slip and moment equations, for
//! the transient models' per-step needs.
//!
//! Deliberate differences from MFeval 4.0 (the reference test handles each):
//! the loaded radius of MF 6.2/5.2 files is the exact root of Fz62(Rl) = Fz,
//! not a Nelder–Mead estimate (Rω at Fz = 0); with turn slip at φt = 0, ζ7 takes
//! its limit instead of MFeval's 0/0 = NaN; an ω input of NaN means "estimate".

pub mod equations;
pub mod extras;
pub mod limits;
pub mod real;
pub mod validate;

pub use equations::{Form, LoadTerms, Model, PureTerms, Solution};
pub use limits::{Clamped, Conditions};
pub use real::Real;

/// The dual-number crate the equations are instantiated with, re-exported so
/// users seed derivatives with exactly the types [`Real`] is implemented for.
pub use num_dual;

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
    /// Longitudinal force Fx (N), positive driving the wheel forward
    /// (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., eq. 4.E50).
    pub fx: f64,
    /// Lateral force Fy (N), ISO-W +y (eq. 4.E58).
    pub fy: f64,
    /// Overturning moment Mx (N·m) about ISO-W +x (MF 6.1 form of eq. 4.E69).
    pub mx: f64,
    /// Rolling resistance moment My (N·m) about ISO-W +y, negative when
    /// rolling forward (MF 6.x paper eq. A48; eq. 4.E70 for MF 5.2).
    pub my: f64,
    /// Aligning moment Mz (N·m) about ISO-W +z (eq. 4.E71).
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
pub struct MfOutput {
    /// Longitudinal force Fx (N, ISO-W: positive driving).
    pub fx: f64,
    /// Lateral force Fy (N, ISO-W).
    pub fy: f64,
    /// Vertical load Fz (N, positive in compression).
    pub fz: f64,
    /// Overturning moment Mx (N·m, ISO-W).
    pub mx: f64,
    /// Rolling resistance moment My (N·m, ISO-W).
    pub my: f64,
    /// Self-aligning moment Mz (N·m, ISO-W).
    pub mz: f64,
    /// Longitudinal slip κ used by the equations (–, after the use mode's limits).
    pub kappa: f64,
    /// Slip angle α used by the equations (rad, ISO-W).
    pub alpha: f64,
    /// Inclination γ used by the equations (rad).
    pub gamma: f64,
    /// Turn slip φt (1/m).
    pub phit: f64,
    /// Longitudinal speed of the wheel centre Vcx (m/s).
    pub vx: f64,
    /// Inflation pressure (Pa).
    pub p: f64,
    /// Effective rolling radius Re (m).
    pub re: f64,
    /// Vertical deflection ρ (m).
    pub rho: f64,
    /// Contact patch length 2a (m).
    pub a2: f64,
    /// Pneumatic trail t (m).
    pub t: f64,
    /// Longitudinal friction coefficient μx (–; Pacejka eq. 4.E13).
    pub mux: f64,
    /// Lateral friction coefficient μy (–, as computed; Pacejka eq. 4.E23).
    pub muy: f64,
    /// Wheel spin rate Ω (rad/s).
    pub omega: f64,
    /// Loaded radius Rl (m).
    pub rl: f64,
    /// Contact patch width 2b (m).
    pub b2: f64,
    /// Residual aligning moment Mzr (N·m), the part of Mz not from the trail (Pacejka eq. 4.E75 for combined slip).
    pub mzr: f64,
    /// Longitudinal carcass stiffness Cx (N/m).
    pub cx: f64,
    /// Lateral carcass stiffness Cy (N/m).
    pub cy: f64,
    /// Vertical stiffness Cz (N/m).
    pub cz: f64,
    /// Cornering stiffness Kyα at the current load (N/rad; Pacejka eq. 4.E25).
    pub kya: f64,
    /// Longitudinal relaxation length σκ = Kxκ/Cx (m).
    pub sigmax: f64,
    /// Lateral relaxation length σα = Kyα/Cy (m).
    pub sigmay: f64,
    /// Instantaneous cornering stiffness ∂Fy/∂α at the operating point (N/rad).
    pub inst_kya: f64,
    /// Longitudinal slip stiffness Kxκ (N per unit slip; Pacejka eq. 4.E15).
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

/// Zero-slip properties ([`Tyre::slip_properties`]): the same values, names
/// and units as the [`MfOutput`] fields of an evaluation at κ = α = 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[allow(missing_docs)]
pub struct SlipProps {
    pub re: f64,
    pub cx: f64,
    pub cy: f64,
    pub kxk: f64,
    pub kya: f64,
    pub sigmax: f64,
    pub sigmay: f64,
    pub mux: f64,
    pub muy: f64,
    /// Forces and rolling resistance moment at zero slip (N, N·m).
    pub fx: f64,
    pub fy: f64,
    pub my: f64,
    /// Inclination angle as used (after the limit checks) (rad).
    pub gamma: f64,
}

/// A tyre ready to evaluate: the property file plus whatever can be
/// precomputed from it. Immutable and `Send + Sync`: share it between threads.
#[derive(Clone, Debug)]
pub struct Tyre {
    params: TyreParams,
    model: Model<f64>,
    /// Physics beyond the MF read from the file (see `transient::extension`).
    ext: Option<crate::transient::extension::Extension>,
}

/// The equation family for a file version.
pub fn form_of(version: MfVersion) -> Form {
    match version {
        MfVersion::Mf61 | MfVersion::Mf62 => Form::Mf6,
        MfVersion::Mf52 => Form::Mf52,
        MfVersion::Pac2002 => Form::Pac2002,
    }
}

impl Tyre {
    /// Prepare a tyre from loaded parameters.
    pub fn new(params: TyreParams) -> crate::Result<Tyre> {
        let p = &params.p;
        for (name, v) in [
            ("FNOMIN", p.fnomin),
            ("UNLOADED_RADIUS", p.unloaded_radius),
            ("NOMPRES", p.nompres),
            ("LONGVL", p.longvl),
        ] {
            if !v.is_finite() {
                return Err(crate::Error::Other(format!(
                    "{}: {name} = {v} is not a finite number",
                    params.source
                )));
            }
        }
        let model = Model::new(params.p.clone(), form_of(params.version));
        let ext = crate::transient::extension::Extension::from_params(&params)?;
        Ok(Tyre { params, model, ext })
    }
    /// Load a `.tir` file, prepare and [`validate`] it: refused with the
    /// reason when the model cannot be evaluated at nominal conditions; the
    /// validation's doubts are appended to [`TyreParams::warnings`] (after the
    /// reader's), which every command prints.
    pub fn from_file(path: &std::path::Path) -> crate::Result<Tyre> {
        Tyre::checked(TyreParams::from_file(path)?)
    }
    /// [`Tyre::new`] plus the one validation every entry point applies
    /// ([`validate::check`]): the fit's output, the CLI and the FMU use this.
    pub fn checked(params: TyreParams) -> crate::Result<Tyre> {
        let mut t = Tyre::new(params)?;
        match validate::check(&t) {
            Ok(w) => {
                t.params.warnings.extend(w);
                Ok(t)
            }
            Err(why) => Err(crate::Error::Other(format!(
                "{}: tyre refused: {why}",
                t.params.source
            ))),
        }
    }
    /// The warnings of loading this tyre: the reader's, then the validation's.
    pub fn warnings(&self) -> &[String] {
        &self.params.warnings
    }
    /// The built-in default tyre.
    pub fn builtin() -> Tyre {
        let params = TyreParams::builtin();
        let model = Model::new(params.p.clone(), form_of(params.version));
        Tyre {
            params,
            model,
            ext: None,
        }
    }
    /// The parameters this tyre was built from.
    pub fn params(&self) -> &TyreParams {
        &self.params
    }
    /// The extension physics of the file (`[THERMAL]`, `[LOAD_SENSITIVITY]`,
    /// LMUV), applied by the transient step; None for a plain MF file.
    pub fn extension(&self) -> Option<&crate::transient::extension::Extension> {
        self.ext.as_ref()
    }
    /// Equation set in use.
    pub fn version(&self) -> MfVersion {
        self.params.version
    }
    /// The prepared equations (`f64`). For derivatives, build a
    /// `Model<Dual…>` from `params().p.map(…)` and call [`Model::solve`] with
    /// the same [`Conditions`] (see [`Tyre::conditions`]).
    pub fn model(&self) -> &Model<f64> {
        &self.model
    }

    /// Conditioned inputs for one evaluation (with ω estimated when turn slip
    /// needs it and none is given), and what the limits clamped.
    pub fn conditions(&self, inp: &MfInput, mode: UseMode) -> (Conditions, Clamped) {
        let (mut c, cl) = Conditions::new(&self.params.p, inp, mode);
        if mode.turn_slip && !(inp.omega != 0.0 && inp.omega.is_finite()) {
            c.omega = extras::effective_radius(&self.params.p, &c, 0.0).2;
        }
        (c, cl)
    }

    /// Full evaluation (all 30 outputs). Allocation-free. `inst_kya` is 0 for
    /// a single evaluation (it is a finite difference along a batch, see
    /// [`Tyre::evaluate_batch`]).
    pub fn evaluate(&self, inp: &MfInput, mode: UseMode) -> MfOutput {
        self.evaluate_checked(inp, mode).0
    }

    /// [`Tyre::evaluate`] on a road of friction `mu_scale` times the one the
    /// file describes (see [`Model::solve_mu`]: LMUX, LMUY × `mu_scale` in
    /// every equation, as MF-Tyre treats a road friction change; the slip
    /// stiffnesses Kxκ, Kyα are unchanged). `mu_scale = 1` is bit-identical
    /// to [`Tyre::evaluate`]. Allocation-free.
    pub fn evaluate_mu(&self, inp: &MfInput, mode: UseMode, mu_scale: f64) -> MfOutput {
        self.evaluate_checked_mu(inp, mode, mu_scale).0
    }

    /// [`Tyre::evaluate`] plus the report of which limits acted.
    pub fn evaluate_checked(&self, inp: &MfInput, mode: UseMode) -> (MfOutput, Clamped) {
        self.evaluate_checked_mu(inp, mode, 1.0)
    }

    /// Conditions with ω filled in as [`Tyre::evaluate`] uses it (given, or
    /// estimated from the Re iteration), and Re, Rω, ω from it.
    fn conditions_radius(&self, inp: &MfInput, mode: UseMode) -> (Conditions, Clamped, [f64; 3]) {
        let p = &self.params.p;
        let (mut c, cl) = Conditions::new(p, inp, mode);
        let given = if inp.omega.is_nan() { 0.0 } else { inp.omega };
        let omega_used = if given != 0.0 {
            given
        } else {
            extras::effective_radius(p, &c, 0.0).2
        };
        c.omega = omega_used;
        let (re, romega, omega) = extras::effective_radius(p, &c, omega_used);
        (c, cl, [re, romega, omega])
    }

    /// [`Tyre::evaluate_checked`] with a road friction scale (see
    /// [`Tyre::evaluate_mu`]).
    pub fn evaluate_checked_mu(
        &self,
        inp: &MfInput,
        mode: UseMode,
        mu_scale: f64,
    ) -> (MfOutput, Clamped) {
        let (out, cl, _) = self.evaluate_full(inp, mode, mu_scale);
        (out, cl)
    }

    /// [`Tyre::evaluate_checked_mu`] plus the conditioned α (for the batch's
    /// finite difference, so that the conditions are computed once per row).
    #[inline]
    fn evaluate_full(
        &self,
        inp: &MfInput,
        mode: UseMode,
        mu_scale: f64,
    ) -> (MfOutput, Clamped, f64) {
        let p = &self.params.p;
        let (c, cl, [re, romega, omega]) = self.conditions_radius(inp, mode);
        let s = self.model.solve_mu(&c, mu_scale);
        let is52 = self.model.form != Form::Mf6;
        let is61 = self.params.version == MfVersion::Mf61;
        let (rl, rho, cz) = extras::loaded_radius(p, is61, &c, omega, romega, s.fx, s.fy);
        let (a, b) = extras::contact_patch(p, is52, &c);
        let (cx, cy, sigmax, sigmay) = extras::relaxation(p, is52, &c, s.kxk, s.kya);
        let muy = if mode.limits { s.muy.abs() } else { s.muy };
        let out = MfOutput {
            fx: s.fx,
            fy: s.fy,
            fz: c.fz_u,
            mx: s.mx,
            my: s.my,
            mz: s.mz,
            kappa: c.kappa_low,
            alpha: c.alpha_out,
            gamma: c.gamma_u,
            phit: c.phit,
            vx: c.vx,
            p: c.p,
            re,
            rho,
            a2: 2.0 * a,
            t: s.t,
            mux: s.mux,
            muy,
            omega,
            rl,
            b2: 2.0 * b,
            mzr: s.mzr,
            cx,
            cy,
            cz,
            kya: s.kya,
            sigmax,
            sigmay,
            inst_kya: 0.0,
            kxk: s.kxk,
        };
        (out, Clamped(cl.0 | s.flags), c.alpha)
    }

    /// Forces and moments only: the hot path. Allocation-free.
    #[inline]
    pub fn forces(&self, inp: &MfInput, mode: UseMode) -> Forces {
        self.forces_mu(inp, mode, 1.0)
    }

    /// [`Tyre::forces`] on a road of friction `mu_scale` times the file's
    /// (see [`Tyre::evaluate_mu`]); `mu_scale = 1` is bit-identical.
    #[inline]
    pub fn forces_mu(&self, inp: &MfInput, mode: UseMode, mu_scale: f64) -> Forces {
        self.forces_with(inp, mode, mu_scale, true, None)
    }

    /// [`Tyre::forces_mu`] with My only when `my` (NaN otherwise,
    /// [`Model::solve_with`]), reusing the slip-independent terms `pre` of
    /// this step's probe ([`Tyre::slip_properties_terms`], [`LoadTerms`];
    /// used only where they belong to the same Fz, p, γ); the other fields
    /// bit-identical either way. Allocation-free.
    #[inline]
    pub fn forces_with(
        &self,
        inp: &MfInput,
        mode: UseMode,
        mu_scale: f64,
        my: bool,
        pre: Option<&LoadTerms<f64>>,
    ) -> Forces {
        let (c, _) = self.conditions(inp, mode);
        let s = self.model.solve_with(&c, mu_scale, my, pre);
        Forces {
            fx: s.fx,
            fy: s.fy,
            mx: s.mx,
            my: s.my,
            mz: s.mz,
        }
    }

    /// The overturning moment Mx at the load, inclination and pressure of
    /// `inp` (its slips are not read) with the lateral force `fy` given:
    /// the equation [`Tyre::forces`] uses (Pacejka, *Tyre and Vehicle
    /// Dynamics*, 3rd ed., eq. 4.E69, with the MF 6.1 paper's camber and
    /// load terms), bit-identical to its `mx` for that evaluation's `fy`.
    /// The transient models' similarity method needs it on a road of
    /// another friction, where Fy scales and Mx's inclination and load
    /// terms do not ([`crate::transient::mf_at`]).
    #[inline]
    pub fn overturning_moment(&self, inp: &MfInput, mode: UseMode, fy: f64) -> f64 {
        let (c, _) = self.conditions(inp, mode);
        self.model.mx_with_fy(&c, fy)
    }

    /// Fx and Fy of [`Tyre::forces_mu`] only (bit-identical to its `fx`,
    /// `fy`), without the moment equations ([`Model::solve_fxfy`]); `pre`
    /// as in [`Tyre::forces_with`]. Allocation-free.
    #[inline]
    pub fn forces_xy(
        &self,
        inp: &MfInput,
        mode: UseMode,
        mu_scale: f64,
        pre: Option<&LoadTerms<f64>>,
    ) -> (f64, f64) {
        let (c, _) = self.conditions(inp, mode);
        self.model.solve_fxfy(&c, mu_scale, pre)
    }

    /// The zero-slip properties the transient models need each step,
    /// without the combined-slip weights and the Mx, Mz equations: the values
    /// [`Tyre::evaluate_mu`] gives for the same input with κ = α = 0
    /// (bit-identical; the other inputs as given, ω estimated the same way).
    pub fn slip_properties_mu(&self, inp: &MfInput, mode: UseMode, mu_scale: f64) -> SlipProps {
        self.slip_properties_terms(inp, mode, mu_scale, true, true)
            .0
    }

    /// [`Tyre::slip_properties_mu`] computing Fx, Fy (at zero slip) only with
    /// `forces` and My only with `my` (NaN otherwise), and the
    /// slip-independent terms it computed ([`LoadTerms`]) for the step's
    /// later evaluations ([`Tyre::forces_with`], [`Tyre::forces_xy`]); every
    /// other field, and those asked for, bit-identical to
    /// [`Tyre::slip_properties_mu`]. The transient step asks only for what
    /// its model uses (see `transient::TransientModel::step`): the skipped
    /// force equations are most of the probe's cost.
    pub fn slip_properties_terms(
        &self,
        inp: &MfInput,
        mode: UseMode,
        mu_scale: f64,
        forces: bool,
        my: bool,
    ) -> (SlipProps, LoadTerms<f64>) {
        let zero = MfInput {
            kappa: 0.0,
            alpha: 0.0,
            ..*inp
        };
        let (c, _, [re, _, _]) = self.conditions_radius(&zero, mode);
        let ([mux, muy, kxk, kya, fx, fy, my], terms) =
            self.model.zero_slip_terms(&c, mu_scale, forces, my);
        let is52 = self.model.form != Form::Mf6;
        let (cx, cy, sigmax, sigmay) = extras::relaxation(&self.params.p, is52, &c, kxk, kya);
        let props = SlipProps {
            re,
            cx,
            cy,
            kxk,
            kya,
            sigmax,
            sigmay,
            mux,
            muy: if mode.limits { muy.abs() } else { muy },
            fx,
            fy,
            my,
            gamma: c.gamma_u,
        };
        (props, terms)
    }

    /// Re of [`Tyre::slip_properties_mu`] alone (bit-identical: the same
    /// conditioning at κ = α = 0 and the same radius iteration), without the
    /// Magic Formula. For the steady transient step, which takes the other
    /// zero-slip properties from its force evaluation
    /// ([`Tyre::forces_and_props`]).
    pub fn zero_slip_radius(&self, inp: &MfInput, mode: UseMode) -> f64 {
        let zero = MfInput {
            kappa: 0.0,
            alpha: 0.0,
            ..*inp
        };
        self.conditions_radius(&zero, mode).2[0]
    }

    /// [`Tyre::forces_mu`] and, from the same evaluation, the slip-independent
    /// fields of [`Tyre::slip_properties_mu`] for the same input: μx, μy, Kxκ,
    /// Kyα, Cx, Cy, σx, σy and γ. Without turn slip these are bit-identical to
    /// the zero-slip probe's: none of them depends on κ or α (Pacejka 3rd ed.
    /// 4.E13, 4.E23, 4.E15, 4.E25 with ζ3 = 1; the carcass stiffnesses and
    /// relaxation lengths use only Fz, p, γ), and the conditioned Fz, p, γ are
    /// those of the probe — so one evaluation serves both. With turn slip Kyα
    /// carries ζ3(φ), which depends on α: use the probe then. `re`, `fx`,
    /// `fy`, `my` of the returned properties are NaN (not computed here).
    /// Allocation-free.
    pub fn forces_and_props(
        &self,
        inp: &MfInput,
        mode: UseMode,
        mu_scale: f64,
    ) -> (Forces, SlipProps) {
        let (c, _) = self.conditions(inp, mode);
        let s = self.model.solve_mu(&c, mu_scale);
        let is52 = self.model.form != Form::Mf6;
        let (cx, cy, sigmax, sigmay) = extras::relaxation(&self.params.p, is52, &c, s.kxk, s.kya);
        let forces = Forces {
            fx: s.fx,
            fy: s.fy,
            mx: s.mx,
            my: s.my,
            mz: s.mz,
        };
        let props = SlipProps {
            re: f64::NAN,
            cx,
            cy,
            kxk: s.kxk,
            kya: s.kya,
            sigmax,
            sigmay,
            mux: s.mux,
            muy: if mode.limits { s.muy.abs() } else { s.muy },
            fx: f64::NAN,
            fy: f64::NAN,
            my: f64::NAN,
            gamma: c.gamma_u,
        };
        (forces, props)
    }

    /// [`Tyre::slip_properties_mu`] with `mu_scale = 1`.
    pub fn slip_properties(&self, inp: &MfInput, mode: UseMode) -> SlipProps {
        self.slip_properties_mu(inp, mode, 1.0)
    }

    /// Batch evaluation over slices (`out.len()` must equal `inp.len()`;
    /// extra elements of either are ignored). `inst_kya` is MFeval's finite
    /// difference ΔFy/Δα between consecutive rows (with the conditioned α),
    /// the last row repeating the previous value; 0 for a single row.
    pub fn evaluate_batch(&self, inp: &[MfInput], mode: UseMode, out: &mut [MfOutput]) {
        let n = inp.len().min(out.len());
        let mut a0 = 0.0;
        for i in 0..n {
            let (o, _, a1) = self.evaluate_full(&inp[i], mode, 1.0);
            out[i] = o;
            if i > 0 {
                out[i - 1].inst_kya = (o.fy - out[i - 1].fy) / (a1 - a0);
            }
            a0 = a1;
        }
        if n > 1 {
            out[n - 1].inst_kya = out[n - 2].inst_kya;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The claim of [`Tyre::forces_and_props`]: without turn slip its
    /// properties are the zero-slip probe's, bit for bit, and its forces are
    /// [`Tyre::forces_mu`]'s — over slips, loads (below FZMIN, above FZMAX,
    /// 0), pressures, cambers, speeds (reversing, below VXLOW, 0), both
    /// limit modes and α*, for every equation family shipped in ../shared.
    #[test]
    fn forces_and_props_equal_the_probe_bitwise() {
        let mut tyres = vec![Tyre::builtin()];
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/tir");
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        files.sort();
        // Files the loader refuses (deliberately broken templates) are skipped.
        tyres.extend(files.iter().filter_map(|f| Tyre::from_file(f).ok()));
        let forms = |f: Form| tyres.iter().filter(|t| t.model().form == f).count();
        assert!(
            forms(Form::Mf6) >= 2 && forms(Form::Mf52) + forms(Form::Pac2002) >= 2,
            "expected MF 6.x and MF 5.2/PAC2002 files in {}",
            dir.display()
        );
        let bits = |x: f64| if x.is_nan() { u64::MAX } else { x.to_bits() };
        let mut n = 0;
        for tyre in &tyres {
            for code in [111, 121, 211, 221] {
                let mode = UseMode::from_code(code).unwrap();
                for fz in [0.0, 50.0, 1500.0, 4000.0, 9000.0, 40000.0] {
                    for (kappa, alpha) in [(0.0, 0.0), (0.05, -0.1), (-0.4, 0.3), (1.5, 1.2)] {
                        for vx in [-15.0, -0.3, 0.0, 0.5, 20.0] {
                            for (gamma, p) in [(0.0, 0.0), (0.05, 1.8e5), (-0.1, 2.6e5)] {
                                let inp = MfInput {
                                    fz,
                                    kappa,
                                    alpha,
                                    gamma,
                                    vx,
                                    p,
                                    omega: vx / 0.3,
                                    ..Default::default()
                                };
                                let (f, a) = tyre.forces_and_props(&inp, mode, 1.0);
                                let b = tyre.slip_properties_mu(&inp, mode, 1.0);
                                let g = tyre.forces_mu(&inp, mode, 1.0);
                                let pairs = [
                                    (a.mux, b.mux),
                                    (a.muy, b.muy),
                                    (a.kxk, b.kxk),
                                    (a.kya, b.kya),
                                    (a.cx, b.cx),
                                    (a.cy, b.cy),
                                    (a.sigmax, b.sigmax),
                                    (a.sigmay, b.sigmay),
                                    (a.gamma, b.gamma),
                                    (f.fx, g.fx),
                                    (f.fy, g.fy),
                                    (f.mx, g.mx),
                                    (f.my, g.my),
                                    (f.mz, g.mz),
                                ];
                                for (i, (x, y)) in pairs.into_iter().enumerate() {
                                    assert_eq!(
                                        bits(x),
                                        bits(y),
                                        "{} field {i}: {x} vs {y} at {inp:?} mode {code}",
                                        tyre.params().source
                                    );
                                }
                                assert_eq!(bits(tyre.zero_slip_radius(&inp, mode)), bits(b.re));
                                n += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(n >= 5 * 1440, "{n} cases");
    }

    /// [`LoadTerms`] change nothing but the cost: the evaluations that reuse
    /// the probe's terms give the same bits as those that compute them, and
    /// terms of another load, pressure, camber or friction scale are not
    /// used (the same bits again, not the other load's numbers). With turn
    /// slip too (the terms exclude ζ1, ζ3, which depend on the slip).
    #[test]
    fn load_terms_are_bit_neutral() {
        let tyre = Tyre::builtin();
        let bits = |x: f64| if x.is_nan() { u64::MAX } else { x.to_bits() };
        let mut used = 0;
        for code in [111, 112, 211, 221] {
            let mode = UseMode::from_code(code).unwrap();
            for (fz, gamma, p) in [(4000.0, 0.0, 0.0), (2500.0, 0.04, 1.9e5), (0.0, 0.0, 0.0)] {
                let base = MfInput {
                    fz,
                    gamma,
                    p,
                    vx: 12.0,
                    omega: 40.0,
                    phit: 0.01,
                    ..Default::default()
                };
                let (_, own) = tyre.slip_properties_terms(&base, mode, 1.0, true, true);
                let other = MfInput {
                    fz: fz + 700.0,
                    gamma: gamma + 0.01,
                    ..base
                };
                let (_, foreign) = tyre.slip_properties_terms(&other, mode, 1.0, true, true);
                for (kappa, alpha) in [(0.0, 0.0), (0.08, -0.05), (-0.5, 0.4)] {
                    let inp = MfInput {
                        kappa,
                        alpha,
                        ..base
                    };
                    let want = tyre.forces_with(&inp, mode, 1.0, false, None);
                    let want_xy = tyre.forces_xy(&inp, mode, 1.0, None);
                    for pre in [&own, &foreign] {
                        let got = tyre.forces_with(&inp, mode, 1.0, false, Some(pre));
                        for (a, b) in [
                            (got.fx, want.fx),
                            (got.fy, want.fy),
                            (got.mx, want.mx),
                            (got.my, want.my),
                            (got.mz, want.mz),
                        ] {
                            assert_eq!(bits(a), bits(b), "mode {code} {inp:?}");
                        }
                        let xy = tyre.forces_xy(&inp, mode, 1.0, Some(pre));
                        assert_eq!(bits(xy.0), bits(want_xy.0));
                        assert_eq!(bits(xy.1), bits(want_xy.1));
                        used += 1;
                    }
                    // Another friction scale: not the same terms.
                    let mu = tyre.forces_with(&inp, mode, 0.6, false, Some(&own));
                    assert_eq!(
                        bits(mu.fy),
                        bits(tyre.forces_with(&inp, mode, 0.6, false, None).fy)
                    );
                }
            }
        }
        assert_eq!(used, 72);
    }
}
