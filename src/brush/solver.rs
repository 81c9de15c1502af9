//! solver — the adhesion/sliding iteration of the brush with a flexible
//! carcass (Guan & Dang, *Automotive Engineering* 28(11), 2006; brush:
//! Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §3.2).
//!
//! Per contact point i (distance s_i from the leading edge, normal force
//! p_i, element length Δ), in Pacejka's theoretical slips σx = κ/(1+κ),
//! σy = tan α/(1+κ) (eq. 3.44 ff.):
//! * adhesion (i < n): the tip stays where it touched the road, so the
//!   tread's deflection is the road path minus the carcass deflection
//!   relative to the leading edge: f_y = k_y·(s_i·σy − (He·f_y)_i),
//!   f_x = k_x·s_i·σx (the carcass is rigid longitudinally in steady state:
//!   a uniform longitudinal carcass deflection cancels like the lateral
//!   translation), with k = c_p·Δ. For the adhesion block this is the paper's
//!   system (I + k_y·D_e·He)·f = k_y·D_e·d, D_e = diag(Δ), d_i = s_i·σy;
//! * sliding (i ≥ n, everything behind the first sliding point): f = μk·p_i
//!   along the slip (σx, σy) (Pacejka's assumption for combined slip, §3.2.3).
//!
//! The adhesion count n is the largest consistent one: with points 0..n
//! adhering, none of them needs more than μs·p_i (the static limit) — the
//! predicate P(n). P(0) holds (all sliding). If P(M) holds the whole patch
//! adheres; otherwise n is found by bisection between a true and a false P,
//! so the iteration always terminates after at most ⌈log2 M⌉ + 1 linear
//! solves, is deterministic (a function of the inputs only), and ends on a
//! converged boundary: P(n) true, P(n+1) false (the sliding region no longer
//! moves). For a rigid carcass the forces of the adhesion points do not
//! depend on n, P is monotone and n is the first point over the limit: the
//! classic brush (solved in one pass without any matrix).
//!
//! Order: with a rigid carcass, parabolic pressure and μs = μk, Fy and Mz are
//! midpoint-rule sums of a continuous, piecewise-smooth force distribution
//! (min of the adhesive and the sliding line loads), so they converge to the
//! closed forms as O(M⁻²) (tests/brush_closed_form.rs measures it).
//!
//! Must never: allocate (fixed-capacity arrays of [`M_MAX`] on the stack),
//! loop without bound, or return a non-finite force for finite inputs.

use super::carcass::StringCarcass;
use super::contact::{discretise, half_length, Point};
use super::params::BrushParams;

/// The most contact points a patch may be discretised into (the fixed
/// capacity of the solver's stack buffers; the dense adhesion matrix is
/// M_MAX² = 4096 numbers, 32 KiB).
pub const M_MAX: usize = 64;

/// One evaluation's inputs (ISO-W, SI).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrushInput {
    /// Normal load (N); ≤ 0: off the ground, no force.
    pub fz: f64,
    /// Longitudinal slip κ = −Vsx/|Vx| (–).
    pub kappa: f64,
    /// tan α = Vsy/|Vx| (–).
    pub tan_alpha: f64,
    /// Road friction scale (multiplies μs and μk); 1 = the file's friction.
    pub mu_scale: f64,
}

impl BrushInput {
    /// At load `fz`, slips κ and tan α, on the file's friction (scale 1).
    pub fn new(fz: f64, kappa: f64, tan_alpha: f64) -> BrushInput {
        BrushInput {
            fz,
            kappa,
            tan_alpha,
            mu_scale: 1.0,
        }
    }
}

/// One evaluation's results (ISO-W, SI).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrushForces {
    /// Longitudinal force (N).
    pub fx: f64,
    /// Lateral force (N), ISO sign (negative for positive α).
    pub fy: f64,
    /// Self-aligning moment about the patch centre (N m), ISO sign.
    pub mz: f64,
    /// Contact half length (m).
    pub a: f64,
    /// Sliding friction coefficient in use (–).
    pub mu_k: f64,
    /// Points in adhesion (from the leading edge).
    pub adhesion: usize,
    /// Linear solves the iteration took (0 for a rigid carcass).
    pub solves: usize,
}

/// The discretised patch of one load (positions, element loads, Δ, a).
#[derive(Clone, Copy, Debug)]
pub struct Patch {
    /// Points `pts[..m]`.
    pub pts: [Point; M_MAX],
    /// Number of points M.
    pub m: usize,
    /// Element length Δ = 2a/M (m).
    pub delta: f64,
    /// Half length a (m).
    pub a: f64,
}

