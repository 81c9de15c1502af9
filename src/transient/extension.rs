//! extension — physics beyond the steady Magic Formula that the diagnosis can
//! name and fit, read once from the tyre file (at [`crate::mf::Tyre::new`])
//! and applied inside [`super::TransientModel::step`] — the code the FMU and
//! `replay` run — through one hook: a friction scale `s` and a slip-stiffness
//! scale `c` per step, applied with the similarity method (Pacejka, *Tyre and
//! Vehicle Dynamics*, 3rd ed., §4.3.2): F(κ) → s·F(c·κ/s), i.e. peak × s,
//! slip stiffness × c (`StepCtx::forces`, [`super::mf_at`]).
//!
//! The scales are a product of:
//! * **load sensitivity of general shape** (`[LOAD_SENSITIVITY]`, keys
//!   `FZ1`…`FZ5` (N, increasing), `MU_FZ1`…, `K_FZ1`…, `MZ_FZ1`… (–)):
//!   multipliers of friction, slip stiffness and aligning moment over the
//!   load range, s = 1 + MU(Fz), c = 1 + K(Fz), Mz × (1 + MZ(Fz)), each a
//!   natural cubic spline through the knots (Fz_i, MU_FZi) … (smooth, of no
//!   fixed shape: it can rise, fall, level off or peak between knots) and
//!   constant beyond the outer knots (no extrapolation past the loads the
//!   data had) — a curve of any shape the
//!   knots resolve, where the MF's own load forms (PDY2, PKY1–2, QDZ2 …:
//!   Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., eqs. 4.E13–4.E40) fix it
//!   to low-order functions of dfz. MZ scales the moment on top of the
//!   similarity scaling (the pneumatic trail and residual moment of that
//!   load): the data of a tyre whose cornering stiffness departs from the MF
//!   form show Mz departing differently from Fy.
//!   The older polynomial keys `MU_DFZ1`, `MU_DFZ2`, `K_DFZ1` (corrections
//!   in dfz = (Fz − Fz0)/Fz0, s = 1 + MU_DFZ1·dfz + MU_DFZ2·dfz²,
//!   c = 1 + K_DFZ1·dfz) are still read, and multiply with the curves.
//! * **sliding-speed friction** (the MF's own `LMUV` with `LONGVL` = V0):
//!   s = 1/(1 + LMUV·Vs/V0), Vs = |Vx|·√(κ² + tan²α) the sliding speed
//!   (MF 6.1, Pacejka 3rd ed. eq. 4.E7: λμ* = λμ/(1 + λμV·Vs/V0)). The
//!   steady [`crate::mf::Tyre::evaluate`] does not apply LMUV (MFeval 4.0
//!   does not either, and no reference file sets it); the step does.
//! * **sliding-speed friction of general monotone shape**
//!   (`[SPEED_FRICTION]`, keys `DMU` –, `VC` m/s, `MU0` –, `VREF` m/s):
//!   s = (1 + MU0)·g(Vs)/g(σ·VREF), g(v) = 1 − DMU·x/(1 + x), x = v/VC,
//!   σ = √(κ² + tan²α) the slip magnitude — a friction that changes monotonically with the sliding
//!   speed and levels off at 1 − DMU: the shape of the Stribeck-type
//!   friction laws, μ(v) = μk + (μs − μk)·g(v/vs) with g falling from 1
//!   to 0 (the LuGre model's g, Canudas de Wit et al., *IEEE Trans. Autom.
//!   Control* 40(3), 1995), written as one rational step so it is smooth
//!   and cheap. It contains the LMUV form above as DMU = 1,
//!   VC = V0/LMUV, and a saturating fall (DMU < 1) the LMUV form cannot
//!   give; DMU < 0 is a friction that rises with the sliding speed. MU0
//!   (default 0) is the friction level at zero sliding speed relative to
//!   the file's: a Magic Formula fitted to data that carry the speed law
//!   already holds its average, so the law must be free to turn about it.
//!   VREF (default 0) is the belt speed at which the file's Magic Formula
//!   already holds the law: a Magic Formula fitted at belt speed V holds
//!   g(σ·V) at every slip σ (its peak, curvature and fall after the peak
//!   have absorbed it), so the same tyre at another belt speed V' sees the
//!   ratio g(σ·V')/g(σ·V). VREF = 0 is the file's friction as the one at
//!   zero sliding speed (a Magic Formula measured without the effect, or
//!   the law written over a static friction); at Vx = VREF the scale is
//!   1 + MU0 at every slip.
//! * **tread temperature** (`[THERMAL]`, keys `CAPACITY` J/K, `COOLING` W/K,
//!   `SHARE` –, `MU_T0`, `MU_T1`, `MU_T2` –; temperatures relative to the
//!   ambient air): a lumped heat balance C·dT/dt = q·P − h·(T − Tamb) with
//!   P = |Fx·Vsx| + |Fy·Vsy| the frictional power (the thermal models of
//!   Sorniotti 2009 / the TRT family reduced to one node), and the friction
//!   s = 1 + MU_T0 + MU_T1·x + MU_T2·x², x = (T − Tamb)/50 K. The state
//!   ΔT = T − Tamb is slot [`SLOT_TEMP`] of the transient state (so it is
//!   part of fmi2GetFMUstate, and reset restores the ambient); it is updated
//!   exactly for the power of the step held (explicit in the coupling).
//!
//! Pressure, camber and the rolling radius need no hook: they are the MF's
//! own keys (PPX*/PPY*, the camber terms, Q_RE0/FREFF of Re(Fz)).
//!
//! # The transient model a file asks for
//! `[TYREKIT]` `TRANSIENT = 'relaxation'` (or `'lugre'`, `'steady'`) names
//! the transient model the file's physics needs ([`file_transient`]): a
//! relaxation or LuGre finding of `tyrekit diagnose` writes it into
//! `extended.tir`, and the FMU's `transient = "file"` (its default) and
//! `tyrekit replay` without `--transient` run that model. A file without
//! the key runs `steady`. The standard `USE_MODE` key (ADAMS' tyre-use
//! switch: 4, 14, 114, 124, 2 in the shared files) is not read for this:
//! files that carry it keep today's behaviour.
//!
//! Must never: change anything for a tyre without these keys (the hook is
//! `None`, the outputs stay bit-identical), allocate, or return a
//! non-positive scale.

