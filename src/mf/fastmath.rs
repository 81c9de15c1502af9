//! fastmath — inlined `f64` elementary functions (atan, sin, cos, tan, exp,
//! ln, pow) for the value-only path of the Magic Formula and the transient
//! step, where glibc's out-of-line calls were most of the time (a combined-slip
//! MF 6.1 evaluation makes ≈ 45 of them).
//!
//! Methods (coefficients as published; the code is written here):
//! * `atan`: Cephes `atan.c` (S. L. Moshier, *Methods and Programs for
//!   Mathematical Functions*, 1989): reduction at tan(3π/8) and 0.66, then
//!   x + x³·P(x²)/Q(x²) with a degree 4/5 rational approximation, π/2 carried
//!   in two parts ("MOREBITS").
//! * `sin`, `cos`, `sin_cos`, `tan`: Cephes `sin.c`: reduction by π/4 in three
//!   parts (Cody & Waite, *Software Manual for the Elementary Functions*, 1980)
//!   to |z| ≤ π/4, then degree-13 (sin) / degree-14 (cos) polynomials. Both
//!   polynomials are always evaluated and selected by octant without branches
//!   (the Magic Formula's arguments change octant with the sign of the slip).
//!   `tan` = sin/cos of the same reduction.
//! * `exp`: Cephes `exp.c`: x = n·ln 2 + r (ln 2 in two parts), Padé form
//!   e^r = 1 + 2r·P(r²)/(Q(r²) − r·P(r²)), scaled by 2ⁿ through the exponent bits.
//! * `ln`: fdlibm `e_log.c` (Sun Microsystems, 1993): x = 2ᵏ·(1+f) with
//!   √2/2 ≤ 1+f < √2, s = f/(2+f), log(1+f) = f − s·(f − R(s²)) with the
//!   degree-14 minimax R.
//! * `pow(x, y)` = exp(y·ln x) for x > 0 and |y·ln x| < 700; elsewhere std.
//!
//! No FMA (the baseline x86_64 has none; `mul_add` would be a library call):
//! plain Horner steps as in the Cephes/fdlibm originals. Every function hands
//! the cases outside its fast range (|x| ≥ 2²⁰ for the trigonometric ones,
//! over/underflow, non-positive or non-finite arguments of ln/pow) to `std`,
//! so NaN, ±∞ and the IEEE special cases are exactly std's.
//! Accuracy against `std` (glibc, itself < 1 ulp): asserted by the sweeps in
//! this module's tests (atan, sin, cos, exp, ln ≤ 2 ulp; tan ≤ 3 ulp; pow ≤ 4 ulp
//! on the Magic Formula's argument ranges).
//!
//! Must never: be used for dual numbers (their derivatives come from
//! `num-dual`'s own functions, see `real.rs`), allocate, or hold state.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// tan(3π/8): above it atan uses π/2 − atan(1/x).
const T3P8: f64 = 2.414_213_562_373_095_048_80;
/// π/2 − FRAC_PI_2 (the bits of π/2 beyond the double).
const MOREBITS: f64 = 6.123_233_995_736_765_886_130e-17;
const ATAN_P: [f64; 5] = [
    -8.750_608_600_031_904_122_785e-1,
    -1.615_753_718_733_365_076_637e1,
    -7.500_855_792_314_704_667_340e1,
    -1.228_866_684_490_136_173_410e2,
    -6.485_021_904_942_025_371_773e1,
];
const ATAN_Q: [f64; 5] = [
    2.485_846_490_142_306_297_962e1,
    1.650_270_098_316_988_542_046e2,
    4.328_810_604_912_902_668_951e2,
    4.853_903_996_359_136_964_868e2,
    1.945_506_571_482_613_964_425e2,
];

