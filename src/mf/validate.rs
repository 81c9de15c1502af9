//! validate — the one check of a loaded tyre, used by every entry point that
//! loads one (CLI commands, the FMU's instantiation and `tyre_file`, the fit's
//! output, the Python binding through the CLI): [`check`].
//!
//! Two outcomes besides success:
//! * **refusal** (`Err`, with the reason and the fix) for a file the model
//!   cannot evaluate at nominal conditions at all: a required key that is not
//!   a positive finite number (FNOMIN, UNLOADED_RADIUS, NOMPRES, LONGVL, LFZO,
//!   INFLPRES), sizes whose units cannot be a tyre's (a radius outside
//!   [`RADIUS_RANGE`], a nominal load outside [`LOAD_RANGE`]: the usual sign
//!   of a wrong `[UNITS]` section), or a non-finite force, moment or friction
//!   at nominal conditions (Fz = FNOMIN, κ = α = γ = 0, Vx = LONGVL,
//!   p = INFLPRES);
//! * **warnings** (the tyre loads; the caller shows them) for doubts: the
//!   model evaluated over the file's own range (loads 0.25–2 × FNOMIN clipped
//!   to FZMIN..FZMAX, κ over KPUMIN..KPUMAX, α over ALPMIN..ALPMAX, γ over
//!   CAMMIN..CAMMAX) gives a non-finite value, a friction coefficient outside
//!   [0, [`MU_MAX`]], a force |Fx|, |Fy| > [`FORCE_FACTOR`]·Fz·max(1, |μx|, |μy|)
//!   or a moment |Mx|, |My|, |Mz| > [`MOMENT_FACTOR`]·Fz·R0·max(1, |μx|, |μy|);
//!   a static deflection FNOMIN/VERTICAL_STIFFNESS beyond [`DEFLECTION_MAX`]
//!   of the radius (a stiffness in N/mm or kN/m).
//!
//! The bounds: the Magic Formula's peak is D = μ·Fz (Pacejka, *Tyre and
//! Vehicle Dynamics*, 3rd ed., eqs. 4.E9/4.E22), the vertical shifts add a few
//! per cent, so a force beyond twice μ·Fz is not a tyre's; every moment is a
//! force of at most that size times a lever no longer than the radius R0
//! (overturning: Fy·R0 at most; aligning: trail·Fy with the trail < R0;
//! rolling resistance: a fraction of Fz·R0), so a moment beyond 2·μ·Fz·R0 is
//! not a tyre's either.
//!
//! Must never: change a parameter, refuse a file that evaluates at nominal
//! conditions for a doubt alone, panic, or allocate more than its messages.

use super::{MfInput, MfOutput, Tyre, UseMode};

/// A force beyond this multiple of Fz·max(1, |μ|) is reported (see the module doc).
pub const FORCE_FACTOR: f64 = 2.0;
/// A moment beyond this multiple of Fz·R0·max(1, |μ|) is reported.
pub const MOMENT_FACTOR: f64 = 2.0;
/// Friction coefficients above this are reported (rubber on any road: < 3).
pub const MU_MAX: f64 = 10.0;
/// UNLOADED_RADIUS (m) a tyre can have; outside is refused (wrong `[UNITS]`).
pub const RADIUS_RANGE: (f64, f64) = (0.01, 20.0);
/// FNOMIN (N) a tyre can have; outside is refused (wrong `[UNITS]`).
pub const LOAD_RANGE: (f64, f64) = (1.0, 1e7);

/// Static deflection at FNOMIN, as a share of UNLOADED_RADIUS, beyond which
/// VERTICAL_STIFFNESS is reported (tyres deflect by a few per cent).
pub const DEFLECTION_MAX: f64 = 0.5;

/// Road speeds (m/s) the grid is also evaluated at (walking pace to 216 km/h).
pub const SPEEDS: [f64; 4] = [1.0, 10.0, 30.0, 60.0];
/// LONGVL (m/s) outside this is reported (measurement speeds; a wrong TIME unit).
pub const LONGVL_RANGE: (f64, f64) = (1.0, 100.0);

