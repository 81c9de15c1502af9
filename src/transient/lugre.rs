//! lugre — the average lumped LuGre tyre friction model (Canudas de Wit,
//! Tsiotras, Velenis, Basset & Gissinger, "Dynamic friction models for road/tire
//! longitudinal interaction", Vehicle System Dynamics 39(3), 2003; Tsiotras,
//! Velenis & Sorine 2004 for the combined-slip form), fed by the Magic Formula.
//!
//! Per direction i ∈ {x, y}, with the relative (sliding) velocity vr
//! (vr_x = −Vsx = κ·|Vx|, vr_y = −Vsy, so that forces have the sign of vr):
//!
//! ```text
//!   dz_i/dt = vr_i − θ_i·z_i
//!   F_i     = Fz·(σ0_i·z_i + σ1_i·dz_i/dt + σ2·vr_i)
//! ```
//! with the bristle "rate" θ_i = σ0_i·|vr|/g + κ_L·|Ω·Re| (the average lumped
//! form: the second term is the distributed bristle transport, Canudas de Wit
//! et al. 2003 eq. 11 with κ_L constant).
//!
//! Friction function g:
//! * [`LuGreFriction::MagicFormula`] (default): g is derived from the Magic
//!   Formula curve of the same tyre, per direction, so that the steady state
//!   (ż = 0: F_i = Fz·σ0_i·vr_i/θ_i) equals the MF force at the same
//!   (combined) slips. The part of the MF force that no sliding in direction
//!   i generates is carried directly: F_x,0 = Fx,MF(0, α) and
//!   F_y,0 = Fy,MF(κ, 0) (the shifts SH/SV and camber thrust at zero slip,
//!   plus the combined-slip cross terms, e.g. SVyκ: a braked tyre running
//!   straight has a lateral force with no lateral sliding). The bristles carry
//!   ΔF_i = F_i,MF(κ, α) − F_i,0, which is zero at zero own slip and has the
//!   sign of vr_i for a monotone curve:
//!   θ_i = Fz·σ0_i·|vr_i|/(|ΔF_i|·S(‖vr‖)), where the Stribeck factor
//!   S = 1 + (μs/μc − 1)·exp(−(‖vr‖/vs)^δ) is 1 by default. Steady state:
//!   F_i = F_i,0 + ΔF_i = F_i,MF exactly. Combined-slip coupling is that of the
//!   MF (its combined-slip weights). Below VXLOW, where the MF evaluation runs
//!   at a raised speed, ΔF is taken against that evaluation's own zero-slip
//!   force, while F_i,0 keeps the MF's low-speed reduction of its shifts, and
//!   the cross terms fade out with the low-speed weight (1 − w) (at standstill
//!   the kinematic slips are meaningless: a creeping wheel must not get SVyκ).
//!   Cost: up to two extra forces evaluations per step (Fx(0, α), Fy(κ, 0)).
//! * [`LuGreFriction::Stribeck`]: the classical isotropic Stribeck curve
//!   g(‖vr‖) = μc + (μs − μc)·exp(−(‖vr‖/vs)^δ) with θ_i = σ0_i‖vr‖/g + κ_L|ΩRe|.
//!
//! Defaults: σ0_i = C_i/Fz (bristle stiffness = carcass stiffness, so at small
//! slip LuGre behaves as the relaxation model with σ = K/C), σ1_i = c_i/Fz
//! (the low-speed damping of the relaxation model), σ2 = 0, κ_L = 0.
//!
//! Low speed (below VXLOW, blended with the same weight w as the relaxation
//! damping): the elasto-plastic form of Dupont, Hayward, Armstrong & Altpeter
//! ("Single state elastoplastic friction models", IEEE TAC 47(5), 2002)
//! multiplies the bristle-rate term by a(z) = 1 − w·(1 − α(z)), α = 0 while
//! |z| < β·z_ss or while the bristle unloads (sgn z ≠ sgn vr), rising smoothly
//! to 1 at z_ss. Without it LuGre drifts under an oscillating load (a parked
//! car rocking on its tyres creeps downhill); with it, presliding is purely
//! elastic. In steady state |z| = z_ss, α = 1, so the steady forces are unchanged.
//!
//! From VXLOW up θ depends only on the inputs, so over a step with held inputs
//! the bristle equations are linear with constant coefficients and are solved
//! exactly. Below VXLOW a(z) is frozen over sub-steps short enough that z
//! moves by at most 5 % of z_ss per sub-step (at most 32, deterministic).
//!
//! Parameters may come from a `[LUGRE]` section of the `.tir`
//! ([`LuGreParams::from_tyre_params`] / [`LuGreParams::write_to`] through the
//! `.tir` custom-section API; `from_tir_text`/`to_tir_section` for raw text); keys
//! (SI): `SIGMA0X`, `SIGMA0Y` (1/m), `SIGMA1X`, `SIGMA1Y` (s/m), `SIGMA2` (s/m),
//! `MUC`, `MUS` (–), `VS` (m/s), `DELTA` (–, Stribeck exponent), `KAPPA_L`
//! (1/m), `BREAKAWAY` (–). A zero SIGMA* means "derive the default". `MUC` > 0 selects the
//! Stribeck friction function; otherwise `MUS` is the ratio μs/μc applied to
//! the Magic Formula curve.
//!
//! Must never: allocate in `step`, divide by a speed or a force without a guard.

