//! validity — the Magic Formula's validity conditions as a part of the
//! least-squares problem, so a fitted tyre is valid by construction over the
//! data's range of load, inclination and pressure (issue #14 item 1):
//!
//! - every curvature factor E ≤ 1 − [`MARGIN`]: Ex (Pacejka, *Tyre and
//!   Vehicle Dynamics*, 3rd ed., eq. 4.E14) at sgn κx = ±1, Ey (4.E24) at
//!   sgn αy = ±1, Et (4.E44) at both ends of its arctangent term (±1: the
//!   bound holds for every slip angle), Exα (4.E56) and Eyκ (4.E64);
//! - the friction coefficients μx (4.E13) and μy (4.E23) ≥ [`MU_MIN`] (the
//!   peak D keeps the sign of the load; use mode 1xx would take |μy|).
//!
//! Bounds of single coefficients (C ≥ 0.8, PKY1 < 0, RCX1, RCY1 ≤ 1 …) stay
//! in the stage tables; what depends on load, inclination and pressure
//! together is checked here on a grid spanning the data ([`Grid`]).
//! Each (condition, grid point) is one residual row
//! `w · max(0, g(θ) − bound)`: zero while the condition holds, so it does
//! not bias a fit that satisfies it, and with w large (a violation of 0.01
//! costs as much as the whole signal, [`Validity::new`]) the optimum keeps it
//! to well below the margin. The use-mode-1xx caps (E clamped to 1) then
//! never act on the data range, and use modes 111 and 211 give the same
//! forces there.
//!
//! Must never: clamp a value after the fit, approximate a derivative by
//! finite differences, or add rows for conditions none of the stage's free
//! parameters can change.

use super::problem::{Param, Problem, RowJacobian};
use crate::mf::Form;
use crate::tir::MfParams;
use nalgebra::DMatrixViewMut;

/// Distance kept from the E ≤ 1 bound.
pub const MARGIN: f64 = 0.01;
/// Smallest friction coefficient allowed over the data range.
pub const MU_MIN: f64 = 0.05;

/// The data range the conditions hold on: loads, inclinations (rad) and
/// pressures (Pa; empty: the file's NOMPRES).
#[derive(Clone, Debug, Default)]
pub struct Grid {
    /// Normal loads (N).
    pub fz: Vec<f64>,
    /// Inclination angles (rad).
    pub gamma: Vec<f64>,
    /// Inflation pressures (Pa); empty: the file's NOMPRES only.
    pub p: Vec<f64>,
}

impl Grid {
    /// A grid over `[lo, hi]` of each quantity (non-finite ends are left
    /// out): 9 loads (E is at most quadratic in the load, so its maximum lies
    /// at an end, at a vertex, or between grid points within a few 1e-3 of
    /// the margin), the inclination's ends and 0 when inside, the
    /// pressure's ends.
    pub fn spanning(fz: (f64, f64), gamma: (f64, f64), p: (f64, f64)) -> Grid {
        let lin = |(a, b): (f64, f64), n: usize| -> Vec<f64> {
            if !(a.is_finite() && b.is_finite()) || b < a {
                return Vec::new();
            }
            if b == a || n < 2 {
                return vec![a];
            }
            (0..n)
                .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
                .collect()
        };
        let mut g = lin(gamma, 2);
        if gamma.0 < 0.0 && gamma.1 > 0.0 {
            g.push(0.0);
        }
        Grid {
            fz: lin(fz, 9),
            gamma: g,
            p: lin(p, 2),
        }
    }
}

/// One validity condition g(θ) ≤ bound.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Ex(f64),
    Ey(f64),
    Et(f64),
    Exa,
    Eyk,
    MuX,
    MuY,
}

impl Kind {
    /// The keys g depends on.
    fn keys(self) -> &'static [&'static str] {
        match self {
            Kind::Ex(_) => &["pex1", "pex2", "pex3", "pex4"],
            Kind::Ey(_) => &["pey1", "pey2", "pey3", "pey4", "pey5"],
            Kind::Et(_) => &["qez1", "qez2", "qez3", "qez4", "qez5"],
            Kind::Exa => &["rex1", "rex2"],
            Kind::Eyk => &["rey1", "rey2"],
            Kind::MuX => &["pdx1", "pdx2", "ppx3", "ppx4", "pdx3"],
            Kind::MuY => &["pdy1", "pdy2", "ppy3", "ppy4", "pdy3"],
        }
    }
    fn all() -> Vec<Kind> {
        vec![
            Kind::Ex(1.0),
            Kind::Ex(-1.0),
            Kind::Ey(1.0),
            Kind::Ey(-1.0),
            Kind::Et(1.0),
            Kind::Et(-1.0),
            Kind::Exa,
            Kind::Eyk,
            Kind::MuX,
            Kind::MuY,
        ]
    }
    fn bound(self) -> f64 {
        match self {
            Kind::MuX | Kind::MuY => -MU_MIN,
            _ => 1.0 - MARGIN,
        }
    }
}