use super::{Kinematics, TransientState, WheelOutput};
use crate::tir::TyreParams;

/// Slot of the tread temperature rise ΔT = T − Tamb (K) in `TransientState::x`.
pub const SLOT_TEMP: usize = 3;
/// Section of the load-sensitivity corrections.
pub const LOAD_SECTION: &str = "LOAD_SENSITIVITY";
/// Polynomial keys of [`LOAD_SECTION`] (read, no longer written by the diagnosis).
pub const LOAD_KEYS: [&str; 3] = ["MU_DFZ1", "MU_DFZ2", "K_DFZ1"];
/// Most knots of the load curves ([`LoadCurve`]).
pub const LOAD_KNOTS: usize = 5;
/// Knot loads of [`LOAD_SECTION`] (N, strictly increasing, > 0; the first
/// missing key ends the list, at least two when any is given).
pub const LOAD_FZ_KEYS: [&str; LOAD_KNOTS] = ["FZ1", "FZ2", "FZ3", "FZ4", "FZ5"];
/// Relative friction change at each knot (–, default 0).
pub const LOAD_MU_KEYS: [&str; LOAD_KNOTS] = ["MU_FZ1", "MU_FZ2", "MU_FZ3", "MU_FZ4", "MU_FZ5"];
/// Relative slip-stiffness change at each knot (–, default 0).
pub const LOAD_K_KEYS: [&str; LOAD_KNOTS] = ["K_FZ1", "K_FZ2", "K_FZ3", "K_FZ4", "K_FZ5"];
/// Relative aligning-moment change at each knot (–, default 0).
pub const LOAD_MZ_KEYS: [&str; LOAD_KNOTS] = ["MZ_FZ1", "MZ_FZ2", "MZ_FZ3", "MZ_FZ4", "MZ_FZ5"];
/// Section of the sliding-speed friction of general shape.
pub const SPEED_SECTION: &str = "SPEED_FRICTION";
/// Keys of [`SPEED_SECTION`]: the friction change at high sliding speed
/// (DMU, –), the sliding speed of half of it (VC, m/s), the level at
/// zero sliding speed (MU0, –, optional, 0) and the belt speed at which
/// the file's Magic Formula holds the law (VREF, m/s, optional, 0).
pub const SPEED_KEYS: [&str; 4] = ["DMU", "VC", "MU0", "VREF"];
/// Section of the tread-temperature model.
pub const THERMAL_SECTION: &str = "THERMAL";
/// Keys of [`THERMAL_SECTION`].
pub const THERMAL_KEYS: [&str; 6] = ["CAPACITY", "COOLING", "SHARE", "MU_T0", "MU_T1", "MU_T2"];
/// The project's own section of the tyre file (settings, not physics).
pub const PROJECT_SECTION: &str = "TYREKIT";
/// Key of [`PROJECT_SECTION`]: the transient model the file needs
/// (`'steady'`, `'relaxation'` or `'lugre'`; see the module docs).
pub const TRANSIENT_KEY: &str = "TRANSIENT";

/// The transient model the file asks for ([`TRANSIENT_KEY`]), None when it
/// says nothing. Errors name the file, key and accepted values.
pub fn file_transient(t: &TyreParams) -> crate::Result<Option<super::TransientKind>> {
    let Some(v) = t.extra(PROJECT_SECTION, TRANSIENT_KEY) else {
        return Ok(None);
    };
    let text = v.as_str().unwrap_or("");
    super::TransientKind::parse(text)
        .map(Some)
        .ok_or_else(|| crate::Error::Tir {
            file: t.source.clone(),
            line: 0,
            key: TRANSIENT_KEY.into(),
            message: format!(
                "[{PROJECT_SECTION}] {TRANSIENT_KEY} = {v:?}: expected 'steady', 'relaxation' or 'lugre'"
            ),
        })
}

