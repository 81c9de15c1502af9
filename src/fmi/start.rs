//! start — the tyre-dependent start values of the FMU's inputs: the packaged
//! tyre free rolling at its nominal load, so a master that runs the FMU
//! untouched sees κ = 0, not a braking or driving tyre.
//!
//! `Fz` starts at FNOMIN; `omega` at the spin rate where the longitudinal slip
//! speed Vsx = Vx − Ω·Re vanishes (κ = −Vsx/|Vx| = 0; Pacejka, *Tyre and Vehicle
//! Dynamics*, 3rd ed., §2.2 eq. 2.10), with Re the effective rolling radius the
//! model itself uses (MF 6.1 eq. 4.E23 ff.; it depends on Ω through the
//! centrifugal growth, hence a fixed-point iteration on the model's own step).
//! Every other start value is the XML's (`modelDescription/modelDescription.xml`,
//! the one source of truth, which build.rs turns into [`Values::start`]).
//! The FMU instance applies these values when it loads its tyre, and
//! `tyrekit package` writes the same numbers into the shipped XML, so the
//! declared and the actual start values agree for every packaged tyre (the GUID
//! does not cover start values).
//!
//! The start values `tyrekit package` *chooses* (`spec::CHOSEN_STARTS`, the
//! `force_model` default) are read back from the packaged
//! `modelDescription.xml` (the FMU's root, the parent of `resources/`), the
//! one place they are written: [`read_chosen`]. [`start_span`] locates a start
//! value in the XML text, for the reader here and the writer (packaging).
//! Must never: be used in the step (load time only), change a start value
//! other than `Fz`, `omega` and those of `spec::CHOSEN_STARTS`, or take a
//! start value from an XML of another interface (GUID checked).

use super::instance::ChosenStart;
use super::spec::CHOSEN_STARTS;
use super::vars::{real, Values, GUID};
use crate::mf::Tyre;
use crate::transient::{TransientConfig, TransientModel, WheelInput};
use std::ops::Range;
use std::path::Path;

