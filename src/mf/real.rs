//! real — the scalar type the Magic Formula equations are written over.
//!
//! The force and moment equations are generic over [`Real`] so that the same
//! code evaluates with plain `f64` (the fast path) and with the forward-mode
//! dual numbers of the `num-dual` crate (`Dual64`, `DualSVec64<N>` …), which
//! gives the fitter exact derivatives with respect to any parameter seeded in
//! [`crate::tir::MfParams::map`].
//!
//! Must never: branch on anything but the real part, or change the value of
//! the `f64` instantiation (for `f64` every helper is the plain operation).

pub use num_dual::DualNum;

/// A scalar the Magic Formula can be evaluated with: `f64` or a `Copy`
/// dual number over `f64`. Arithmetic with `f64` on the right-hand side
/// (`x * 2.0`), comparison with `f64`, and the usual functions (`sin`, `atan`,
/// `sqrt`, `exp`, `powd` …) come from [`DualNum`].
pub trait Real: DualNum<f64> + Copy + Send + Sync {
    /// Whether the type carries derivatives. When it does, terms whose
    /// coefficient is zero must still be evaluated (their derivative is not
    /// zero), so value-only shortcuts are disabled.
    const TRACKS_DERIVATIVES: bool;
    /// The value part.
    #[inline(always)]
    fn v(&self) -> f64 {
        self.re()
    }
    /// A constant.
    #[inline(always)]
    fn c(x: f64) -> Self {
        Self::from(x)
    }
    /// atan, as [`DualNum::atan`]. For `f64` it is the inherent `f64::atan`
    /// (the same libm function, the same bits): num-dual's `f64` impl is a
    /// separate function that the cdylib (the FMU) did not inline, an extra
    /// call per use on the hot path.
    #[inline(always)]
    fn arctan(self) -> Self {
        DualNum::atan(&self)
    }
    /// tan, as [`DualNum::tan`] (see [`Real::arctan`] for why).
    #[inline(always)]
    fn tangent(self) -> Self {
        DualNum::tan(&self)
    }
}

impl Real for f64 {
    const TRACKS_DERIVATIVES: bool = false;
    #[inline(always)]
    fn arctan(self) -> f64 {
        f64::atan(self)
    }
    #[inline(always)]
    fn tangent(self) -> f64 {
        f64::tan(self)
    }
}

impl<const N: usize> Real for num_dual::DualSVec64<N> {
    const TRACKS_DERIVATIVES: bool = true;
}

impl Real for num_dual::Dual64 {
    const TRACKS_DERIVATIVES: bool = true;
}

/// MATLAB's `sign`: −1, 0 or +1 (0 for 0 and NaN stays NaN), of the value part.
#[inline(always)]
pub fn sign<T: Real>(x: T) -> f64 {
    let v = x.v();
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else if v == 0.0 {
        0.0
    } else {
        f64::NAN
    }
}

/// `sign` with 0 mapped to +1: the guard used with the small ε of Pacejka's
/// eq. 4.E6a so that `K / (C·D + ε·sgn D)` never divides by zero.
#[inline(always)]
pub fn sign1<T: Real>(x: T) -> f64 {
    if x.v() < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// `|x|` (derivative sign taken from the value part).
#[inline(always)]
pub fn abs<T: Real>(x: T) -> T {
    if x.v() < 0.0 {
        -x
    } else {
        x
    }
}

/// `x^y` with `0^y` = `0f64.powf(y)` also for dual numbers (whose `powd`
/// goes through `ln 0`).
#[inline(always)]
pub fn pow<T: Real>(x: T, y: T) -> T {
    if T::TRACKS_DERIVATIVES && x.v() == 0.0 {
        T::c(0f64.powf(y.v()))
    } else {
        x.powd(y)
    }
}

/// `min(x, 1)` as used by the limit checks on the curvature factors; the
/// returned flag says whether it clamped.
#[inline(always)]
pub fn cap_one<T: Real>(x: T, on: bool) -> (T, bool) {
    if on && x.v() > 1.0 {
        (T::c(1.0), true)
    } else {
        (x, false)
    }
}

/// cos(atan x) = 1/sqrt(1 + x²), without the two transcendental calls.
#[inline(always)]
pub fn cos_atan<T: Real>(x: T) -> T {
    (x * x + 1.0).sqrt().recip()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helpers_follow_matlab() {
        assert_eq!(sign(0.0), 0.0);
        assert_eq!(sign1(0.0), 1.0);
        assert_eq!(sign(-2.0), -1.0);
        assert!(sign(f64::NAN).is_nan());
        assert_eq!(pow(0.0, 0.0), 1.0);
        assert_eq!(
            pow(num_dual::Dual64::from(0.0), num_dual::Dual64::from(0.85)).re,
            0.0
        );
        assert!((cos_atan(0.7) - 0.7f64.atan().cos()).abs() < 1e-16);
    }
}
