//! study — Guan & Dang's study (*Automotive Engineering* 28(11), 2006)
//! reproduced: how strongly the cornering stiffness C_y depends on the tread's
//! shear stiffness k_y (here c_py, per unit length), against how strongly the
//! vertical stiffness K_z depends on the same tread, over a range of k_y.
//!
//! # Cornering stiffness
//! C_y(c_py) is the brush's full-adhesion stiffness with the string carcass,
//! the paper's eq. (14), C_y = Σ_i [k_y (I + k_y D_e H)⁻¹ C]_i
//! ([`super::cornering_stiffness_on`]), on a fixed patch (the load, contact
//! length, pressure and carcass of the tyre file at FNOMIN; only the tread
//! changes). Its limits: c_py → 0, the carcass is rigid next to the tread and
//! C_y → 2·c_py·a² → 0 (the rigid-carcass brush, Pacejka, *Tyre and Vehicle
//! Dynamics*, 3rd ed., §3.2); c_py → ∞, the tread is rigid and C_y tends to the stretched
//! string's own cornering stiffness C_Fα = 2·c_c·(σ_c + a)² = (σ_c + a)²/(σ_c·h)
//! (Pacejka 3rd ed. §5.3, the string's steady side slip: σα = σ_c + a,
//! C_Fα = C_Fy·σα with C_Fy = 2·c_c·(σ_c + a); the string's point compliance
//! h = 1/(2·c_c·σ_c), see [`super::StringCarcass`]), [`string_cornering_stiffness`].
//!
//! # Vertical stiffness: tread in series with the carcass
//! Under a flat road the belt (carcass) and the tread carry the same normal
//! load Fz in series: the deflection is Fz/K_c + Fz/K_t, so
//!
//! ```text
//!   1/K_z = 1/K_c + 1/K_t,     K_t = c_pz·2a,     c_pz = β·c_py
//! ```
//! * K_t: the tread elements under the patch are parallel springs, each
//!   compressed by the same belt displacement, so the tread's vertical
//!   stiffness is its stiffness per unit length c_pz times the contact length 2a
//!   (independent of the pressure shape for this linear stiffness).
//! * c_pz = β·c_py: a tread block of height t, width w has shear stiffness
//!   G·w/t and compression stiffness E_c·w/t per unit length, so the ratio is
//!   β = E_c/G. For rubber (incompressible, E = 3G) bonded to the belt,
//!   E_c = E·(1 + 2·k·S²) with S the block's shape factor (loaded over free
//!   surface area) and k ≈ 0.5–1 (Gent, *Engineering with Rubber*, 3rd ed.,
//!   ch. 8): β = 3·(1 + 2kS²) ≥ 3. β = 3 ([`BETA_MIN`], the unconfined
//!   block) makes the tread vertically softest, i.e. it gives the *largest*
//!   vertical sensitivity: the conservative choice for the comparison.
//! * K_c (carcass and inflation) from the file's VERTICAL_STIFFNESS Cz, which
//!   is the whole tyre at the file's tread c_py0: 1/K_c = 1/Cz − 1/K_t(c_py0).
//!
//! The elasticities: d ln K_z / d ln c_py = K_z/K_t exactly (the tread's share
//! of the vertical deflection); d ln C_y / d ln c_py by a central difference in
//! ln c_py of step 1e-4 (C_y is analytic in c_py at full adhesion; the
//! truncation error is O(1e-8) relative). For a pair of springs in series it
//! would be the tread's share of the lateral deflection likewise.
//!
//! Must never: report a vertical model whose carcass stiffness is not positive
//! (a tread softer than the whole tyre is an error naming the cause).

use super::params::BrushParams;
use super::solver::{cornering_stiffness_on, Patch};

/// The smallest physical compression-to-shear modulus ratio of the tread
/// (E_c/G = 3 for an unconfined incompressible block; module docs).
pub const BETA_MIN: f64 = 3.0;

/// Cornering stiffness of the stretched string alone (rigid tread) over a
/// contact of half length `a` (N/rad): (σ_c + a)²/(σ_c·h), Pacejka 3rd ed.
/// §5.3 (C_Fα = 2·c_c·(σ_c + a)²); infinite for a rigid carcass.
pub fn string_cornering_stiffness(b: &BrushParams, a: f64) -> f64 {
    let c = b.carcass();
    if c.rigid() {
        f64::INFINITY
    } else {
        (c.sigma_c + a).powi(2) / (c.sigma_c * c.h)
    }
}