impl Patch {
    /// The patch of `p` at load `fz` (M = p.points, capped at [`M_MAX`]).
    pub fn new(p: &BrushParams, fz: f64) -> Patch {
        let a = half_length(fz, p.r0, p.cz, p.q_ra1, p.q_ra2);
        let m = p.points.clamp(1, M_MAX);
        let mut pts = [Point::default(); M_MAX];
        let delta = if a > 0.0 {
            discretise(a, fz, p.pressure_n, m, &mut pts)
        } else {
            0.0
        };
        Patch { pts, m, delta, a }
    }
}

/// Friction coefficients (μs, μk) at load `fz` and friction scale `s`:
/// μ = MU·(1 + MU_DFZ·dfz), dfz = (Fz − Fz0)/Fz0 (the MF's first-order load
/// dependence of D, Pacejka 3rd ed. eq. 4.E23 with PDY2), kept ≥ 0.1·MU.
pub fn friction(p: &BrushParams, fz: f64, s: f64) -> (f64, f64) {
    let dfz = (fz - p.fz0) / p.fz0;
    let g = (1.0 + p.mu_dfz * dfz).max(0.1);
    let s = if s > 0.0 && s.is_finite() { s } else { 1.0 };
    (s * p.mu_s * g, s * p.mu_k * g)
}

/// Solve `a·x = b` in place for the n×n row-major matrix `a` (Gaussian
/// elimination with partial pivoting); `b` becomes x. A zero pivot leaves the
/// unknown at 0 (cannot happen for I + K·He with the physical parameters:
/// the matrix is close to diagonally dominant).
fn gauss(a: &mut [f64], b: &mut [f64], n: usize) {
    for k in 0..n {
        let mut piv = k;
        let mut best = a[k * n + k].abs();
        for r in k + 1..n {
            let v = a[r * n + k].abs();
            if v > best {
                best = v;
                piv = r;
            }
        }
        if best == 0.0 {
            continue;
        }
        if piv != k {
            for c in 0..n {
                a.swap(k * n + c, piv * n + c);
            }
            b.swap(k, piv);
        }
        let d = a[k * n + k];
        for r in k + 1..n {
            let f = a[r * n + k] / d;
            if f != 0.0 {
                for c in k..n {
                    a[r * n + c] -= f * a[k * n + c];
                }
                b[r] -= f * b[k];
            }
        }
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for c in k + 1..n {
            s -= a[k * n + c] * b[c];
        }
        let d = a[k * n + k];
        b[k] = if d != 0.0 { s / d } else { 0.0 };
    }
}

/// Workspace of one evaluation (stack).
struct Work {
    /// exp(−k·Δ/σ_c), k = 0..M.
    r: [f64; M_MAX],
    /// exp(−s_j/σ_c).
    q: [f64; M_MAX],
    mat: [f64; M_MAX * M_MAX],
}

/// Lateral forces of the adhesion block 0..n (carcass `c`), the rest sliding
/// with `fy[n..m]` already set: (I + K·He_AA)·f_A = K·(d_A − He_AS·f_S).
fn solve_adhesion(
    w: &mut Work,
    c: &StringCarcass,
    patch: &Patch,
    ky: f64,
    sy: f64,
    n: usize,
    fy: &mut [f64; M_MAX],
) {
    let m = patch.m;
    let he = |w: &Work, i: usize, j: usize| c.h * (w.r[i.abs_diff(j)] - w.q[j]);
    for i in 0..n {
        let mut rhs = patch.pts[i].s * sy;
        for j in n..m {
            rhs -= he(w, i, j) * fy[j];
        }
        fy[i] = ky * rhs;
        for j in 0..n {
            let v = ky * he(w, i, j) + if i == j { 1.0 } else { 0.0 };
            w.mat[i * n + j] = v;
        }
    }
    gauss(&mut w.mat[..n * n], &mut fy[..n], n);
}

/// Whether adhesion points 0..n hold with the static limit.
fn holds(patch: &Patch, fx: &[f64; M_MAX], fy: &[f64; M_MAX], mu_s: f64, n: usize) -> bool {
    (0..n).all(|i| fx[i].hypot(fy[i]) <= mu_s * patch.pts[i].pz * (1.0 + 1e-12))
}

/// The brush model at one operating point (module docs).
pub fn evaluate(p: &BrushParams, inp: &BrushInput) -> BrushForces {
    let fz = inp.fz;
    if !(fz > 0.0 && fz.is_finite()) {
        return BrushForces::default();
    }
    let patch = Patch::new(p, fz);
    evaluate_on(p, &patch, inp)
}