use super::{relax_exact, Slip, StepCtx, TransientState, WheelOutput, SLOT_X, SLOT_Y};

/// Which friction function the bristles saturate at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LuGreFriction {
    /// Derived from the Magic Formula of the same tyre (steady state = MF).
    #[default]
    MagicFormula,
    /// The classical Stribeck curve from `mu_c`, `mu_s`, `vs`, `delta`.
    Stribeck,
}

/// LuGre parameters. Zero σ's mean "derive from the tyre" (see module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuGreParams {
    /// Friction function g the bristles saturate at (MF-derived or Stribeck).
    pub friction: LuGreFriction,
    /// Longitudinal bristle stiffness σ0x per unit normal load (1/m): the
    /// LuGre σ0 (Canudas de Wit et al. 1995) divided by Fz; 0 = Cx/Fz.
    pub sigma0x: f64,
    /// Lateral bristle stiffness σ0y per unit normal load (1/m); 0 = Cy/Fz.
    pub sigma0y: f64,
    /// Longitudinal bristle damping σ1x per unit normal load (s/m); 0 = the
    /// relaxation model's low-speed damping cx/Fz.
    pub sigma1x: f64,
    /// Lateral bristle damping σ1y per unit normal load (s/m); 0 = cy/Fz.
    pub sigma1y: f64,
    /// Viscous friction per unit normal load (s/m).
    pub sigma2: f64,
    /// Coulomb friction coefficient (Stribeck curve).
    pub mu_c: f64,
    /// Static friction coefficient (Stribeck curve); with the MF curve, the
    /// ratio μs/μc of the Stribeck factor (1 = none).
    pub mu_s: f64,
    /// Stribeck velocity (m/s).
    pub vs: f64,
    /// Stribeck exponent (–).
    pub delta: f64,
    /// Average-lumped distributed-bristle coefficient κ_L (1/m).
    pub kappa_l: f64,
    /// Breakaway ratio β = z_ba/z_ss of the elasto-plastic low-speed form (–, 0..1).
    pub breakaway: f64,
}

impl Default for LuGreParams {
    /// MF-derived friction, derived stiffness and damping, no Stribeck peak;
    /// vs = 3.5 m/s and δ = 1 are typical dry-asphalt values (Canudas de Wit et al. 2003).
    fn default() -> Self {
        LuGreParams {
            friction: LuGreFriction::MagicFormula,
            sigma0x: 0.0,
            sigma0y: 0.0,
            sigma1x: 0.0,
            sigma1y: 0.0,
            sigma2: 0.0,
            mu_c: 0.0,
            mu_s: 1.0,
            vs: 3.5,
            delta: 1.0,
            kappa_l: 0.0,
            breakaway: 0.5,
        }
    }
}

/// Name of the `.tir` section holding the LuGre parameters.
pub const SECTION: &str = "LUGRE";