/// Check a prepared tyre. `Ok(warnings)` when it loads (each warning starts
/// `validation:`), `Err(reason)` when it is refused (see the module doc).
pub fn check(tyre: &Tyre) -> Result<Vec<String>, String> {
    let p = &tyre.params().p;
    for (name, v) in [
        ("FNOMIN", p.fnomin),
        ("UNLOADED_RADIUS", p.unloaded_radius),
        ("NOMPRES", p.nompres),
        ("INFLPRES", p.inflpres),
        ("LONGVL", p.longvl),
        ("LFZO", p.lfzo),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!(
                "{name} = {v}: the Magic Formula needs a positive finite {name} \
                 (it divides by it); give it in the file"
            ));
        }
    }
    for (name, v, (lo, hi), unit) in [
        ("UNLOADED_RADIUS", p.unloaded_radius, RADIUS_RANGE, "m"),
        ("FNOMIN", p.fnomin, LOAD_RANGE, "N"),
    ] {
        if !(lo..=hi).contains(&v) {
            return Err(format!(
                "{name} = {v} {unit} after [UNITS] conversion is outside {lo}..{hi} {unit}, \
                 which no tyre has; check the [UNITS] section (LENGTH, FORCE)"
            ));
        }
    }
    let mode = UseMode::default();
    let nominal = MfInput {
        fz: p.fnomin,
        vx: p.longvl,
        p: p.inflpres,
        ..Default::default()
    };
    let o = tyre.evaluate(&nominal, mode);
    if let Some((n, v)) = first_non_finite(&o) {
        return Err(format!(
            "{n} = {v} at nominal conditions (Fz = FNOMIN = {} N, kappa = alpha = gamma = 0, \
             Vx = LONGVL = {} m/s, p = INFLPRES = {} Pa): the model cannot be evaluated; \
             check the keys the warnings name and the [UNITS] section",
            p.fnomin, p.longvl, p.inflpres
        ));
    }
    let mut warnings = Vec::new();
    if !o.re.is_finite() {
        warnings.push(format!(
            "validation: effective rolling radius Re = {} at nominal load (as MFeval computes \
             it from this file): slips from wheel speed (FMU input_mode = velocities, replay) \
             cannot be computed; check Q_RE0, Q_V1, BREFF, DREFF, FREFF, Q_FZ1",
            o.re
        ));
    } else if !(o.re > 0.0 && o.re <= 2.0 * p.unloaded_radius) {
        warnings.push(format!(
            "validation: effective rolling radius Re = {} m at nominal load, expected in \
             (0, 2·UNLOADED_RADIUS = {} m]",
            o.re,
            2.0 * p.unloaded_radius
        ));
    }
    let mut worst = Worst::default();
    for fz in loads(p.fnomin, p.fzmin, p.fzmax) {
        for kappa in span(p.kpumin, p.kpumax, 1.0) {
            for alpha in span(p.alpmin, p.alpmax, 0.5) {
                for gamma in span(p.cammin, p.cammax, 0.0) {
                    let x = MfInput {
                        fz,
                        kappa,
                        alpha,
                        gamma,
                        ..nominal
                    };
                    worst.add(&x, &tyre.evaluate(&x, mode), p.unloaded_radius);
                }
            }
        }
    }
    // Speed enters through Vx/LONGVL (My, the LMUV friction decay, MF 6.2's
    // speed terms): the grid again at road speeds at the nominal load.
    for vx in SPEEDS {
        for kappa in span(p.kpumin, p.kpumax, 1.0) {
            for alpha in span(p.alpmin, p.alpmax, 0.5) {
                let x = MfInput {
                    kappa,
                    alpha,
                    vx,
                    ..nominal
                };
                worst.add(&x, &tyre.evaluate(&x, mode), p.unloaded_radius);
            }
        }
    }
    // The static deflection at the nominal load, FNOMIN/Cz, is a few per
    // cent of a tyre's radius; beyond half of it the file's stiffness is in
    // other units (N/mm, kN/m) and every loaded radius, and in the FMU's
    // vertical mode every load, computed from it is meaningless.
    let deflection = p.fnomin / p.vertical_stiffness;
    if p.vertical_stiffness > 0.0
        && deflection.is_finite()
        && deflection > DEFLECTION_MAX * p.unloaded_radius
    {
        warnings.push(format!(
            "validation: VERTICAL_STIFFNESS = {} N/m deflects the tyre by {:.3} m at FNOMIN = {} N, \
             more than {DEFLECTION_MAX} × UNLOADED_RADIUS = {} m: the value is likely in N/mm or \
             kN/m; loaded radii and loads from deflection are not a tyre's — check the value and \
             the [UNITS] section",
            p.vertical_stiffness, deflection, p.fnomin, p.unloaded_radius
        ));
    }
    if !(LONGVL_RANGE.0..=LONGVL_RANGE.1).contains(&p.longvl) {
        warnings.push(format!(
            "validation: LONGVL = {} m/s is outside {}..{} m/s, where measurements are made; \
             check the [UNITS] section (LENGTH, TIME)",
            p.longvl, LONGVL_RANGE.0, LONGVL_RANGE.1
        ));
    }
    worst.report(&mut warnings);
    Ok(warnings)
}

