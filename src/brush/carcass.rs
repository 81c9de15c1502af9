//! carcass — the lateral compliance of the carcass under the contact: the
//! stretched string on an elastic foundation.
//!
//! # Derivation
//! The carcass' lateral deflection v(x) under a line load q(x) is modelled as
//! a string with tension S on a foundation of stiffness c_c per unit length
//! (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §5.3; von Schlippe /
//! Segel's stretched string): S·v'' − c_c·v = −q. Its Green's function for a
//! point force F at ξ (outside the contact the string is free and decays) is
//!
//! ```text
//!   v(x) = F·h·exp(−|x − ξ|/σ_c),   σ_c = √(S/c_c),   h = 1/(2·c_c·σ_c)
//! ```
//! so two lateral modal parameters fix it: the point compliance h (m/N, the
//! inverse of the string's stiffness to a concentrated force) and the string
//! relaxation length σ_c (m). The compliance matrix of the M contact points
//! is H_ij = h·exp(−|s_i − s_j|/σ_c).
//!
//! A tread element enters the contact at the leading edge (s = 0) undeformed,
//! on the carcass; in adhesion its tip then stays where it touched the road.
//! Its shear deflection is therefore the road path minus the carcass
//! deflection *relative to the leading edge*: e_i = s_i·σ_y − (v(s_i) − v(0)),
//! which gives the effective compliance used by the solver
//!
//! ```text
//!   He_ij = h·(exp(−|s_i − s_j|/σ_c) − exp(−s_j/σ_c))
//! ```
//! (a uniform lateral translation of the carcass cancels: it changes the
//! transient, not the steady state, as in Pacejka §3.2.2). The paper's
//! (Guan & Dang, *Automotive Engineering* 28(11), 2006) H is this He.
//!
//! The carcass lateral stiffness to a load spread over the contact (what the
//! relaxation length σα = C_Fα/C_Fy uses) is that of the string under a
//! uniform load of length 2a: C_Fy = 2·c_c·(σ_c + a) = (σ_c + a)/(σ_c·h)
//! (Pacejka 3rd ed. eq. 5.63 ff.); with a rigid tread σα = σ_c + a.
//!
//! Must never: produce a non-finite entry (h = 0 is the rigid carcass).

/// The string carcass: point compliance h (m/N, 0 = rigid) and relaxation
/// length σ_c (m, > 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StringCarcass {
    /// Compliance to a concentrated lateral force (m/N); 0 = rigid carcass.
    pub h: f64,
    /// String relaxation length σ_c = √(S/c_c) (m).
    pub sigma_c: f64,
}

impl StringCarcass {
    /// Whether the carcass is rigid (H = 0).
    #[inline]
    pub fn rigid(&self) -> bool {
        self.h == 0.0
    }

    /// The effective compliance He_ij between contact points at distances
    /// `si`, `sj` from the leading edge (m/N) (module docs).
    #[inline]
    pub fn he(&self, si: f64, sj: f64) -> f64 {
        self.h * ((-(si - sj).abs() / self.sigma_c).exp() - (-sj / self.sigma_c).exp())
    }

    /// Lateral stiffness of the carcass to a load spread over a contact of
    /// half length `a` (N/m): (σ_c + a)/(σ_c·h); infinite when rigid.
    pub fn lateral_stiffness(&self, a: f64) -> f64 {
        if self.rigid() {
            f64::INFINITY
        } else {
            (self.sigma_c + a) / (self.sigma_c * self.h)
        }
    }
}