/// Names of the `[LUGRE]` keys, in writer order.
pub const LUGRE_KEYS: [&str; 11] = [
    "SIGMA0X",
    "SIGMA0Y",
    "SIGMA1X",
    "SIGMA1Y",
    "SIGMA2",
    "MUC",
    "MUS",
    "VS",
    "DELTA",
    "KAPPA_L",
    "BREAKAWAY",
];

impl LuGreParams {
    /// From a key lookup (for the `.tir` reader's custom-section API): `get(KEY)`
    /// returns the SI value of a `[LUGRE]` key if the file has it. Values are
    /// checked (finite, non-negative; VS, DELTA > 0).
    pub fn from_lookup(get: impl Fn(&str) -> Option<f64>) -> crate::Result<Self> {
        let mut p = LuGreParams::default();
        for key in LUGRE_KEYS {
            let Some(x) = get(key) else { continue };
            let positive = matches!(key, "VS" | "DELTA");
            if !x.is_finite() || x < 0.0 || (positive && x == 0.0) {
                return Err(crate::Error::Tir {
                    file: String::new(),
                    line: 0,
                    key: key.to_string(),
                    message: format!(
                        "[LUGRE] {key} = {x}: expected a finite number {}",
                        if positive { "> 0" } else { ">= 0" }
                    ),
                });
            }
            match key {
                "SIGMA0X" => p.sigma0x = x,
                "SIGMA0Y" => p.sigma0y = x,
                "SIGMA1X" => p.sigma1x = x,
                "SIGMA1Y" => p.sigma1y = x,
                "SIGMA2" => p.sigma2 = x,
                "MUC" => p.mu_c = x,
                "MUS" => p.mu_s = x,
                "VS" => p.vs = x,
                "DELTA" => p.delta = x,
                "KAPPA_L" => p.kappa_l = x,
                _ => p.breakaway = x.min(0.99),
            }
        }
        if p.mu_c > 0.0 {
            p.friction = LuGreFriction::Stribeck;
            if get("MUS").is_none() {
                p.mu_s = p.mu_c;
            }
        }
        Ok(p)
    }

    /// Read the `[LUGRE]` section of `.tir` text (SI values, `$` comments);
    /// defaults when the section is absent. Stop-gap until the `.tir` reader
    /// exposes custom sections; errors name the file and line.
    pub fn from_tir_text(text: &str, name: &str) -> crate::Result<Self> {
        let mut vals = [None::<(f64, usize)>; LUGRE_KEYS.len()];
        let mut inside = false;
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split(['$', '!']).next().unwrap_or("").trim();
            if line.starts_with('[') {
                inside = line.eq_ignore_ascii_case("[LUGRE]");
                continue;
            }
            if !inside {
                continue;
            }
            let Some((k, v)) = line.split_once('=') else {
                continue;
            };
            let k = k.trim().to_ascii_uppercase();
            let Some(idx) = LUGRE_KEYS.iter().position(|n| *n == k) else {
                continue;
            };
            let x: f64 = v.trim().parse().map_err(|_| crate::Error::Tir {
                file: name.to_string(),
                line: i + 1,
                key: k.clone(),
                message: format!("expected a number, found '{}'", v.trim()),
            })?;
            vals[idx] = Some((x, i + 1));
        }
        let lookup = |key: &str| {
            LUGRE_KEYS
                .iter()
                .position(|n| *n == key)
                .and_then(|i| vals[i].map(|v| v.0))
        };
        LuGreParams::from_lookup(lookup).map_err(|e| match e {
            crate::Error::Tir { key, message, .. } => {
                let line = LUGRE_KEYS
                    .iter()
                    .position(|n| *n == key)
                    .and_then(|i| vals[i].map(|v| v.1))
                    .unwrap_or(0);
                crate::Error::Tir {
                    file: name.to_string(),
                    line,
                    key,
                    message,
                }
            }
            other => other,
        })
    }

    /// From the `[LUGRE]` section of a read tyre file (the `.tir` custom-section
    /// API, [`crate::tir::TyreParams::extra_number`]); defaults when absent. A
    /// key that is present but not a number is refused, naming the file and key.
    pub fn from_tyre_params(t: &crate::tir::TyreParams) -> crate::Result<Self> {
        for key in LUGRE_KEYS {
            if t.extra(SECTION, key).is_some() && t.extra_number(SECTION, key).is_none() {
                return Err(crate::Error::Tir {
                    file: t.source.clone(),
                    line: 0,
                    key: key.to_string(),
                    message: format!("[LUGRE] {key}: expected a number"),
                });
            }
        }
        LuGreParams::from_lookup(|k| t.extra_number(SECTION, k)).map_err(|e| match e {
            crate::Error::Tir {
                line, key, message, ..
            } => crate::Error::Tir {
                file: t.source.clone(),
                line,
                key,
                message,
            },
            other => other,
        })
    }

    /// Store these parameters as the `[LUGRE]` section of `t` (the `.tir`
    /// writer then writes it; [`LuGreParams::from_tyre_params`] reads it back).
    pub fn write_to(&self, t: &mut crate::tir::TyreParams) {
        let sec = t.extra_section(SECTION);
        for (k, v) in LUGRE_KEYS.iter().zip(self.values()) {
            sec.set(k, v);
        }
    }

    /// Values in [`LUGRE_KEYS`] order (MUC = 0 unless Stribeck).
    fn values(&self) -> [f64; 11] {
        [
            self.sigma0x,
            self.sigma0y,
            self.sigma1x,
            self.sigma1y,
            self.sigma2,
            if self.friction == LuGreFriction::Stribeck {
                self.mu_c
            } else {
                0.0
            },
            self.mu_s,
            self.vs,
            self.delta,
            self.kappa_l,
            self.breakaway,
        ]
    }

    /// The `[LUGRE]` section as `.tir` text (for the writer).
    pub fn to_tir_section(&self) -> String {
        let vals = self.values();
        let mut s = String::from("[LUGRE]\n");
        for (k, v) in LUGRE_KEYS.iter().zip(vals) {
            s.push_str(&format!("{k} = {v:e}\n"));
        }
        s
    }
}