/// Write the transient model `kind` into the file's [`PROJECT_SECTION`].
pub fn set_file_transient(t: &mut TyreParams, kind: super::TransientKind) {
    t.set_string(PROJECT_SECTION, TRANSIENT_KEY, kind.name());
}

/// Temperature scale of the friction polynomial (K).
pub const T_SCALE: f64 = 50.0;
/// Smallest scale the hook returns (a guard, not physics).
const S_MIN: f64 = 0.05;

/// The lumped tread-temperature model (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thermal {
    /// Heat capacity of the tread layer C (J/K).
    pub capacity: f64,
    /// Heat loss to air and carcass h (W/K).
    pub cooling: f64,
    /// Share q of the frictional power heating the tread (–).
    pub share: f64,
    /// Friction polynomial in x = ΔT/50 K: `s = 1 + mu[0] + mu[1]·x + mu[2]·x²`.
    pub mu: [f64; 3],
}

impl Thermal {
    /// Friction scale at a temperature rise `dt_k` (K).
    #[inline]
    pub fn friction(&self, dt_k: f64) -> f64 {
        let x = dt_k / T_SCALE;
        1.0 + self.mu[0] + self.mu[1] * x + self.mu[2] * x * x
    }
    /// Time constant C/h (s).
    pub fn time_constant(&self) -> f64 {
        self.capacity / self.cooling
    }
}

/// Friction scale of the sliding-speed law of general shape at sliding
/// speed `vs` (m/s) without its level: 1 − DMU·x/(1 + x), x = Vs/VC (see
/// the module docs).
#[inline]
pub fn speed_friction(dmu: f64, vc: f64, vs: f64) -> f64 {
    let x = vs.abs() / vc;
    1.0 - dmu * x / (1.0 + x)
}

/// The sliding-speed friction law of [`SPEED_SECTION`] (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedLaw {
    /// Friction change at high sliding speed (–, < 1).
    pub dmu: f64,
    /// Sliding speed of half the change (m/s, > 0).
    pub vc: f64,
    /// Level at zero sliding speed relative to the file's (–, > −1).
    pub mu0: f64,
    /// Belt speed at which the file's Magic Formula holds the law (m/s, ≥ 0).
    pub vref: f64,
}

impl SpeedLaw {
    /// Friction scale at forward speed `vx_abs` (m/s) and slip magnitude
    /// `slip` = √(κ² + tan²α): (1 + MU0)·g(Vs)/g(slip·VREF), Vs = vx_abs·slip.
    #[inline]
    pub fn scale(&self, vx_abs: f64, slip: f64) -> f64 {
        let g = |v: f64| speed_friction(self.dmu, self.vc, v);
        (1.0 + self.mu0) * g(vx_abs * slip) / g(self.vref * slip)
    }
}

/// Multipliers of friction, slip stiffness and aligning moment over the
/// load: natural cubic splines through the knots (see the module docs),
/// constant beyond the outer knots. Fixed-size: no allocation in the step.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct LoadCurve {
    /// Number of knots in use (2..=[`LOAD_KNOTS`]).
    pub n: usize,
    /// Knot loads (N), strictly increasing.
    pub fz: [f64; LOAD_KNOTS],
    /// Relative friction change at each knot.
    pub mu: [f64; LOAD_KNOTS],
    /// Relative slip-stiffness change at each knot.
    pub k: [f64; LOAD_KNOTS],
    /// Relative aligning-moment change at each knot.
    pub mz: [f64; LOAD_KNOTS],
    /// The splines' second derivatives at the knots (mu, k, mz), from [`LoadCurve::new`].
    d2: [[f64; LOAD_KNOTS]; 3],
}

/// Second derivatives of the natural cubic spline through (x, y)[..n]
/// (zero at both ends; the tridiagonal system solved by the Thomas
/// algorithm; de Boor, *A Practical Guide to Splines*, 1978, ch. IV).
fn natural_d2(x: &[f64; LOAD_KNOTS], y: &[f64; LOAD_KNOTS], n: usize) -> [f64; LOAD_KNOTS] {
    let mut m = [0.0; LOAD_KNOTS];
    if n < 3 {
        return m;
    }
    let (mut c, mut d) = ([0.0; LOAD_KNOTS], [0.0; LOAD_KNOTS]);
    for i in 1..n - 1 {
        let (h0, h1) = (x[i] - x[i - 1], x[i + 1] - x[i]);
        let r = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
        let b = 2.0 * (h0 + h1) - if i > 1 { h0 * c[i - 1] } else { 0.0 };
        c[i] = h1 / b;
        d[i] = (r - if i > 1 { h0 * d[i - 1] } else { 0.0 }) / b;
    }
    for i in (1..n - 1).rev() {
        m[i] = d[i] - c[i] * m[i + 1];
    }
    m
}