/// Arc tangent (Cephes method, see the module header). NaN → NaN, ±∞ → ±π/2.
#[inline(always)]
pub fn atan(x: f64) -> f64 {
    let a = x.abs();
    let big = a > T3P8;
    let mid = a > 0.66;
    // Reduced argument r = num/den, atan(a) = base + atan(r) (+ the low bits of base).
    let num = if big {
        -1.0
    } else if mid {
        a - 1.0
    } else {
        a
    };
    let den = if big {
        a
    } else if mid {
        a + 1.0
    } else {
        1.0
    };
    let base = if big {
        FRAC_PI_2
    } else if mid {
        FRAC_PI_4
    } else {
        0.0
    };
    let more = if big {
        MOREBITS
    } else if mid {
        0.5 * MOREBITS
    } else {
        0.0
    };
    let r = num / den;
    let z = r * r;
    let p = (((ATAN_P[0] * z + ATAN_P[1]) * z + ATAN_P[2]) * z + ATAN_P[3]) * z + ATAN_P[4];
    let q = ((((z + ATAN_Q[0]) * z + ATAN_Q[1]) * z + ATAN_Q[2]) * z + ATAN_Q[3]) * z + ATAN_Q[4];
    let y = base + ((r * (z * p / q) + r) + more);
    y.copysign(x)
}

/// π/4 in three parts (Cephes DP1..DP3): y·PI4A and y·PI4B are exact for the
/// octant counts the fast range allows.
const PI4A: f64 = 7.853_981_256_484_985_351_56e-1;
const PI4B: f64 = 3.774_894_707_930_798_176_68e-8;
const PI4C: f64 = 2.695_151_429_079_059_526_45e-15;
const SIN_C: [f64; 6] = [
    1.589_623_015_765_465_680_60e-10,
    -2.505_074_776_285_780_728_66e-8,
    2.755_731_362_138_572_452_13e-6,
    -1.984_126_982_958_953_959_96e-4,
    8.333_333_333_322_118_588_78e-3,
    -1.666_666_666_666_663_072_95e-1,
];
const COS_C: [f64; 6] = [
    -1.135_853_652_138_768_173_00e-11,
    2.087_570_084_197_473_167_78e-9,
    -2.755_731_417_929_673_881_12e-7,
    2.480_158_728_885_170_453_48e-5,
    -1.388_888_888_887_305_641_16e-3,
    4.166_666_666_666_659_292_18e-2,
];
/// Beyond this the three-part reduction loses bits: std takes over.
const TRIG_FAST_MAX: f64 = 1_048_576.0;

/// (sin x, cos x) with one reduction (Cephes method, see the module header).
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let a = x.abs();
    if !(a < TRIG_FAST_MAX) {
        return (x.sin(), x.cos());
    }
    // Octant j of |x| (rounded up to even, so |z| ≤ π/4), z = |x| − j·π/4.
    let mut j = (a * (4.0 / std::f64::consts::PI)) as i64;
    j += j & 1;
    let y = j as f64;
    let z = ((a - y * PI4A) - y * PI4B) - y * PI4C;
    let zz = z * z;
    let ps = z + z
        * zz
        * (((((SIN_C[0] * zz + SIN_C[1]) * zz + SIN_C[2]) * zz + SIN_C[3]) * zz + SIN_C[4]) * zz
            + SIN_C[5]);
    let pc = 1.0 - 0.5 * zz
        + zz * zz
            * (((((COS_C[0] * zz + COS_C[1]) * zz + COS_C[2]) * zz + COS_C[3]) * zz + COS_C[4])
                * zz
                + COS_C[5]);
    // j mod 8 ∈ {0, 2, 4, 6}: sin|x| = ps, pc, −ps, −pc; cos x = pc, −ps, −pc, ps.
    let q = j & 7;
    let swap = q & 2 != 0;
    let (s, c) = if swap { (pc, ps) } else { (ps, pc) };
    let s_neg = (q & 4 != 0) != (x < 0.0);
    let c_neg = (q == 2) | (q == 4);
    (if s_neg { -s } else { s }, if c_neg { -c } else { c })
}

/// Sine (see [`sin_cos`]).
#[inline(always)]
pub fn sin(x: f64) -> f64 {
    sin_cos(x).0
}

/// Cosine (see [`sin_cos`]).
#[inline(always)]
pub fn cos(x: f64) -> f64 {
    sin_cos(x).1
}

/// Tangent as sin/cos of one reduction.
#[inline(always)]
pub fn tan(x: f64) -> f64 {
    let (s, c) = sin_cos(x);
    s / c
}