/// Stribeck shape exp(−(v/vs)^δ) (0..1).
#[inline]
fn stribeck_shape(v: f64, p: &LuGreParams) -> f64 {
    let r = v / p.vs;
    if p.delta == 1.0 {
        (-r).exp()
    } else {
        (-r.powf(p.delta)).exp()
    }
}

/// Elasto-plastic factor α(z) of Dupont et al. 2002: 0 below the breakaway
/// β·z_ss and while unloading, 1 at and above z_ss, a half sine in between.
#[inline]
fn elastoplastic(z: f64, zss: f64, vr: f64, beta: f64) -> f64 {
    let valid = zss.is_finite() && zss > 0.0;
    if !valid {
        // No steady bristle deflection to compare with (no sliding): plain LuGre.
        return 1.0;
    }
    if z * vr <= 0.0 {
        // Unloading (or at rest): elastic.
        return 0.0;
    }
    let r = z.abs() / zss;
    if r >= 1.0 {
        1.0
    } else if r <= beta {
        0.0
    } else {
        let x = (r - 0.5 * (1.0 + beta)) / (1.0 - beta);
        0.5 + 0.5 * (std::f64::consts::PI * x).sin()
    }
}

/// LuGre forces never exceed this multiple of the friction limit
/// max(μ_i·Fz, |F_i,MF|) per direction (see `step`); μ_i is the Stribeck
/// peak max(μs, μc) with the own Stribeck curve, else the MF's μ_i·max(1, μs).
pub const LUGRE_FRICTION_MARGIN: f64 = 1.05;