/// The first non-finite output among the ones a user reads, by name.
fn first_non_finite(o: &MfOutput) -> Option<(&'static str, f64)> {
    [
        ("Fx", o.fx),
        ("Fy", o.fy),
        ("Mx", o.mx),
        ("My", o.my),
        ("Mz", o.mz),
        ("mux", o.mux),
        ("muy", o.muy),
    ]
    .into_iter()
    .find(|(_, v)| !v.is_finite())
}

/// Five loads over the file's range: 0.25, 0.5, 1, 1.5, 2 × FNOMIN, clipped
/// to FZMIN..FZMAX when those are sensible.
fn loads(fnomin: f64, fzmin: f64, fzmax: f64) -> [f64; 5] {
    let lo = if fzmin.is_finite() && fzmin > 0.0 {
        fzmin
    } else {
        0.0
    };
    let hi = if fzmax.is_finite() && fzmax > lo {
        fzmax
    } else {
        f64::INFINITY
    };
    [0.25, 0.5, 1.0, 1.5, 2.0].map(|f| (f * fnomin).clamp(lo.min(fnomin), hi.max(fnomin)))
}

/// Five points over `lo..hi` (the file's range limits) through 0; ±`fallback`
/// when the limits are not a sensible interval.
fn span(lo: f64, hi: f64, fallback: f64) -> [f64; 5] {
    let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo <= 0.0 && hi >= 0.0 && hi > lo {
        (lo.max(-10.0), hi.min(10.0))
    } else {
        (-fallback, fallback)
    };
    [lo, 0.5 * lo, 0.0, 0.5 * hi, hi]
}

/// The worst excess per quantity over the grid (ratio to its bound), with
/// the input where it happened.
#[derive(Default)]
struct Worst {
    non_finite: Option<(&'static str, MfInput)>,
    mu: Option<(f64, &'static str, MfInput)>,
    excess: [Option<(f64, f64, f64, MfInput)>; 5],
}

const NAMES: [&str; 5] = ["Fx", "Fy", "Mx", "My", "Mz"];
const HINTS: [&str; 5] = [
    "PCX1, PDX*, PEX*, PKX*, PVX*",
    "PCY1, PDY*, PEY*, PKY*, PVY*",
    "QSX*",
    "QSY*",
    "QBZ*, QCZ1, QDZ*, QEZ*, QHZ*, SSZ*",
];

impl Worst {
    fn add(&mut self, x: &MfInput, o: &MfOutput, r0: f64) {
        if self.non_finite.is_none() {
            if let Some((n, _)) = first_non_finite(o) {
                self.non_finite = Some((n, *x));
                return;
            }
        }
        if first_non_finite(o).is_some() {
            return;
        }
        for (n, mu) in [("mux", o.mux), ("muy", o.muy)] {
            if !(0.0..=MU_MAX).contains(&mu) && self.mu.is_none() {
                self.mu = Some((mu, n, *x));
            }
        }
        let mu = 1f64.max(o.mux.abs()).max(o.muy.abs());
        let fb = FORCE_FACTOR * x.fz * mu;
        let mb = MOMENT_FACTOR * x.fz * r0 * mu;
        for (i, (v, b)) in [(o.fx, fb), (o.fy, fb), (o.mx, mb), (o.my, mb), (o.mz, mb)]
            .into_iter()
            .enumerate()
        {
            let ratio = v.abs() / b;
            if ratio > 1.0 && self.excess[i].is_none_or(|(r, ..)| ratio > r) {
                self.excess[i] = Some((ratio, v, b, *x));
            }
        }
    }

    fn report(&self, w: &mut Vec<String>) {
        let at = |x: &MfInput| {
            format!(
                "Fz = {} N, kappa = {}, alpha = {} rad, gamma = {} rad, Vx = {} m/s",
                x.fz, x.kappa, x.alpha, x.gamma, x.vx
            )
        };
        if let Some((n, x)) = &self.non_finite {
            w.push(format!(
                "validation: {n} is not finite at {} (inside the file's own range); \
                 the FMU refuses such a step",
                at(x)
            ));
        }
        if let Some((mu, n, x)) = &self.mu {
            w.push(format!(
                "validation: friction {n} = {mu} at {}, expected in [0, {MU_MAX}]; \
                 check PDX1/PDY1 and LMUX/LMUY",
                at(x)
            ));
        }
        for (i, e) in self.excess.iter().enumerate() {
            if let Some((_, v, b, x)) = e {
                let what = if i < 2 {
                    "Fz·max(1, mu)"
                } else {
                    "Fz·R0·max(1, mu)"
                };
                let f = if i < 2 { FORCE_FACTOR } else { MOMENT_FACTOR };
                w.push(format!(
                    "validation: {} = {v:.4e} at {} exceeds {f}·{what} = {b:.4e}, \
                     which no tyre gives; check {}",
                    NAMES[i],
                    at(x),
                    HINTS[i]
                ));
            }
        }
    }
}