const LOG2E: f64 = std::f64::consts::LOG2_E;
/// ln 2 in two parts (Cephes C1, C2): n·LN2_HI is exact for |n| < 2¹¹.
const LN2_HI: f64 = 6.931_457_519_531_25e-1;
const LN2_LO: f64 = 1.428_606_820_309_417_232_12e-6;
const EXP_P: [f64; 3] = [
    1.261_771_930_748_105_908_78e-4,
    3.029_944_077_074_419_613_00e-2,
    9.999_999_999_999_999_999_10e-1,
];
const EXP_Q: [f64; 4] = [
    3.001_985_051_386_644_550_42e-6,
    2.524_483_403_496_841_041_92e-3,
    2.272_655_482_081_550_287_66e-1,
    2.000_000_000_000_000_000_09,
];
/// 1.5·2⁵²: adding and subtracting it rounds to the nearest integer.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

/// e^x (Cephes method, see the module header); outside |x| < 700 std.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    if !(x.abs() < 700.0) {
        return x.exp();
    }
    let n = (x * LOG2E + ROUND_MAGIC) - ROUND_MAGIC;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let rr = r * r;
    let px = r * ((EXP_P[0] * rr + EXP_P[1]) * rr + EXP_P[2]);
    let qx = ((EXP_Q[0] * rr + EXP_Q[1]) * rr + EXP_Q[2]) * rr + EXP_Q[3];
    let e = 1.0 + 2.0 * (px / (qx - px));
    // 2ⁿ from its exponent bits (|n| ≤ 1010 here, a normal number).
    let scale = f64::from_bits(((n as i64 + 1023) as u64) << 52);
    e * scale
}

const LN2_HI_D: f64 = 6.931_471_803_691_238_164_90e-1;
const LN2_LO_D: f64 = 1.908_214_929_270_587_700_02e-10;
const LG: [f64; 7] = [
    6.666_666_666_666_735_130e-1,
    3.999_999_999_940_941_908e-1,
    2.857_142_874_366_239_149e-1,
    2.222_219_843_214_978_396e-1,
    1.818_357_216_161_805_012e-1,
    1.531_383_769_920_937_332e-1,
    1.479_819_860_511_658_591e-1,
];

/// Natural logarithm (fdlibm method, see the module header); std for
/// x ≤ 0, subnormal, ∞ or NaN.
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    if !(x >= f64::MIN_POSITIVE && x < f64::INFINITY) {
        return x.ln();
    }
    let bits = x.to_bits();
    let mut k = ((bits >> 52) as i64) - 1023;
    // Mantissa m ∈ [1, 2); fold to [√2/2, √2).
    let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    if m > std::f64::consts::SQRT_2 {
        m *= 0.5;
        k += 1;
    }
    let f = m - 1.0;
    let kf = k as f64;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    let hfsq = 0.5 * f * f;
    kf * LN2_HI_D - ((hfsq - (s * (hfsq + r) + kf * LN2_LO_D)) - f)
}