/// One LuGre step (see the module docs); updates slots 0, 1 of `st`.
/// |F_i| ≤ [`LUGRE_FRICTION_MARGIN`]·max(μ_i·Fz, |F_i,MF|) in any slip history.
pub(crate) fn step(c: &StepCtx, p: &LuGreParams, st: &mut TransientState, dt: f64) -> WheelOutput {
    let fz = c.fz;
    let vrx = -c.kin.vsx;
    let vry = -c.kin.vsy;
    let vr = (vrx * vrx + vry * vry).sqrt();
    let pos = |x: f64, fb: f64| if x > 0.0 { x } else { fb };
    let s0x = pos(p.sigma0x, c.props.cx / fz);
    let s0y = pos(p.sigma0y, c.props.cy / fz);
    let s1x = pos(p.sigma1x, c.props.damp_x_full / fz);
    let s1y = pos(p.sigma1y, c.props.damp_y_full / fz);
    let transport = p.kappa_l * c.omega_re.abs();
    // Steady MF at the kinematic slips (also the moments and μ outputs).
    let o = c.forces(&c.base, Slip::of(&c.kin));
    // Force not generated by sliding in its own direction (MF mode only):
    // carried directly, not by the bristles.
    // ΔF is taken against the zero-slip force of the same (raised-speed)
    // evaluation, so it is zero at zero slip at every speed.
    // The direct part of each direction is the MF force with that direction's
    // own slip removed: Fx(0, α) and Fy(κ, 0) (at zero slip the shifts and
    // camber thrust; with the other slip also the combined-slip cross terms,
    // e.g. SVyκ, the lateral force of a braked tyre running straight, which no
    // lateral sliding could generate). Below VXLOW the cross terms fade out
    // with the low-speed weight (the kinematic slips lose their meaning there).
    let (f0x, f0y, b0x, b0y) = match p.friction {
        LuGreFriction::MagicFormula => {
            let (cx, cy) = c.offset_correction();
            let (zx, zy) = (c.s * c.props.fx0 - cx, c.s * c.props.fy0 - cy);
            let k = &c.kin;
            let fx_a = if k.tan_alpha == 0.0 {
                zx
            } else {
                c.forces_xy(&c.base, Slip::new(0.0, k.tan_alpha)).0
            };
            let fy_k = if k.kappa == 0.0 {
                zy
            } else {
                c.forces_xy(&c.base, Slip::new(k.kappa, 0.0)).1
            };
            let keep = 1.0 - c.props.weight;
            let (b0x, b0y) = (zx + keep * (fx_a - zx), zy + keep * (fy_k - zy));
            (b0x + cx, b0y + cy, b0x, b0y)
        }
        LuGreFriction::Stribeck => (0.0, 0.0, 0.0, 0.0),
    };
    let (thx, thy) = match p.friction {
        LuGreFriction::MagicFormula => {
            let strib = if p.mu_s != 1.0 {
                1.0 + (p.mu_s - 1.0) * stribeck_shape(vr, p)
            } else {
                1.0
            };
            // θ = Fz·σ0·|vr_i| / (|ΔF_i|·S); ΔF floored at 1e-9·Fz (θ then
            // just very large: z follows vr/θ ≈ 0, i.e. no slip force, as the MF says).
            // At (numerically) zero own slip the ratio is 0/0: there θ takes
            // its limit Fz·σ0·|Vx|/(|c·K_i|·S), K_i the MF's slip stiffness
            // at zero slip (ΔF_i → c·K_i·slip), so that the bristles keep
            // relaxing over the rolled distance. (θ = 0 there froze z: a
            // sweep ending at exactly κ = 0 kept its last force for as long
            // as κ stayed exactly 0, while κ = 1e-9 relaxed it in
            // centimetres.) The pure-slip K_i is the limit's slope at zero
            // slip in the other direction too; under combined slip it
            // overestimates the slope a little (θ a little low), which only
            // changes how fast a deflection left at zero own slip decays.
            let vx = c.kin.vx_abs;
            let th = |s0: f64, v: f64, f: f64, k0: f64| {
                let k = (c.c * k0 * strib).abs();
                if v.abs() <= 1e-9 * vx && k.is_finite() && k > 0.0 {
                    fz * s0 * vx / k + transport
                } else {
                    fz * s0 * v.abs() / (f.abs() * strib).max(1e-9 * fz) + transport
                }
            };
            (
                th(s0x, vrx, o.fx - b0x, c.props.kxk),
                th(s0y, vry, o.fy - b0y, c.props.kya),
            )
        }
        LuGreFriction::Stribeck => {
            let g = (p.mu_c + (p.mu_s - p.mu_c) * stribeck_shape(vr, p)) * c.s;
            let g = g.max(1e-9);
            (s0x * vr / g + transport, s0y * vr / g + transport)
        }
    };
    // z_ss per direction (for the elasto-plastic factor): g_i/σ0_i.
    let (zssx, zssy) = (
        (vrx / (thx - transport)).abs(),
        (vry / (thy - transport)).abs(),
    );
    let w = c.props.weight;
    let (mut zx, mut zy) = (st.x[SLOT_X], st.x[SLOT_Y]);
    let (mut thx_e, mut thy_e) = (thx, thy);
    if w > 0.0 {
        let rate = |th: f64, z: f64, zss: f64, vr: f64| {
            let a = 1.0 - w * (1.0 - elastoplastic(z, zss, vr, p.breakaway));
            (th - transport) * a + transport
        };
        let lim = 0.05 * zssx.min(zssy).max(1e-9);
        let n = ((vr * dt / lim).ceil() as usize).clamp(1, 32);
        let h = dt / n as f64;
        for _ in 0..n {
            thx_e = rate(thx, zx, zssx, vrx);
            thy_e = rate(thy, zy, zssy, vry);
            zx = relax_exact(zx, thx_e, vrx, h);
            zy = relax_exact(zy, thy_e, vry, h);
        }
    } else {
        zx = relax_exact(zx, thx, vrx, dt);
        zy = relax_exact(zy, thy, vry, dt);
    }
    st.x[SLOT_X] = zx;
    st.x[SLOT_Y] = zy;
    let dzx = vrx - thx_e * zx;
    let dzy = vry - thy_e * zy;
    let fx = f0x + fz * (s0x * zx + s1x * dzx + p.sigma2 * vrx);
    let fy = f0y + fz * (s0y * zy + s1y * dzy + p.sigma2 * vry);
    // The friction limit (issue 16): the damping term σ1·ż is unbounded at a
    // slip reversal (ż ≈ vr while z has not followed), which gave |Fx| = 5·Fz
    // at 100 m/s with reversals every 0.5 ms. No bristle force exceeds what
    // friction can transmit, so each force is clamped to
    // LUGRE_FRICTION_MARGIN·max(μ_i·Fz, |F_i,MF|) (μ_i with the road scale;
    // F_i,MF the steady Magic Formula at the same slips, which the steady
    // state equals, so steady states are unchanged).
    let lim = |mu: f64, f_mf: f64| {
        let l = LUGRE_FRICTION_MARGIN * (c.s * mu * fz).abs().max(f_mf.abs());
        if l.is_finite() {
            l
        } else {
            f64::INFINITY
        }
    };
    // The friction coefficient the bristles can reach: the Stribeck curve's
    // peak with its own parameters, or the MF's μ raised by the static
    // factor μs where the MF mode applies one (both set the steady state).
    let (mux, muy) = match p.friction {
        LuGreFriction::Stribeck => {
            let m = p.mu_s.abs().max(p.mu_c.abs());
            (m, m)
        }
        LuGreFriction::MagicFormula => {
            let k = p.mu_s.abs().max(1.0);
            (k * c.props.mux, k * c.props.muy)
        }
    };
    let fx = fx.clamp(-lim(mux, o.fx), lim(mux, o.fx));
    let fy = fy.clamp(-lim(muy, o.fy), lim(muy, o.fy));
    // Aligning moment: the MF's, scaled by the ratio of dynamic to steady Fy
    // (the pneumatic trail of the steady state; bounded to stay sane when
    // the steady Fy is near zero).
    let mz = if o.fy.abs() > 1e-6 * fz {
        o.mz * (fy / o.fy).clamp(-2.0, 2.0)
    } else {
        0.0
    };
    WheelOutput {
        fx,
        fy,
        mx: o.mx,
        my: o.my,
        mz,
        kappa: c.dir * c.kin.kappa,
        alpha: c.kin.alpha,
        re: c.props.re,
        mux: c.s * c.props.mux,
        muy: c.s * c.props.muy,
        vsx: c.kin.vsx,
        vsy: c.kin.vsy,
        sigma_x: c.props.sigma_x,
        sigma_y: c.props.sigma_y,
        friction_scale: c.s,
        stiffness_scale: c.c,
    }
}