impl LoadCurve {
    /// Curves through the knots `fz` (N, strictly increasing, 2..=5) with
    /// the relative changes `mu`, `k`, `mz` there (same lengths).
    pub fn new(fz: &[f64], mu: &[f64], k: &[f64], mz: &[f64]) -> LoadCurve {
        let n = fz.len().min(LOAD_KNOTS);
        let mut c = LoadCurve {
            n,
            ..Default::default()
        };
        for i in 0..n {
            c.fz[i] = fz[i];
            c.mu[i] = mu.get(i).copied().unwrap_or(0.0);
            c.k[i] = k.get(i).copied().unwrap_or(0.0);
            c.mz[i] = mz.get(i).copied().unwrap_or(0.0);
        }
        c.prepare();
        c
    }

    fn prepare(&mut self) {
        self.d2 = [
            natural_d2(&self.fz, &self.mu, self.n),
            natural_d2(&self.fz, &self.k, self.n),
            natural_d2(&self.fz, &self.mz, self.n),
        ];
    }

    /// Curve `j` (0 mu, 1 k, 2 mz) with knot values `v` at load `fz`.
    #[inline]
    fn at(&self, j: usize, v: &[f64; LOAD_KNOTS], fz: f64) -> f64 {
        let n = self.n.clamp(1, LOAD_KNOTS);
        if !(fz > self.fz[0]) {
            return v[0];
        }
        let m = &self.d2[j];
        for i in 1..n {
            if fz < self.fz[i] {
                let h = self.fz[i] - self.fz[i - 1];
                let (a, b) = (self.fz[i] - fz, fz - self.fz[i - 1]);
                return (m[i - 1] * a * a * a + m[i] * b * b * b) / (6.0 * h)
                    + (v[i - 1] / h - m[i - 1] * h / 6.0) * a
                    + (v[i] / h - m[i] * h / 6.0) * b;
            }
        }
        v[n - 1]
    }
    /// Friction scale at `fz` (N).
    #[inline]
    pub fn friction(&self, fz: f64) -> f64 {
        1.0 + self.at(0, &self.mu, fz)
    }
    /// Slip-stiffness scale at `fz` (N).
    #[inline]
    pub fn stiffness(&self, fz: f64) -> f64 {
        1.0 + self.at(1, &self.k, fz)
    }
    /// Aligning-moment scale at `fz` (N).
    #[inline]
    pub fn moment(&self, fz: f64) -> f64 {
        1.0 + self.at(2, &self.mz, fz)
    }

    /// The curves of a file, None without `FZ1`. Errors name the key.
    fn from_params(t: &TyreParams) -> crate::Result<Option<LoadCurve>> {
        let bad = |key: &str, msg: String| crate::Error::Tir {
            file: t.source.clone(),
            line: 0,
            key: key.into(),
            message: msg,
        };
        let mut c = LoadCurve::default();
        for (i, key) in LOAD_FZ_KEYS.iter().enumerate() {
            let Some(f) = number(t, LOAD_SECTION, key)? else {
                break;
            };
            if !(f > 0.0) || (i > 0 && !(f > c.fz[i - 1])) {
                return Err(bad(
                    key,
                    format!("[{LOAD_SECTION}] {key} = {f}: the knot loads must be positive (N) and strictly increasing"),
                ));
            }
            c.fz[i] = f;
            c.n = i + 1;
        }
        for (keys, v) in [
            (&LOAD_MU_KEYS, &mut c.mu),
            (&LOAD_K_KEYS, &mut c.k),
            (&LOAD_MZ_KEYS, &mut c.mz),
        ] {
            for (i, key) in keys.iter().enumerate() {
                if let Some(x) = number(t, LOAD_SECTION, key)? {
                    if i >= c.n {
                        return Err(bad(
                            key,
                            format!("[{LOAD_SECTION}] {key} has no knot load {} (give FZ1..FZ{} in order)", LOAD_FZ_KEYS[i], i + 1),
                        ));
                    }
                    if !(x > -1.0) {
                        return Err(bad(
                            key,
                            format!("[{LOAD_SECTION}] {key} = {x}: a relative change must be above -1 (the scale 1 + {key} must stay positive)"),
                        ));
                    }
                    v[i] = x;
                }
            }
        }
        match c.n {
            0 => Ok(None),
            1 => Err(bad(
                "FZ2",
                format!("[{LOAD_SECTION}] needs at least two knot loads (FZ1, FZ2)"),
            )),
            _ => {
                c.prepare();
                Ok(Some(c))
            }
        }
    }