/// A grid point: load deviation dfz (4.E2a), pressure deviation dpi
/// (4.E2b), inclination γ with the form's scaling per channel.
#[derive(Clone, Copy, Debug)]
struct Point {
    dfz: f64,
    dpi: f64,
    gx: f64,
    gy: f64,
    gz: f64,
}

/// g(θ) and ∂g/∂key (in the order of [`Kind::keys`]).
fn eval(kind: Kind, p: &MfParams<f64>, x: &Point) -> (f64, [f64; 5]) {
    let d = x.dfz;
    match kind {
        Kind::Ex(s) => {
            let a = p.pex1 + p.pex2 * d + p.pex3 * d * d;
            let b = 1.0 - p.pex4 * s;
            let l = p.lex;
            (
                a * b * l,
                [b * l, d * b * l, d * d * b * l, -s * a * l, 0.0],
            )
        }
        Kind::Ey(s) => {
            let g = x.gy;
            let a = p.pey1 + p.pey2 * d;
            let b = 1.0 + p.pey5 * g * g - (p.pey3 + p.pey4 * g) * s;
            let l = p.ley;
            (
                a * b * l,
                [b * l, d * b * l, -s * a * l, -s * g * a * l, g * g * a * l],
            )
        }
        Kind::Et(u) => {
            let g = x.gz;
            let a = p.qez1 + p.qez2 * d + p.qez3 * d * d;
            let b = 1.0 + (p.qez4 + p.qez5 * g) * u;
            (a * b, [b, d * b, d * d * b, a * u, a * u * g])
        }
        Kind::Exa => (p.rex1 + p.rex2 * d, [1.0, d, 0.0, 0.0, 0.0]),
        Kind::Eyk => (p.rey1 + p.rey2 * d, [1.0, d, 0.0, 0.0, 0.0]),
        Kind::MuX | Kind::MuY => {
            let (d1, d2, p3, p4, d3, g, l) = if kind == Kind::MuX {
                (p.pdx1, p.pdx2, p.ppx3, p.ppx4, p.pdx3, x.gx, p.lmux)
            } else {
                (p.pdy1, p.pdy2, p.ppy3, p.ppy4, p.pdy3, x.gy, p.lmuy)
            };
            let a = d1 + d2 * d;
            let pi = x.dpi;
            let b = 1.0 + p3 * pi + p4 * pi * pi;
            let c = 1.0 - d3 * g * g;
            // g = −μ (≤ −MU_MIN).
            (
                -a * b * c * l,
                [
                    -b * c * l,
                    -d * b * c * l,
                    -a * pi * c * l,
                    -a * pi * pi * c * l,
                    a * b * g * g * l,
                ],
            )
        }
    }
}

/// The validity conditions of a stage as a [`Problem`] over the stage's
/// parameter table (stack it with the stage's channels).
pub struct Validity {
    params: Vec<Param>,
    /// Key index in [`MfParams::as_slice`] order of every θ entry.
    keys: Vec<usize>,
    base: MfParams<f64>,
    /// (condition, grid point, θ column of each of the condition's keys).
    rows: Vec<(Kind, Point, [Option<usize>; 5])>,
    weight: f64,
}