/// `evaluate` on a given patch (the fitter and the study reuse one patch per load).
pub fn evaluate_on(p: &BrushParams, patch: &Patch, inp: &BrushInput) -> BrushForces {
    let (mu_s, mu_k) = friction(p, inp.fz, inp.mu_scale);
    let m = patch.m;
    let mut out = BrushForces {
        a: patch.a,
        mu_k,
        ..Default::default()
    };
    if patch.a <= 0.0 {
        return out;
    }
    // Theoretical slips; at 1 + κ ≤ 0 (locked or reversed contact) the whole
    // patch slides along (κ, tan α).
    let den = 1.0 + inp.kappa;
    let locked = den <= 1e-9;
    let (sx, sy) = if locked {
        (0.0, 0.0)
    } else {
        (inp.kappa / den, inp.tan_alpha / den)
    };
    let dir = inp.kappa.hypot(inp.tan_alpha);
    if !(dir > 0.0) {
        return out;
    }
    let (ex, ey) = (inp.kappa / dir, inp.tan_alpha / dir);
    let kx = p.cpx * patch.delta;
    let ky = p.cpy * patch.delta;
    let mut fx = [0.0; M_MAX];
    let mut fy = [0.0; M_MAX];
    let slide = |i: usize| (mu_k * patch.pts[i].pz * ex, mu_k * patch.pts[i].pz * ey);
    let carcass = p.carcass();
    let n = if locked {
        0
    } else if carcass.rigid() {
        // One pass: adhesion up to the first point over the static limit.
        let mut n = m;
        for i in 0..m {
            let s = patch.pts[i].s;
            let (ax, ay) = (kx * s * sx, ky * s * sy);
            if ax.hypot(ay) > mu_s * patch.pts[i].pz * (1.0 + 1e-12) {
                n = i;
                break;
            }
            fx[i] = ax;
            fy[i] = ay;
        }
        n
    } else {
        for i in 0..m {
            fx[i] = kx * patch.pts[i].s * sx;
        }
        let mut w = Work {
            r: [0.0; M_MAX],
            q: [0.0; M_MAX],
            mat: [0.0; M_MAX * M_MAX],
        };
        let e = (-patch.delta / carcass.sigma_c).exp();
        let mut rk = 1.0;
        for k in 0..m {
            w.r[k] = rk;
            rk *= e;
            w.q[k] = (-patch.pts[k].s / carcass.sigma_c).exp();
        }
        let mut trial = [0.0; M_MAX];
        let mut run = |n: usize, fy: &mut [f64; M_MAX], solves: &mut usize| {
            for j in n..m {
                fy[j] = slide(j).1;
            }
            if n > 0 {
                solve_adhesion(&mut w, &carcass, patch, ky, sy, n, fy);
                *solves += 1;
            }
        };
        run(m, &mut fy, &mut out.solves);
        if holds(patch, &fx, &fy, mu_s, m) {
            m
        } else {
            let (mut lo, mut hi) = (0usize, m);
            run(0, &mut fy, &mut out.solves);
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                run(mid, &mut trial, &mut out.solves);
                if holds(patch, &fx, &trial, mu_s, mid) {
                    lo = mid;
                    fy = trial;
                } else {
                    hi = mid;
                }
            }
            lo
        }
    };
    for i in n..m {
        (fx[i], fy[i]) = slide(i);
    }
    out.adhesion = n;
    let (mut sfx, mut sfy, mut mz) = (0.0, 0.0, 0.0);
    for i in 0..m {
        sfx += fx[i];
        sfy += fy[i];
        // Moment of the lateral force about the centre, plus the longitudinal
        // force on the tread's lateral deflection f_y/k_y (Pacejka 3rd ed. §3.2.3).
        mz += fy[i] * (patch.pts[i].s - patch.a);
        if ky > 0.0 {
            mz += fx[i] * fy[i] / ky;
        }
    }
    out.fx = sfx;
    out.fy = -sfy;
    out.mz = mz;
    out
}

/// Cornering stiffness C_y = ∂Fy/∂tan α at α = κ = 0 (N/rad, magnitude): the
/// full-adhesion solution for σy = 1, Σ_i [(I + K·He)⁻¹·K·s]_i (the paper's
/// eq. 14).
pub fn cornering_stiffness_on(p: &BrushParams, patch: &Patch) -> f64 {
    let big = 1e12; // no point reaches the friction limit
    let q = BrushParams {
        mu_s: big,
        mu_k: big,
        mu_dfz: 0.0,
        ..*p
    };
    let f = evaluate_on(
        &q,
        patch,
        &BrushInput {
            fz: p.fz0,
            kappa: 0.0,
            tan_alpha: 1.0,
            mu_scale: 1.0,
        },
    );
    -f.fy
}

/// Longitudinal slip stiffness C_κ = ∂Fx/∂κ at zero slip (N): c_px·Δ·Σ s_i = 2·c_px·a².
pub fn slip_stiffness_on(p: &BrushParams, patch: &Patch) -> f64 {
    p.cpx * patch.delta * patch.pts[..patch.m].iter().map(|q| q.s).sum::<f64>()
}
