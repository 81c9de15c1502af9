//! Shared test problems for the fit tests: a 1-D curve fit y = f(θ, x) with an
//! analytic gradient, which records every θ it was evaluated at.
#![allow(clippy::needless_range_loop)]
#![allow(dead_code)]

use nalgebra::DMatrixViewMut;
use std::cell::RefCell;
use tyrekit::fit::{Param, Problem};

pub type Model = fn(&[f64], f64) -> f64;
pub type Grad = fn(&[f64], f64, &mut [f64]);

pub struct Curve {
    pub params: Vec<Param>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub w: Option<Vec<f64>>,
    pub model: Model,
    pub grad: Grad,
    /// Every θ the fitter asked for.
    pub seen: RefCell<Vec<Vec<f64>>>,
}

impl Curve {
    pub fn new(params: Vec<Param>, x: Vec<f64>, y: Vec<f64>, model: Model, grad: Grad) -> Curve {
        Curve {
            params,
            x,
            y,
            w: None,
            model,
            grad,
            seen: RefCell::new(Vec::new()),
        }
    }
}

impl Problem for Curve {
    fn params(&self) -> &[Param] {
        &self.params
    }
    fn n_residuals(&self) -> usize {
        self.x.len()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        self.seen.borrow_mut().push(theta.to_vec());
        for i in 0..self.x.len() {
            r[i] = (self.model)(theta, self.x[i]) - self.y[i];
        }
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        self.seen.borrow_mut().push(theta.to_vec());
        let mut g = vec![0.0; theta.len()];
        for i in 0..self.x.len() {
            r[i] = (self.model)(theta, self.x[i]) - self.y[i];
            (self.grad)(theta, self.x[i], &mut g);
            for (k, &c) in cols.iter().enumerate() {
                jac[(i, k)] = g[c];
            }
        }
    }
    fn weights(&self) -> Option<&[f64]> {
        self.w.as_deref()
    }
}

/// Deterministic pseudo-noise in [-1, 1] (a fixed LCG, so tests need no RNG crate state).
pub fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

pub fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

/// y = a·exp(−b·x) + c
pub fn exp_model(t: &[f64], x: f64) -> f64 {
    t[0] * (-t[1] * x).exp() + t[2]
}
pub fn exp_grad(t: &[f64], x: f64, g: &mut [f64]) {
    let e = (-t[1] * x).exp();
    g[0] = e;
    g[1] = -t[0] * x * e;
    g[2] = 1.0;
}

/// y = D·sin(C·atan(B·x))   (θ = [B, C, D])
pub fn sinatan_model(t: &[f64], x: f64) -> f64 {
    t[2] * (t[1] * (t[0] * x).atan()).sin()
}
pub fn sinatan_grad(t: &[f64], x: f64, g: &mut [f64]) {
    let (b, c, d) = (t[0], t[1], t[2]);
    let at = (b * x).atan();
    let cs = (c * at).cos();
    g[0] = d * cs * c * x / (1.0 + b * b * x * x);
    g[1] = d * cs * at;
    g[2] = (c * at).sin();
}

/// y = a + b·x
pub fn line_model(t: &[f64], x: f64) -> f64 {
    t[0] + t[1] * x
}
pub fn line_grad(_t: &[f64], x: f64, g: &mut [f64]) {
    g[0] = 1.0;
    g[1] = x;
}
