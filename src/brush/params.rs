//! params — the brush model's parameters: the `[BRUSH]` section of the `.tir`
//! and the defaults derived from the same file's Magic Formula.
//!
//! Keys (SI): `POINTS` (M, contact points, 1..=64), `CPY`, `CPX` (tread shear
//! stiffness per unit length per unit deflection, N/m²), `CARCASS_COMPLIANCE`
//! (h, m/N, the string's compliance to a concentrated lateral force; 0 =
//! rigid carcass), `SIGMA_C` (string relaxation length, m), `MUS`, `MUK`
//! (static and sliding friction at FNOMIN), `MU_DFZ` (relative change of μ
//! per unit dfz), `PRESSURE_N` (pressure shape exponent, 1 = parabola).
//! Geometry comes from the MF keys (one source of truth): UNLOADED_RADIUS,
//! VERTICAL_STIFFNESS, Q_RA1, Q_RA2, FNOMIN·LFZO.
//!
//! Defaults for absent keys, from the Magic Formula at FNOMIN, zero slip:
//! * MUS = MUK = μy of the MF (PDY1·LMUY), MU_DFZ = PDY2/PDY1;
//! * SIGMA_C = 2·σα,MF − a: the string alone (rigid tread) would have the
//!   cornering stiffness C_Fy·(σ_c + a) (Pacejka 3rd ed. §5.3, σα = σ_c + a);
//!   this makes it 2·|Kyα|, i.e. tread and carcass share the lateral
//!   deflection about equally at small slip — the paper's finding of
//!   "comparable amounts" taken as the prior (a fit or the file refines it);
//!   at least a/2, 0.8 m when the MF gives no σα. The brush's relaxation
//!   length C_y/C_Fy then equals the MF's σα = Kyα/Cy;
//! * CARCASS_COMPLIANCE such that the string's lateral stiffness to a load
//!   over the contact, (σ_c + a)/(σ_c·h), equals the MF's Cy (PCFY1 or
//!   LATERAL_STIFFNESS);
//! * CPY such that the brush's cornering stiffness at FNOMIN equals the MF's
//!   |Kyα| (bisection in log CPY; the model's C_y is increasing in CPY); when
//!   the carcass alone is too soft for that, the stiffest tread of the search
//!   (1e10 N/m²) and a warning in [`BrushParams::notes`];
//! * CPX = |Kxκ|/(2a²) (the brush's C_κ = 2·c_px·a², Pacejka eq. 3.13);
//! * POINTS = [`DEFAULT_POINTS`], PRESSURE_N = 1.
//!
//! Must never: accept a non-finite or out-of-range value silently (errors
//! name the key and the allowed range).

use super::carcass::StringCarcass;
use super::solver::{cornering_stiffness_on, Patch, M_MAX};
use crate::mf::{MfInput, Tyre, UseMode};

/// Name of the `.tir` section.
pub const SECTION: &str = "BRUSH";

/// The `[BRUSH]` keys, in writer order.
pub const BRUSH_KEYS: [&str; 9] = [
    "POINTS",
    "CPY",
    "CPX",
    "CARCASS_COMPLIANCE",
    "SIGMA_C",
    "MUS",
    "MUK",
    "MU_DFZ",
    "PRESSURE_N",
];

/// Default number of contact points (`tyrekit bench brush`, README: with the
/// string carcass an evaluation at M = 20 costs ≈ 4 µs, < 0.5 % of a 1 kHz
/// step's budget, and its Fy differs from M = 64's by ≤ 6e-4·Fz over
/// α = 0.5..10°; M = 40 costs ≈ 10× more for a 4× smaller difference).
pub const DEFAULT_POINTS: usize = 20;

/// The brush model's parameters (plain data, `Copy`: a transient model holds one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushParams {
    /// Number of contact points M (1..=[`M_MAX`]).
    pub points: usize,
    /// Lateral tread shear stiffness per unit length (N/m²).
    pub cpy: f64,
    /// Longitudinal tread shear stiffness per unit length (N/m²).
    pub cpx: f64,
    /// Carcass point compliance h (m/N); 0 = rigid.
    pub compliance: f64,
    /// String relaxation length σ_c (m).
    pub sigma_c: f64,
    /// Static friction coefficient at FNOMIN.
    pub mu_s: f64,
    /// Sliding friction coefficient at FNOMIN.
    pub mu_k: f64,
    /// Relative friction change per unit dfz.
    pub mu_dfz: f64,
    /// Pressure shape exponent n (q ∝ 1 − |x/a|^(2n)).
    pub pressure_n: f64,
    /// Nominal load Fz0 = FNOMIN·LFZO (N).
    pub fz0: f64,
    /// Unloaded radius (m).
    pub r0: f64,
    /// Vertical stiffness (N/m).
    pub cz: f64,
    /// Q_RA1 of the MF 6.x tyre file (dimensionless): the √(ρ/R0) coefficient of
    /// the contact half length a = R0·(Q_RA2·ρ/R0 + Q_RA1·√(ρ/R0)), ρ = Fz/Cz
    /// (see [`half_length`](super::half_length)).
    pub q_ra1: f64,
    /// Q_RA2 of the MF 6.x tyre file (dimensionless): the linear ρ/R0 coefficient
    /// of the same contact half length.
    pub q_ra2: f64,
}