/// x^y = e^{y·ln x} for finite x > 0, finite y and |y·ln x| < 700 (relative
/// error ≈ |y·ln x|·2⁻⁵³ beyond exp's own); every other case is std's `powf`.
#[inline(always)]
pub fn pow(x: f64, y: f64) -> f64 {
    if x >= f64::MIN_POSITIVE && x < f64::INFINITY && y.is_finite() {
        let t = y * ln(x);
        if t.abs() < 700.0 {
            return exp(t);
        }
    }
    x.powf(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Distance in units in the last place between two finite doubles (of
    /// either sign; ±0 are 0 apart).
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |x: f64| {
            let i = x.to_bits() as i64;
            if i < 0 {
                i64::MIN - i
            } else {
                i
            }
        };
        key(a).abs_diff(key(b))
    }

    /// Largest ulp distance of `fast` from `exact` over 10⁶ arguments drawn
    /// uniformly from `lo..hi` (seeded), plus the worst argument.
    fn sweep(
        lo: f64,
        hi: f64,
        fast: impl Fn(f64) -> f64,
        exact: impl Fn(f64) -> f64,
    ) -> (u64, f64) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut worst = (0, 0.0);
        for _ in 0..1_000_000 {
            let x = rng.gen_range(lo..hi);
            let (f, e) = (fast(x), exact(x));
            assert_eq!(f.is_nan(), e.is_nan(), "{x}");
            let d = ulps(f, e);
            if d > worst.0 {
                worst = (d, x);
            }
        }
        worst
    }

    // The bounds: the Cephes/fdlibm methods are documented at < 1 ulp
    // (peak relative error ≈ 2e-16) and glibc's functions are within 1 ulp of
    // the true value, so two implementations may differ by 2 ulp; tan is a
    // quotient of two such values (3); pow goes through exp(y ln x) (4 on
    // these ranges, where |y ln x| < 3). A bad coefficient or reduction step
    // gives thousands of ulp.

    #[test]
    fn atan_within_2_ulp_of_std() {
        for (lo, hi) in [(-1.0, 1.0), (-4.0, 4.0), (-1e3, 1e3), (-1e-6, 1e-6)] {
            let (d, x) = sweep(lo, hi, atan, f64::atan);
            assert!(d <= 2, "atan: {d} ulp at {x} (range {lo}..{hi})");
        }
        assert_eq!(atan(f64::INFINITY), FRAC_PI_2);
        assert_eq!(atan(f64::NEG_INFINITY), -FRAC_PI_2);
        assert!(atan(f64::NAN).is_nan());
        assert_eq!(atan(-0.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(atan(1e300), FRAC_PI_2);
    }

    #[test]
    fn sin_cos_within_2_ulp_of_std() {
        for (lo, hi) in [(-4.0, 4.0), (-0.1, 0.1), (-1e3, 1e3)] {
            let (d, x) = sweep(lo, hi, sin, f64::sin);
            assert!(d <= 2, "sin: {d} ulp at {x} (range {lo}..{hi})");
            let (d, x) = sweep(lo, hi, cos, f64::cos);
            assert!(d <= 2, "cos: {d} ulp at {x} (range {lo}..{hi})");
        }
        for x in [f64::NAN, f64::INFINITY, 1e7, -3e9] {
            let (s, c) = sin_cos(x);
            assert_eq!(s.to_bits(), x.sin().to_bits());
            assert_eq!(c.to_bits(), x.cos().to_bits());
        }
        assert_eq!(sin(0.0), 0.0);
        assert_eq!(cos(0.0), 1.0);
    }

    #[test]
    fn tan_within_3_ulp_of_std() {
        // |x| < 1.4: slip angles and the α of the aligning torque stay well inside.
        let (d, x) = sweep(-1.4, 1.4, tan, f64::tan);
        assert!(d <= 3, "tan: {d} ulp at {x}");
    }

    #[test]
    fn exp_within_2_ulp_of_std() {
        for (lo, hi) in [(-1.0, 1.0), (-50.0, 50.0), (-699.0, 699.0)] {
            let (d, x) = sweep(lo, hi, exp, f64::exp);
            assert!(d <= 2, "exp: {d} ulp at {x} (range {lo}..{hi})");
        }
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(800.0), f64::INFINITY);
        assert_eq!(exp(-800.0), 0.0);
        assert!(exp(f64::NAN).is_nan());
    }

    #[test]
    fn ln_within_2_ulp_of_std() {
        for (lo, hi) in [(0.5, 2.0), (1e-3, 1e3), (1e-300, 1e300)] {
            let (d, x) = sweep(lo, hi, ln, f64::ln);
            assert!(d <= 2, "ln: {d} ulp at {x} (range {lo}..{hi})");
        }
        assert_eq!(ln(1.0), 0.0);
        assert!(ln(-1.0).is_nan());
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
    }

    #[test]
    fn pow_within_4_ulp_of_std() {
        // The Magic Formula's powers: (Fz/Fz0)^QSY7, (p/p0)^QSY8 — bases 0.05..5,
        // exponents of order 1.
        for y in [-1.7, -0.4089, 0.3333, 0.9008, 2.5] {
            let (d, x) = sweep(0.05, 5.0, |x| pow(x, y), |x| x.powf(y));
            assert!(d <= 4, "pow(x, {y}): {d} ulp at {x}");
        }
        assert_eq!(pow(0.0, 0.85), 0.0);
        assert_eq!(pow(0.0, 0.0), 1.0);
        assert!(pow(-1.0, 0.5).is_nan());
    }
}
