//! brush — a physical steady-state force model beside the Magic Formula: the
//! brush model with tread shear springs in series with a flexible carcass
//! (Guan & Dang, "An analysis on the effect of tire tread characteristics on
//! the prediction accuracy of the cornering model", *Automotive Engineering*
//! 28(11), 2006; brush: Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., ch. 3;
//! carcass: the stretched string, Pacejka ch. 5).
//!
//! The patch is discretised into M points (`contact`: length from load and
//! vertical stiffness, parabolic or generalised pressure); the tread is a
//! shear spring per point (c_px, c_py per unit length); the carcass' lateral
//! compliance is the string's Green's function (`carcass`, derivation in
//! its header); adhesion where the force needed stays below μs·p, sliding
//! with μk behind the first sliding point, the boundary iterated until it no
//! longer moves (`solver`). Outputs Fx, Fy, Mz (ISO-W) for pure and
//! combined slip (Pacejka's theoretical slips, sliding along the slip), the
//! cornering stiffness of the paper's eq. (14) and the slip stiffness.
//! Camber is not modelled: the brush's camber thrust (the tread following
//! the cambered ring's curved path, Pacejka §3.2.4) holds for round-profile
//! motorcycle tyres and overestimates a car tyre's camber stiffness several
//! times, so a term without a tyre-specific factor would be wrong; Fy, Mz
//! are those of γ = 0.
//!
//! Parameters: `[BRUSH]` section of the `.tir`, defaults from the file's
//! Magic Formula (`params`). Selectable as the force model of the
//! transient models (`TransientOptions::brush`), in `eval`/`replay`
//! (`--force-model brush`), the FMU (`force_model = brush`), fitted by
//! `fit --model brush` (`crate::fit::brush`); the paper's study of tread
//! stiffness in `study.rs` ([`sensitivity`], `tyrekit brush study`).
//!
//! Must never: allocate in [`BrushParams::forces`], or return a non-finite
//! force for finite inputs.

mod carcass;
mod contact;
mod params;
mod solver;
mod study;
pub(crate) mod transient;

pub use carcass::StringCarcass;
pub use contact::{half_length, pressure_shape, Point};
pub use params::{cpy_for, BrushParams, Derivation, BRUSH_KEYS, DEFAULT_POINTS, SECTION};
pub use solver::{
    cornering_stiffness_on, evaluate_on, friction, slip_stiffness_on, BrushForces, BrushInput,
    Patch, M_MAX,
};
pub use study::{
    cy_at, cy_elasticity, sensitivity, string_cornering_stiffness, StudyRow, VerticalSeries,
    BETA_MIN, STUDY_FACTORS,
};

/// Which steady-state force model a transient model (or `eval`, the FMU) uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ForceModelKind {
    /// The Magic Formula of the tyre file.
    #[default]
    Mf,
    /// The brush model of this module.
    Brush,
}

impl ForceModelKind {
    /// Parse `mf` | `brush` (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mf" => Some(Self::Mf),
            "brush" => Some(Self::Brush),
            _ => None,
        }
    }
    /// The name as accepted by [`ForceModelKind::parse`].
    pub fn name(self) -> &'static str {
        match self {
            Self::Mf => "mf",
            Self::Brush => "brush",
        }
    }
}

impl BrushParams {
    /// Fx, Fy, Mz at one operating point (allocation-free; see `solver`).
    #[inline]
    pub fn forces(&self, inp: &BrushInput) -> BrushForces {
        solver::evaluate(self, inp)
    }

    /// The discretised patch at load `fz`.
    pub fn patch(&self, fz: f64) -> Patch {
        Patch::new(self, fz)
    }

    /// Cornering stiffness C_y = ∂|Fy|/∂tan α at zero slip and load `fz` (N/rad).
    pub fn cornering_stiffness(&self, fz: f64) -> f64 {
        cornering_stiffness_on(self, &self.patch(fz))
    }

    /// Longitudinal slip stiffness C_κ at zero slip and load `fz` (N).
    pub fn slip_stiffness(&self, fz: f64) -> f64 {
        slip_stiffness_on(self, &self.patch(fz))
    }

    /// Lateral relaxation length at load `fz` (m): σα = C_y/C_Fy with C_Fy the
    /// string carcass' lateral stiffness over the contact
    /// ([`StringCarcass::lateral_stiffness`]); bounded below by a, the
    /// order of the tread's own build-up length (elements are renewed over
    /// 2a), which is also the value for a rigid carcass.
    pub fn lateral_relaxation(&self, fz: f64) -> f64 {
        let patch = self.patch(fz);
        let c = self.carcass();
        if c.rigid() {
            return patch.a;
        }
        let s = cornering_stiffness_on(self, &patch) / c.lateral_stiffness(patch.a);
        if s.is_finite() {
            s.max(patch.a)
        } else {
            patch.a
        }
    }
}