impl Default for BrushParams {
    /// A 205/60R15-like tyre at 4 kN with a rigid carcass (for tests and
    /// examples; real use derives from a tyre file: [`BrushParams::from_tyre`]).
    fn default() -> Self {
        BrushParams {
            points: DEFAULT_POINTS,
            cpy: 8e6,
            cpx: 8e6,
            compliance: 0.0,
            sigma_c: 0.4,
            mu_s: 1.0,
            mu_k: 1.0,
            mu_dfz: 0.0,
            pressure_n: 1.0,
            fz0: 4000.0,
            r0: 0.313,
            cz: 2.1e5,
            q_ra1: 0.5,
            q_ra2: 1.0,
        }
    }
}

/// What [`BrushParams::from_tyre`] derived, for the user.
#[derive(Clone, Debug, Default)]
pub struct Derivation {
    /// Keys taken from the `[BRUSH]` section.
    pub given: Vec<&'static str>,
    /// Keys derived from the Magic Formula.
    pub derived: Vec<&'static str>,
    /// Warnings (e.g. an MF cornering stiffness the carcass cannot reach).
    pub notes: Vec<String>,
}

fn tir_err(file: &str, key: &str, message: String) -> crate::Error {
    crate::Error::Tir {
        file: file.to_string(),
        line: 0,
        key: key.to_string(),
        message,
    }
}

impl BrushParams {
    /// The string carcass of these parameters.
    pub fn carcass(&self) -> StringCarcass {
        StringCarcass {
            h: self.compliance,
            sigma_c: self.sigma_c,
        }
    }

