//! extension — physics beyond the steady Magic Formula that the diagnosis can
//! name and fit, read once from the tyre file (at [`crate::mf::Tyre::new`])
//! and applied inside [`super::TransientModel::step`] — the code the FMU and
//! `replay` run — through one hook: a friction scale `s` and a slip-stiffness
//! scale `c` per step, applied with the similarity method (Pacejka, *Tyre and
//! Vehicle Dynamics*, 3rd ed., §4.3.2): F(κ) → s·F(c·κ/s), i.e. peak × s,
//! slip stiffness × c (`StepCtx::forces`, [`super::mf_at`]).
//!
//! The scales are a product of:
//! * **load sensitivity** (`[LOAD_SENSITIVITY]`, keys `MU_DFZ1`, `MU_DFZ2`,
//!   `K_DFZ1`): polynomial corrections in dfz = (Fz − Fz0)/Fz0 beyond the MF
//!   forms, s = 1 + MU_DFZ1·dfz + MU_DFZ2·dfz², c = 1 + K_DFZ1·dfz — the
//!   role the η-corrections play for heavy radial tyres.
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
/// Keys of [`LOAD_SECTION`].
pub const LOAD_KEYS: [&str; 3] = ["MU_DFZ1", "MU_DFZ2", "K_DFZ1"];
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
    /// Friction polynomial in x = ΔT/50 K: s = 1 + mu[0] + mu[1]·x + mu[2]·x².
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

/// The extension physics of one tyre (None fields: not in the file).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Extension {
    /// (MU_DFZ1, MU_DFZ2, K_DFZ1).
    pub load: Option<[f64; 3]>,
    /// LMUV and V0 (LONGVL, m/s).
    pub lmuv: Option<(f64, f64)>,
    /// The law of [`SPEED_SECTION`].
    pub speed: Option<SpeedLaw>,
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
            if e.load.is_some() || e.lmuv.is_some() || e.speed.is_some() || e.thermal.is_some() {
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
}