impl Validity {
    /// The conditions touched by a free parameter of `params`, on `grid`,
    /// from `base` (whose FNOMIN, NOMPRES and scaling factors define dfz,
    /// dpi and the λs). `energy` is the stage's weighted measured energy
    /// Σ w y²: a violation δ costs 1e4·energy·δ², as much as the whole
    /// signal at δ = 0.01.
    pub fn new(
        form: Form,
        base: &MfParams<f64>,
        params: &[Param],
        grid: &Grid,
        energy: f64,
    ) -> crate::Result<Validity> {
        let keys = params
            .iter()
            .map(|p| {
                crate::tir::keys::key_index(&p.name).ok_or_else(|| {
                    crate::Error::Input(format!("fit: '{}' is not a .tir key", p.name))
                })
            })
            .collect::<crate::Result<Vec<_>>>()?;
        let fz0 = base.fnomin * base.lfzo;
        let (lx, ly, lz) = if form == Form::Pac2002 {
            (base.lgax, base.lgay, base.lgaz)
        } else {
            (1.0, 1.0, 1.0)
        };
        let pres = if grid.p.is_empty() {
            vec![base.nompres]
        } else {
            grid.p.clone()
        };
        let gams = if grid.gamma.is_empty() {
            vec![0.0]
        } else {
            grid.gamma.clone()
        };
        let mut points = Vec::new();
        for &fz in &grid.fz {
            for &g in &gams {
                for &pr in &pres {
                    points.push(Point {
                        dfz: (fz - fz0) / fz0,
                        dpi: if base.nompres > 0.0 {
                            (pr - base.nompres) / base.nompres
                        } else {
                            0.0
                        },
                        gx: g * lx,
                        gy: g * ly,
                        gz: g * lz,
                    });
                }
            }
        }
        let mut rows = Vec::new();
        for kind in Kind::all() {
            let mut cols = [None; 5];
            for (k, name) in kind.keys().iter().enumerate() {
                cols[k] = params
                    .iter()
                    .position(|p| p.name.eq_ignore_ascii_case(name));
            }
            if !cols.iter().flatten().any(|&c| params[c].free) {
                continue;
            }
            // A pressure-free condition needs one pressure only.
            let needs_p = matches!(kind, Kind::MuX | Kind::MuY);
            let mut seen = Vec::new();
            for x in &points {
                let key = (x.dfz, x.gx, if needs_p { x.dpi } else { 0.0 });
                if seen.contains(&key) {
                    continue;
                }
                seen.push(key);
                rows.push((kind, *x, cols));
            }
        }
        Ok(Validity {
            params: params.to_vec(),
            keys,
            base: base.clone(),
            rows,
            weight: 100.0 * energy.max(1e-12).sqrt(),
        })
    }

    fn params_at(&self, theta: &[f64]) -> MfParams<f64> {
        super::mf_stages::params_with(&self.base, &self.keys, theta)
    }

    /// The largest g − bound over the grid (≤ 0: every condition holds) and
    /// the condition it belongs to, in words.
    pub fn worst(&self, theta: &[f64]) -> Option<(f64, String)> {
        let p = self.params_at(theta);
        self.rows
            .iter()
            .map(|(k, x, _)| {
                (
                    eval(*k, &p, x).0 - k.bound(),
                    format!("{k:?} at dfz {:.2}", x.dfz),
                )
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// The rows of a [`Validity`] at one θ.
struct Rows<'s> {
    v: &'s Validity,
    p: MfParams<f64>,
    cols: Vec<usize>,
}

impl RowJacobian for Rows<'_> {
    fn rows(&self, first: usize, r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        for (k, rk) in r.iter_mut().enumerate() {
            let (kind, x, kc) = &self.v.rows[first + k];
            let (g, dg) = eval(*kind, &self.p, x);
            let over = g - kind.bound();
            *rk = self.v.weight * over.max(0.0);
            for (j, &c) in self.cols.iter().enumerate() {
                jac[(k, j)] = 0.0;
                if over > 0.0 {
                    for (l, kcl) in kc.iter().enumerate() {
                        if *kcl == Some(c) {
                            jac[(k, j)] = self.v.weight * dg[l];
                        }
                    }
                }
            }
        }
    }
}

impl Problem for Validity {
    fn params(&self) -> &[Param] {
        &self.params
    }
    fn n_residuals(&self) -> usize {
        self.rows.len()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        let p = self.params_at(theta);
        for (rk, (kind, x, _)) in r.iter_mut().zip(&self.rows) {
            *rk = self.weight * (eval(*kind, &p, x).0 - kind.bound()).max(0.0);
        }
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        if let Some(rows) = self.row_jacobian(theta, cols) {
            rows.rows(0, r, jac);
        }
    }
    fn row_jacobian<'s>(
        &'s self,
        theta: &[f64],
        cols: &[usize],
    ) -> Option<Box<dyn RowJacobian + 's>> {
        Some(Box::new(Rows {
            v: self,
            p: self.params_at(theta),
            cols: cols.to_vec(),
        }))
    }
}