    /// Check ranges; the error names the key and what is allowed.
    pub fn validate(&self, file: &str) -> crate::Result<()> {
        let pos = |k: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(tir_err(
                    file,
                    k,
                    format!("[BRUSH] {k} = {x}: expected a finite number > 0"),
                ))
            }
        };
        if !(1..=M_MAX).contains(&self.points) {
            return Err(tir_err(
                file,
                "POINTS",
                format!(
                    "[BRUSH] POINTS = {}: expected an integer 1..={M_MAX}",
                    self.points
                ),
            ));
        }
        pos("CPY", self.cpy)?;
        pos("CPX", self.cpx)?;
        pos("SIGMA_C", self.sigma_c)?;
        pos("MUS", self.mu_s)?;
        pos("MUK", self.mu_k)?;
        pos("PRESSURE_N", self.pressure_n)?;
        if !(self.compliance.is_finite() && self.compliance >= 0.0) {
            return Err(tir_err(
                file,
                "CARCASS_COMPLIANCE",
                format!(
                    "[BRUSH] CARCASS_COMPLIANCE = {}: expected a finite number >= 0 (0 = rigid carcass)",
                    self.compliance
                ),
            ));
        }
        if !self.mu_dfz.is_finite() {
            return Err(tir_err(
                file,
                "MU_DFZ",
                "[BRUSH] MU_DFZ: expected a finite number".into(),
            ));
        }
        if self.mu_s < self.mu_k {
            return Err(tir_err(
                file,
                "MUS",
                format!(
                    "[BRUSH] MUS = {} < MUK = {}: static friction must be at least the sliding friction",
                    self.mu_s, self.mu_k
                ),
            ));
        }
        for (k, x) in [
            ("fz0 (FNOMIN*LFZO)", self.fz0),
            ("UNLOADED_RADIUS", self.r0),
            ("VERTICAL_STIFFNESS", self.cz),
        ] {
            pos(k, x)?;
        }
        Ok(())
    }

    /// The parameters of a tyre: the `[BRUSH]` section where it gives a key,
    /// the Magic Formula defaults (module docs) for the rest.
    pub fn from_tyre(tyre: &Tyre) -> crate::Result<(BrushParams, Derivation)> {
        let t = tyre.params();
        let file = t.source.as_str();
        let mut given = [None::<f64>; BRUSH_KEYS.len()];
        for (i, key) in BRUSH_KEYS.iter().enumerate() {
            if t.extra(SECTION, key).is_some() {
                let x = t.extra_number(SECTION, key).ok_or_else(|| {
                    tir_err(file, key, format!("[BRUSH] {key}: expected a number"))
                })?;
                given[i] = Some(x);
            }
        }
        let get = |k: &str| given[BRUSH_KEYS.iter().position(|n| *n == k).unwrap_or(0)];
        let p = &t.p;
        let posf = |x: f64, fb: f64| if x.is_finite() && x > 0.0 { x } else { fb };
        let fz0 = posf(p.fnomin * p.lfzo, 4000.0);
        let mut b = BrushParams {
            fz0,
            r0: posf(p.unloaded_radius, 0.3),
            cz: posf(p.vertical_stiffness, 2e5),
            q_ra1: p.q_ra1,
            q_ra2: p.q_ra2,
            ..Default::default()
        };
        let mut d = Derivation::default();
        if let Some(x) = get("POINTS") {
            if !(x.fract() == 0.0 && x >= 1.0 && x <= M_MAX as f64) {
                return Err(tir_err(
                    file,
                    "POINTS",
                    format!("[BRUSH] POINTS = {x}: expected an integer 1..={M_MAX}"),
                ));
            }
            b.points = x as usize;
        }
        b.pressure_n = get("PRESSURE_N").unwrap_or(1.0);
        // The MF at FNOMIN, zero slip.
        let probe = tyre.slip_properties(
            &MfInput {
                fz: fz0,
                vx: 20.0,
                ..Default::default()
            },
            UseMode::from_code(211).unwrap_or_default(),
        );
        let patch0 = |b: &BrushParams| Patch::new(b, fz0);
        let a0 = patch0(&b).a;
        let mu_mf = posf(probe.muy.abs(), 1.0);
        b.mu_k = get("MUK").unwrap_or(mu_mf);
        b.mu_s = get("MUS").unwrap_or(b.mu_k.max(mu_mf));
        if get("MUS").is_none() && get("MUK").is_some() {
            b.mu_s = b.mu_k;
        }
        b.mu_dfz = get("MU_DFZ").unwrap_or(if p.pdy1 != 0.0 { p.pdy2 / p.pdy1 } else { 0.0 });
        let sig_mf = probe.sigmay;
        b.sigma_c = get("SIGMA_C").unwrap_or(if sig_mf.is_finite() && sig_mf > 0.0 {
            (2.0 * sig_mf - a0).max(0.5 * a0)
        } else {
            0.8
        });
        let cy_mf = posf(probe.cy, posf(p.lateral_stiffness, 1e5));
        b.compliance = get("CARCASS_COMPLIANCE").unwrap_or((b.sigma_c + a0) / (b.sigma_c * cy_mf));
        let kxk = probe.kxk.abs();
        b.cpx = get("CPX").unwrap_or(if kxk.is_finite() && kxk > 0.0 && a0 > 0.0 {
            kxk / (2.0 * a0 * a0)
        } else {
            8e6
        });
        b.cpy = match get("CPY") {
            Some(x) => x,
            None => {
                let kya = probe.kya.abs();
                if kya.is_finite() && kya > 0.0 {
                    let (x, reached) = cpy_for(&b, kya);
                    if !reached {
                        d.notes.push(format!(
                            "[BRUSH] CPY: the MF's cornering stiffness {kya:.0} N/rad at FNOMIN is beyond what the carcass (CARCASS_COMPLIANCE {:.3e} m/N, SIGMA_C {:.3} m) allows with any tread; CPY = {x:.3e} N/m² (give CPY or a stiffer carcass in [BRUSH])",
                            b.compliance, b.sigma_c
                        ));
                    }
                    x
                } else {
                    8e6
                }
            }
        };
        for (i, key) in BRUSH_KEYS.iter().enumerate() {
            if given[i].is_some() {
                d.given.push(key);
            } else {
                d.derived.push(key);
            }
        }
        b.validate(file)?;
        Ok((b, d))
    }

    /// Store these parameters as the `[BRUSH]` section of `t` (read back by
    /// [`BrushParams::from_tyre`]).
    pub fn write_to(&self, t: &mut crate::tir::TyreParams) {
        let sec = t.extra_section(SECTION);
        for (k, v) in BRUSH_KEYS.iter().zip(self.values()) {
            sec.set(k, v);
        }
    }

    /// Values in [`BRUSH_KEYS`] order.
    pub fn values(&self) -> [f64; 9] {
        [
            self.points as f64,
            self.cpy,
            self.cpx,
            self.compliance,
            self.sigma_c,
            self.mu_s,
            self.mu_k,
            self.mu_dfz,
            self.pressure_n,
        ]
    }
}

/// CPY giving the cornering stiffness `target` at FNOMIN (bisection in log
/// CPY over 1e4..1e10 N/m², 60 halvings: relative precision 1e-5 of the
/// bracket's log width); false when even the top of the bracket is too soft.
pub fn cpy_for(b: &BrushParams, target: f64) -> (f64, bool) {
    let patch = Patch::new(b, b.fz0);
    let cy = |c: f64| cornering_stiffness_on(&BrushParams { cpy: c, ..*b }, &patch);
    let (mut lo, mut hi) = (1e4f64.ln(), 1e10f64.ln());
    if cy(hi.exp()) < target {
        return (hi.exp(), false);
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if cy(mid.exp()) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    ((0.5 * (lo + hi)).exp(), true)
}