/// The vertical model of the tread in series with the carcass (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VerticalSeries {
    /// Carcass and inflation stiffness K_c (N/m).
    pub k_carcass: f64,
    /// Compression-to-shear modulus ratio β = c_pz/c_py of the tread.
    pub beta: f64,
    /// Contact half length a (m).
    pub a: f64,
}

impl VerticalSeries {
    /// The model whose total stiffness at tread `cpy0` is `cz` (the tyre
    /// file's VERTICAL_STIFFNESS), over a patch of half length `a`.
    pub fn calibrated(cz: f64, cpy0: f64, beta: f64, a: f64) -> crate::Result<VerticalSeries> {
        let kt0 = beta * cpy0 * 2.0 * a;
        let inv = 1.0 / cz - 1.0 / kt0;
        if !(inv > 0.0 && inv.is_finite() && beta > 0.0) {
            return Err(crate::Error::Input(format!(
                "brush study: the tread's vertical stiffness β·CPY·2a = {kt0:.4e} N/m (β = {beta}, CPY = {cpy0:.4e} N/m², a = {a:.4} m) is not stiffer than the whole tyre's VERTICAL_STIFFNESS {cz:.4e} N/m, so no carcass stiffness fits in series; give a larger β or CPY"
            )));
        }
        Ok(VerticalSeries {
            k_carcass: 1.0 / inv,
            beta,
            a,
        })
    }

    /// Tread vertical stiffness K_t = β·c_py·2a (N/m).
    pub fn k_tread(&self, cpy: f64) -> f64 {
        self.beta * cpy * 2.0 * self.a
    }

    /// Whole-tyre vertical stiffness K_z = (1/K_c + 1/K_t)⁻¹ (N/m).
    pub fn kz(&self, cpy: f64) -> f64 {
        1.0 / (1.0 / self.k_carcass + 1.0 / self.k_tread(cpy))
    }

    /// d ln K_z / d ln c_py = K_z/K_t (the tread's share of the deflection).
    pub fn elasticity(&self, cpy: f64) -> f64 {
        self.kz(cpy) / self.k_tread(cpy)
    }
}

/// c_py/c_py0 of the study's rows (`tyrekit brush study`): powers of two
/// from 1/32 to 32.
pub const STUDY_FACTORS: [f64; 11] = [
    1.0 / 32.0,
    1.0 / 16.0,
    0.125,
    0.25,
    0.5,
    1.0,
    2.0,
    4.0,
    8.0,
    16.0,
    32.0,
];

/// One row of the study.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StudyRow {
    /// Tread shear stiffness c_py (N/m²).
    pub cpy: f64,
    /// c_py over the file's (derived or given) c_py0.
    pub cpy_rel: f64,
    /// Cornering stiffness C_y (N/rad).
    pub cy: f64,
    /// Vertical stiffness K_z (N/m).
    pub kz: f64,
    /// d ln C_y / d ln c_py.
    pub e_cy: f64,
    /// d ln K_z / d ln c_py.
    pub e_kz: f64,
}

/// Cornering stiffness at tread `cpy` on `patch`.
pub fn cy_at(b: &BrushParams, patch: &Patch, cpy: f64) -> f64 {
    cornering_stiffness_on(&BrushParams { cpy, ..*b }, patch)
}

/// d ln C_y / d ln c_py at `cpy` (central difference, step 1e-4 in ln c_py).
pub fn cy_elasticity(b: &BrushParams, patch: &Patch, cpy: f64) -> f64 {
    const H: f64 = 1e-4;
    let up = cy_at(b, patch, cpy * H.exp());
    let dn = cy_at(b, patch, cpy * (-H).exp());
    (up.ln() - dn.ln()) / (2.0 * H)
}

/// The study over `factors` (c_py/c_py0) for the brush `b` (its c_py is
/// c_py0; the patch at its FNOMIN) and tread modulus ratio `beta`.
pub fn sensitivity(b: &BrushParams, factors: &[f64], beta: f64) -> crate::Result<Vec<StudyRow>> {
    let patch = Patch::new(b, b.fz0);
    let vert = VerticalSeries::calibrated(b.cz, b.cpy, beta, patch.a)?;
    Ok(factors
        .iter()
        .map(|&f| {
            let cpy = b.cpy * f;
            StudyRow {
                cpy,
                cpy_rel: f,
                cy: cy_at(b, &patch, cpy),
                kz: vert.kz(cpy),
                e_cy: cy_elasticity(b, &patch, cpy),
                e_kz: vert.elasticity(cpy),
            }
        })
        .collect())
}