/// The free-rolling start of `tyre` as (variable name, value) for the inputs
/// of [`super::spec::TYRE_DEPENDENT_STARTS`], at the XML's start values of the
/// other inputs (`vx`, `p` = 0 = INFLPRES, …).
pub fn free_rolling(tyre: &Tyre) -> [(&'static str, f64); 2] {
    let v = Values::start();
    let r = &v.reals;
    let fz = tyre.params().p.fnomin;
    let mut inp = WheelInput {
        vx: r[real::VX],
        vy: r[real::VY],
        omega: 0.0,
        fz,
        gamma: r[real::GAMMA],
        p: r[real::P],
        phit: r[real::PHIT],
        mu_scale: r[real::MU_SCALE],
        kappa_in: r[real::KAPPA_IN],
        alpha_in: r[real::ALPHA_IN],
    };
    // Start from the unloaded radius, then Ω ← Vx / Re(Ω) with the Re the
    // steady step reports. Re changes with Ω only through the centrifugal
    // growth (∂Re/∂Ω·Ω/Re ~ 1e-3), so each pass shrinks the error by that
    // factor: 8 passes reach round-off; stop early once Ω stops moving.
    let r0 = tyre.params().p.unloaded_radius;
    inp.omega = if r0 > 0.0 { inp.vx / r0 } else { 0.0 };
    let mut model = TransientModel::new(TransientConfig::default());
    for _ in 0..8 {
        let re = match model.step(tyre, &inp, 0.0) {
            Ok(o) if o.re.is_finite() && o.re > 0.0 => o.re,
            _ => break,
        };
        let next = inp.vx / re;
        let done = (next - inp.omega).abs() <= 1e-15 * next.abs();
        inp.omega = next;
        if done {
            break;
        }
    }
    [("Fz", fz), ("omega", inp.omega)]
}

/// Set the tyre-dependent start values of `values` for `tyre`.
pub fn apply(values: &mut Values, tyre: &Tyre) {
    let [(_, fz), (_, omega)] = free_rolling(tyre);
    values.reals[real::FZ] = fz;
    values.reals[real::OMEGA] = omega;
}

/// Byte range of the text of `name`'s `start="…"` attribute in a
/// modelDescription.xml text (as build.rs and packaging write it: the
/// attribute inside the variable's `<ScalarVariable …>…</ScalarVariable>`).
pub fn start_span(xml: &str, name: &str) -> Option<Range<usize>> {
    let at = xml.find(&format!("<ScalarVariable name=\"{name}\""))?;
    let end = at + xml[at..].find("</ScalarVariable>")?;
    let key = " start=\"";
    let s = at + xml[at..end].find(key)? + key.len();
    let e = s + xml[s..end].find('"')?;
    Some(s..e)
}

/// The chosen start values (`spec::CHOSEN_STARTS`) of the FMU whose
/// resources folder is `resources`, from `resources/modelDescription.xml` (the
/// packaged copy) or else `resources/../modelDescription.xml`.
/// Empty when that file is absent or belongs to another interface (another
/// GUID: e.g. a master that passes a bare folder): the built-in XML's starts
/// apply. An error names the file when it is ours but unreadable or holds a
/// value the library does not know.
pub fn read_chosen(resources: &Path) -> Result<Vec<ChosenStart>, String> {
    // Packaging puts a copy in resources/ (fmpy's simulate_fmu extracts only
    // binaries/ and resources/); the FMU root's is the fallback.
    let candidates = [
        Some(resources.join("modelDescription.xml")),
        resources.parent().map(|d| d.join("modelDescription.xml")),
    ];
    let Some(path) = candidates.into_iter().flatten().find(|p| p.is_file()) else {
        return Ok(Vec::new());
    };
    let xml = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "{}: cannot read the packaged modelDescription.xml: {e}",
            path.display()
        )
    })?;
    if !xml.contains(&format!("guid=\"{GUID}\"")) {
        return Ok(Vec::new());
    }
    let mut out = Vec::with_capacity(CHOSEN_STARTS.len());
    for (name, allowed) in CHOSEN_STARTS {
        let value = start_span(&xml, name)
            .map(|r| xml[r].trim().to_ascii_lowercase())
            .ok_or_else(|| {
                format!(
                    "{}: no start value of \"{name}\" (re-package the FMU with tyrekit package)",
                    path.display()
                )
            })?;
        if !allowed.contains(&value.as_str()) {
            return Err(format!(
                "{}: start value \"{value}\" of \"{name}\" is not one of {allowed:?} (re-package the FMU with tyrekit package)",
                path.display()
            ));
        }
        out.push((*name, value));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transient::InputMode;

    /// At the start state the model's own kinematics give κ ≈ 0: |κ| below
    /// 1e-12 (the iteration converges to round-off, ~1e-16 relative), and Fx is
    /// only the rolling-resistance-free zero-slip offset, below 2 % of Fz
    /// (the acceptance bound; the built-in tyre's SVx/SHx are ~0.1 %).
    #[test]
    fn builtin_tyre_starts_free_rolling() {
        let tyre = Tyre::builtin();
        let [("Fz", fz), ("omega", omega)] = free_rolling(&tyre) else {
            panic!("free_rolling names changed")
        };
        let mut names: Vec<_> = free_rolling(&tyre).iter().map(|p| p.0).collect();
        names.sort_unstable();
        assert_eq!(
            names,
            super::super::spec::TYRE_DEPENDENT_STARTS,
            "the XML's tyre-dependent starts"
        );
        assert_eq!(fz, tyre.params().p.fnomin);
        let v = Values::start();
        let inp = WheelInput {
            vx: v.reals[real::VX],
            omega,
            fz,
            mu_scale: v.reals[real::MU_SCALE],
            ..Default::default()
        };
        let mut model = TransientModel::new(TransientConfig::default());
        assert_eq!(model.config.input_mode, InputMode::Velocities);
        let o = model.step(&tyre, &inp, 1e-3).unwrap();
        assert!(o.kappa.abs() < 1e-12, "kappa {}", o.kappa);
        assert!(o.fx.abs() < 0.02 * fz, "Fx {} at Fz {fz}", o.fx);
        // ω·Re = Vx, and ω is of the size Vx/R0 (Re within 5 % of R0).
        let r0 = tyre.params().p.unloaded_radius;
        assert!((omega * r0 / inp.vx - 1.0).abs() < 0.05, "omega {omega}");
    }

    /// The XML's own start values of Fz and omega are the built-in tyre's
    /// free-rolling state (what an unpackaged XML or a reader of the file sees);
    /// 1e-12 relative: the XML holds the shortest round-trip text of ω.
    #[test]
    fn xml_start_values_are_the_builtin_free_rolling_state() {
        let v = Values::start();
        for (name, x) in free_rolling(&Tyre::builtin()) {
            let slot = if name == "Fz" { real::FZ } else { real::OMEGA };
            let xml = v.reals[slot];
            assert!(
                (xml - x).abs() <= 1e-12 * x.abs(),
                "{name}: XML {xml}, built-in {x}"
            );
        }
    }
}