    /// Write the curves into `[LOAD_SECTION]`.
    fn write_to(&self, t: &mut TyreParams) {
        let s = t.extra_section(LOAD_SECTION);
        for i in 0..self.n.min(LOAD_KNOTS) {
            s.set(LOAD_FZ_KEYS[i], self.fz[i]);
            s.set(LOAD_MU_KEYS[i], self.mu[i]);
            s.set(LOAD_K_KEYS[i], self.k[i]);
            s.set(LOAD_MZ_KEYS[i], self.mz[i]);
        }
    }
}

/// The extension physics of one tyre (None fields: not in the file).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Extension {
    /// (MU_DFZ1, MU_DFZ2, K_DFZ1).
    pub load: Option<[f64; 3]>,
    /// The load curves of [`LOAD_SECTION`].
    pub load_curve: Option<LoadCurve>,
    /// LMUV and V0 (LONGVL, m/s).
    pub lmuv: Option<(f64, f64)>,
    /// The law of [`SPEED_SECTION`].
    pub speed: Option<SpeedLaw>,
    /// The lumped tread-temperature model of [`THERMAL_SECTION`].
    pub thermal: Option<Thermal>,
    /// Nominal load Fz0 = FNOMIN·LFZO (N).
    pub fz0: f64,
}

fn number(t: &TyreParams, sec: &str, key: &str) -> crate::Result<Option<f64>> {
    match t.extra(sec, key) {
        None => Ok(None),
        Some(_) => match t.extra_number(sec, key) {
            Some(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(crate::Error::Tir {
                file: t.source.clone(),
                line: 0,
                key: key.into(),
                message: format!("[{sec}] {key}: expected a finite number"),
            }),
        },
    }
}

impl Extension {
    /// The extension a tyre file describes, or None when it has none (then
    /// the step is exactly the plain model's). Errors name the file and key.
    pub fn from_params(t: &TyreParams) -> crate::Result<Option<Extension>> {
        let p = &t.p;
        let bad = |key: &str, msg: &str| crate::Error::Tir {
            file: t.source.clone(),
            line: 0,
            key: key.into(),
            message: msg.into(),
        };
        let mut e = Extension {
            fz0: {
                let f = p.fnomin * p.lfzo;
                if f.is_finite() && f > 0.0 {
                    f
                } else {
                    4000.0
                }
            },
            ..Default::default()
        };
        let mut load = [0.0; 3];
        let mut any = false;
        for (v, k) in load.iter_mut().zip(LOAD_KEYS) {
            if let Some(x) = number(t, LOAD_SECTION, k)? {
                *v = x;
                any = true;
            }
        }
        if any && load.iter().any(|x| *x != 0.0) {
            e.load = Some(load);
        }
        e.load_curve = LoadCurve::from_params(t)?;
        if p.lmuv != 0.0 {
            if !p.lmuv.is_finite() || p.lmuv < 0.0 {
                return Err(bad("LMUV", "expected a finite number >= 0"));
            }
            let v0 = if p.longvl.is_finite() && p.longvl > 0.0 {
                p.longvl
            } else {
                return Err(bad("LONGVL", "LMUV needs a positive LONGVL (V0)"));
            };
            e.lmuv = Some((p.lmuv, v0));
        }
        let dmu = number(t, SPEED_SECTION, SPEED_KEYS[0])?;
        let vc = number(t, SPEED_SECTION, SPEED_KEYS[1])?;
        let mu0 = number(t, SPEED_SECTION, SPEED_KEYS[2])?.unwrap_or(0.0);
        let vref = number(t, SPEED_SECTION, SPEED_KEYS[3])?.unwrap_or(0.0);
        if !(vref >= 0.0) {
            return Err(bad("VREF", "[SPEED_FRICTION] VREF must be >= 0 (m/s, the belt speed at which the file's friction holds; 0: the file's friction is the one at zero sliding speed)"));
        }
        if !(mu0 > -1.0) {
            return Err(bad("MU0", "[SPEED_FRICTION] MU0 must be above -1 (the friction level 1 + MU0 must stay positive)"));
        }
        if let Some(d) = dmu.filter(|d| *d != 0.0) {
            if d >= 1.0 {
                return Err(bad(
                    "DMU",
                    "[SPEED_FRICTION] DMU must be below 1 (the friction left at high sliding speed, 1 - DMU, must stay positive)",
                ));
            }
            match vc {
                Some(vc) if vc > 0.0 => {
                    e.speed = Some(SpeedLaw {
                        dmu: d,
                        vc,
                        mu0,
                        vref,
                    })
                }
                _ => {
                    return Err(bad(
                        "VC",
                        "[SPEED_FRICTION] needs VC > 0 (m/s, the sliding speed of half the friction change)",
                    ))
                }
            }
        }
        let mut th = [f64::NAN; 6];
        let mut any = false;
        for (v, k) in th.iter_mut().zip(THERMAL_KEYS) {
            if let Some(x) = number(t, THERMAL_SECTION, k)? {
                *v = x;
                any = true;
            }
        }
        if any {
            let or = |x: f64, d: f64| if x.is_nan() { d } else { x };
            let m = Thermal {
                capacity: or(th[0], 4000.0),
                cooling: or(th[1], 40.0),
                share: or(th[2], 0.5),
                mu: [or(th[3], 0.0), or(th[4], 0.0), or(th[5], 0.0)],
            };
            if !(m.capacity > 0.0 && m.cooling > 0.0 && m.share >= 0.0) {
                return Err(bad(
                    "CAPACITY",
                    "[THERMAL] needs CAPACITY > 0, COOLING > 0, SHARE >= 0",
                ));
            }
            e.thermal = Some(m);
        }
        Ok(
            if e.load.is_some()
                || e.load_curve.is_some()
                || e.lmuv.is_some()
                || e.speed.is_some()
                || e.thermal.is_some()
            {
                Some(e)
            } else {
                None
            },
        )
    }

    /// Write these parameters into `t` (sections and LMUV), replacing what
    /// was there, so that `Tyre::new` reads them back.
    pub fn write_to(&self, t: &mut TyreParams) {
        if let Some(l) = self.load {
            let s = t.extra_section(LOAD_SECTION);
            for (k, v) in LOAD_KEYS.iter().zip(l) {
                s.set(k, v);
            }
        }
        if let Some(c) = self.load_curve {
            c.write_to(t);
        }
        if let Some((lmuv, _)) = self.lmuv {
            t.p.lmuv = lmuv;
        }
        if let Some(l) = self.speed {
            let s = t.extra_section(SPEED_SECTION);
            for (k, x) in SPEED_KEYS.iter().zip([l.dmu, l.vc, l.mu0, l.vref]) {
                s.set(k, x);
            }
        }
        if let Some(m) = self.thermal {
            let s = t.extra_section(THERMAL_SECTION);
            let v = [m.capacity, m.cooling, m.share, m.mu[0], m.mu[1], m.mu[2]];
            for (k, v) in THERMAL_KEYS.iter().zip(v) {
                s.set(k, v);
            }
        }
    }

    /// Friction and slip-stiffness scales (s, c) for this step, from the
    /// load, the kinematic sliding speed and the temperature in `st`.
    #[inline]
    pub fn scales(&self, st: &TransientState, fz: f64, kin: &Kinematics) -> (f64, f64) {
        let (mut s, mut c) = (1.0, 1.0);
        if let Some([m1, m2, k1]) = self.load {
            let dfz = (fz - self.fz0) / self.fz0;
            s *= 1.0 + m1 * dfz + m2 * dfz * dfz;
            c *= 1.0 + k1 * dfz;
        }
        if let Some(l) = &self.load_curve {
            s *= l.friction(fz);
            c *= l.stiffness(fz);
        }
        if self.lmuv.is_some() || self.speed.is_some() {
            let slip = (kin.kappa * kin.kappa + kin.tan_alpha * kin.tan_alpha).sqrt();
            if let Some((lmuv, v0)) = self.lmuv {
                s /= 1.0 + lmuv * kin.vx_abs * slip / v0;
            }
            if let Some(l) = self.speed {
                s *= l.scale(kin.vx_abs, slip);
            }
        }
        if let Some(m) = self.thermal {
            s *= m.friction(st.x[SLOT_TEMP]);
        }
        let g = |x: f64| if x.is_finite() { x.max(S_MIN) } else { 1.0 };
        (g(s), g(c))
    }

    /// Scale of the aligning moment at load `fz` (N) on top of the
    /// similarity scaling ([`LoadCurve::moment`]; 1 without load curves).
    #[inline]
    pub fn moment_scale(&self, fz: f64) -> f64 {
        match &self.load_curve {
            Some(l) => {
                let m = l.moment(fz);
                if m.is_finite() {
                    m.max(S_MIN)
                } else {
                    1.0
                }
            }
            None => 1.0,
        }
    }

    /// Advance the extension states over `dt` from `prev` into `next` with
    /// the step's output held (the thermal node, exact for the held power).
    #[inline]
    pub fn advance(
        &self,
        prev: &TransientState,
        next: &mut TransientState,
        out: &WheelOutput,
        dt: f64,
    ) {
        if let Some(m) = self.thermal {
            let p = (out.fx * out.vsx).abs() + (out.fy * out.vsy).abs();
            let p = if p.is_finite() { p } else { 0.0 };
            let eq = m.share * p / m.cooling;
            let t0 = prev.x[SLOT_TEMP];
            next.x[SLOT_TEMP] = eq + (t0 - eq) * (-dt / m.time_constant()).exp();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transient::TransientKind;

    /// The built-in file plus `extra` text.
    fn with(extra: &str) -> TyreParams {
        let text = format!("{}\n{extra}", crate::tir::BUILTIN_TIR);
        TyreParams::from_tir_str(&text, "test.tir").unwrap()
    }

    /// `file` resolves to the key's model, `steady` without the key; the
    /// ADAMS USE_MODE switch (124 here, as in shared files) is not read;
    /// a written key reads back; a bad value is refused naming the key.
    #[test]
    fn transient_key_selects_the_model() {
        let plain = with("");
        assert_eq!(file_transient(&plain).unwrap(), None);
        assert_eq!(
            TransientKind::resolve("file", &plain).unwrap(),
            TransientKind::Steady
        );
        let text = crate::tir::BUILTIN_TIR.replacen("[MODEL]", "[MODEL]\nUSE_MODE = 124", 1);
        let adams = TyreParams::from_tir_str(&text, "adams.tir").unwrap();
        assert_eq!(adams.get("USE_MODE"), Some(124.0));
        assert_eq!(
            TransientKind::resolve("file", &adams).unwrap(),
            TransientKind::Steady
        );
        let relax = with("[TYREKIT]\nTRANSIENT = 'relaxation'\n");
        assert_eq!(
            TransientKind::resolve("FILE", &relax).unwrap(),
            TransientKind::Relaxation
        );
        // An explicit value overrides the file.
        assert_eq!(
            TransientKind::resolve("lugre", &relax).unwrap(),
            TransientKind::LuGre
        );
        let mut w = plain.clone();
        set_file_transient(&mut w, TransientKind::LuGre);
        let back = TyreParams::from_tir_str(&w.to_tir_string(), "w.tir").unwrap();
        assert_eq!(file_transient(&back).unwrap(), Some(TransientKind::LuGre));
        let bad = with("[TYREKIT]\nTRANSIENT = 'fast'\n");
        let e = file_transient(&bad).unwrap_err().to_string();
        assert!(e.contains("TRANSIENT") && e.contains("relaxation"), "{e}");
    }

    /// The general sliding-speed law against two other formulations of
    /// the same physics: the LMUV law 1/(1 + LMUV·Vs/V0) is the member
    /// DMU = 1, VC = V0/LMUV (identical to rounding), and an exponential
    /// Stribeck-type fall 1 − a·(1 − e^(−Vs/v)) is matched, after a fit of
    /// (DMU, VC) by grid search over 0–10 m/s, to within 10 % of its own
    /// fall a (the two shapes differ in how they level off; 10 % of the
    /// fall is below what a tyre test separates). The file keys read back,
    /// and DMU ≥ 1 or a missing VC is refused naming the key.
    #[test]
    fn speed_friction_law_covers_other_formulations() {
        let (lmuv, v0) = (0.8, 16.7);
        for vs in [0.0, 0.3, 1.0, 3.0, 10.0] {
            let a = 1.0 / (1.0 + lmuv * vs / v0);
            let b = speed_friction(1.0, v0 / lmuv, vs);
            assert!((a - b).abs() < 1e-12, "vs {vs}: {a} vs {b}");
        }
        let (fall, v) = (0.1, 1.5);
        let exp = |vs: f64| 1.0 - fall * (1.0 - (-vs / v).exp());
        let grid: Vec<f64> = (0..=100).map(|i| 0.1 * i as f64).collect();
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for i in 1..=60 {
            let dmu = 0.005 * i as f64;
            for j in 1..=60 {
                let vc = 0.1 * j as f64;
                let e = grid
                    .iter()
                    .map(|&x| (speed_friction(dmu, vc, x) - exp(x)).abs())
                    .fold(0.0, f64::max);
                if e < best.0 {
                    best = (e, dmu, vc);
                }
            }
        }
        assert!(
            best.0 < 0.1 * fall,
            "largest misfit {:.4} of a fall {fall}",
            best.0
        );
        // Monotone in the sliding speed for a fall and for a rise.
        for d in [0.3, -0.2] {
            let s: Vec<f64> = grid.iter().map(|&x| speed_friction(d, 1.0, x)).collect();
            assert!(s.windows(2).all(|w| (w[1] - w[0]) * d <= 0.0));
        }
        let t = with("[SPEED_FRICTION]\nDMU = 0.12\nVC = 1.5\nMU0 = 0.03\n");
        let e = Extension::from_params(&t).unwrap().unwrap();
        let law = SpeedLaw {
            dmu: 0.12,
            vc: 1.5,
            mu0: 0.03,
            vref: 0.0,
        };
        assert_eq!(e.speed, Some(law));
        // VREF = 0: the law over the file's friction at zero sliding speed.
        assert!((law.scale(10.0, 0.1) - 1.03 * speed_friction(0.12, 1.5, 1.0)).abs() < 1e-15);
        let t = with("[SPEED_FRICTION]\nDMU = 0.12\nVC = 1.5\nVREF = 11.1\n");
        let e = Extension::from_params(&t).unwrap().unwrap();
        let law = e.speed.unwrap();
        assert_eq!(law.vref, 11.1);
        // At the reference belt speed the file's friction holds at every
        // slip (to rounding); below it the friction is higher, above it
        // lower.
        for slip in [0.0, 0.02, 0.1, 0.3] {
            assert!((law.scale(11.1, slip) - 1.0).abs() < 1e-12);
        }
        let (lo, hi) = (law.scale(8.9, 0.1), law.scale(13.3, 0.1));
        assert!(lo > 1.0 && hi < 1.0, "{lo} {hi}");
        let mut w = with("");
        e.write_to(&mut w);
        let back = TyreParams::from_tir_str(&w.to_tir_string(), "w.tir").unwrap();
        assert_eq!(
            Extension::from_params(&back).unwrap().unwrap().speed,
            Some(law)
        );
        let bad = Extension::from_params(&with("[SPEED_FRICTION]\nDMU = 0.1\nVC = 1\nVREF = -3\n"));
        assert!(bad.unwrap_err().to_string().contains("VREF"));
        let bad = Extension::from_params(&with("[SPEED_FRICTION]\nDMU = 1.2\nVC = 1\n"));
        assert!(bad.unwrap_err().to_string().contains("DMU"));
        let bad = Extension::from_params(&with("[SPEED_FRICTION]\nDMU = 0.1\n"));
        assert!(bad.unwrap_err().to_string().contains("VC"));
    }

    /// The load curves: through the knots exactly, a straight line stays
    /// straight (a natural spline reproduces linear data), a concave set of
    /// knot values gives a smooth curve bending the same way between them,
    /// constant beyond the outer knots; the keys read back and write back;
    /// unordered knots, a missing knot load or a change ≤ −1 is refused
    /// naming the key; the old polynomial keys still read.
    #[test]
    fn load_curves_interpolate_and_read_back() {
        let c = LoadCurve::new(
            &[1000.0, 2500.0, 6000.0],
            &[-0.1, 0.02, 0.0],
            &[0.05, 0.0, -0.05],
            &[0.0, 0.1, 0.0],
        );
        for (i, f) in [1000.0, 2500.0, 6000.0].iter().enumerate() {
            assert!((c.friction(*f) - 1.0 - c.mu[i]).abs() < 1e-12);
            assert!((c.stiffness(*f) - 1.0 - c.k[i]).abs() < 1e-12);
            assert!((c.moment(*f) - 1.0 - c.mz[i]).abs() < 1e-12);
        }
        // k is linear in Fz? No: (1000, .05), (2500, 0), (6000, -.05) is
        // not collinear; a collinear set is reproduced exactly.
        let lin = LoadCurve::new(&[1000.0, 2500.0, 6000.0], &[-0.1, 0.05, 0.4], &[], &[]);
        for f in [1200.0, 2000.0, 3000.0, 5500.0] {
            let want = -0.1 + 0.15 * (f - 1000.0) / 1500.0;
            assert!((lin.friction(f) - 1.0 - want).abs() < 1e-12, "{f}");
        }
        // Concave knots (the mu set): the curve between them lies above
        // the chords, and is continuous at the middle knot.
        let chord = -0.1 + 0.12 * (1750.0 - 1000.0) / 1500.0;
        assert!(c.friction(1750.0) - 1.0 > chord);
        let e = 1e-6;
        assert!((c.friction(2500.0 - e) - c.friction(2500.0 + e)).abs() < 1e-8);
        // Constant beyond the outer knots.
        assert_eq!(c.friction(200.0), c.friction(1000.0));
        assert_eq!(c.friction(9000.0), c.friction(6000.0));
        let t = with("[LOAD_SENSITIVITY]\nFZ1 = 1000\nFZ2 = 2500\nFZ3 = 6000\nMU_FZ1 = -0.1\nMU_FZ2 = 0.02\nMU_FZ3 = 0\nK_FZ1 = 0.05\nK_FZ3 = -0.05\nMZ_FZ2 = 0.1\n");
        let e = Extension::from_params(&t).unwrap().unwrap();
        assert_eq!(e.load_curve, Some(c));
        let mut w = with("");
        e.write_to(&mut w);
        let back = TyreParams::from_tir_str(&w.to_tir_string(), "w.tir").unwrap();
        assert_eq!(
            Extension::from_params(&back).unwrap().unwrap().load_curve,
            Some(c)
        );
        for (text, key) in [
            ("FZ1 = 2000\nFZ2 = 1000\n", "FZ2"),
            ("FZ1 = 1000\n", "FZ2"),
            ("FZ1 = 1000\nFZ2 = 2000\nMU_FZ3 = 0.1\n", "MU_FZ3"),
            ("FZ1 = 1000\nFZ2 = 2000\nK_FZ1 = -1.2\n", "K_FZ1"),
        ] {
            let r = Extension::from_params(&with(&format!("[LOAD_SENSITIVITY]\n{text}")));
            let msg = r.unwrap_err().to_string();
            assert!(msg.contains(key), "{text}: {msg}");
        }
        let old = with("[LOAD_SENSITIVITY]\nMU_DFZ1 = -0.1\nMU_DFZ2 = 0\nK_DFZ1 = 0\n");
        let e = Extension::from_params(&old).unwrap().unwrap();
        assert_eq!((e.load, e.load_curve), (Some([-0.1, 0.0, 0.0]), None));
    }
}
