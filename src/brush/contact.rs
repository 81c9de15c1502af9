//! contact — the brush model's contact patch: half length from the load and
//! the tyre's vertical stiffness, the pressure distribution (parabolic or the
//! generalised shape), and its discretisation into M points.
//!
//! Must never: return a patch with a non-finite length or pressure, or a
//! pressure whose element loads do not sum to Fz.

/// Contact half length a (m) at load `fz` (N): the MF-Swift relation
/// (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §A3.3, the contact-length
/// equation of the MF 6.1 tyre file: a = R0·(Q_RA2·ρ/R0 + Q_RA1·√(ρ/R0)),
/// with ρ = Fz/Cz the vertical deflection). 0 for `fz ≤ 0`.
pub fn half_length(fz: f64, r0: f64, cz: f64, q_ra1: f64, q_ra2: f64) -> f64 {
    if fz <= 0.0 || !(r0 > 0.0 && cz > 0.0) {
        return 0.0;
    }
    let rho = fz / (cz * r0);
    let a = r0 * (q_ra2 * rho + q_ra1 * rho.sqrt());
    if a.is_finite() && a > 0.0 {
        a
    } else {
        // Circle chord of the deflected ring (ρ ≪ R0): a ≈ √(2·R0·ρ)/2 is a
        // lower estimate of real tyres' patches; used only when the file has no
        // usable Q_RA1/Q_RA2.
        0.5 * (2.0 * r0 * fz / cz).sqrt()
    }
}

/// Shape of the pressure q_z(x) ∝ 1 − |x/a|^(2n), x from the patch centre
/// (Pacejka 3rd ed. §3.2, the parabola for n = 1; larger n flattens it
/// towards the uniform pressure of a tyre with a stiff belt).
#[inline]
pub fn pressure_shape(xi: f64, n: f64) -> f64 {
    let r = xi.abs();
    if r >= 1.0 {
        0.0
    } else if n == 1.0 {
        1.0 - r * r
    } else {
        1.0 - r.powf(2.0 * n)
    }
}

/// One point of the discretised patch: position and normal force.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point {
    /// Distance from the leading edge s_i = (i + ½)·Δ (m).
    pub s: f64,
    /// Normal force on the element (N); Σ = Fz exactly.
    pub pz: f64,
}

/// The patch discretised into `m` equal elements of length Δ = 2a/m, one point
/// at each element's midpoint (midpoint rule: second order for the smooth
/// parts of the force distribution, see `solver`). Writes the points into
/// `out[..m]` and returns Δ. The element loads q_z(s_i)·Δ are renormalised so
/// that they sum to Fz exactly (so full sliding gives exactly μ·Fz).
pub fn discretise(a: f64, fz: f64, n: f64, m: usize, out: &mut [Point]) -> f64 {
    let d = 2.0 * a / m as f64;
    let mut sum = 0.0;
    for (i, p) in out[..m].iter_mut().enumerate() {
        let s = (i as f64 + 0.5) * d;
        let w = pressure_shape((a - s) / a, n);
        *p = Point { s, pz: w };
        sum += w;
    }
    let scale = if sum > 0.0 { fz / sum } else { 0.0 };
    for p in out[..m].iter_mut() {
        p.pz *= scale;
    }
    d
}
