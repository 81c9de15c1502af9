//! version — which Magic Formula equation set a `.tir` file is written for,
//! and refusal of files of other tyre models.
//!
//! Evidence, strongest first: `FITTYP` (5, 6, 52 → MF 5.2; 61 → MF 6.1;
//! 62 → MF 6.2), `PROPERTY_FILE_FORMAT` (`'PAC2002'`, `'MF_05'`, `'MF61'` …),
//! a `TIRE_VERSION` key or header comment (`! : TIRE_VERSION : PAC2002`,
//! `!TIRE_VERSION: MF-TYRE 5.0`). FITTYP wins when present; a disagreeing
//! PROPERTY_FILE_FORMAT is reported as a warning.
//!
//! Refused: files whose `FUNCTION_NAME` or `PROPERTY_FILE_FORMAT` names another
//! tyre model (Harty `HTire…::TYR501`, Fiala, UA, FTire, PAC89/PAC94), and
//! files without FITTYP that hold no Magic Formula coefficient at all.
//!
//! Must never: guess silently (every fallback is a warning), or accept a
//! FITTYP it does not know.

use super::keys::{lookup_key, KEYS};
use super::parse::{TirDoc, Value};
use super::MfVersion;
use crate::error::{Error, Result};

/// Sections whose keys are Magic Formula coefficients proper.
const MF_COEFF_SECTIONS: [&str; 6] = [
    "LONGITUDINAL_COEFFICIENTS",
    "OVERTURNING_COEFFICIENTS",
    "LATERAL_COEFFICIENTS",
    "ROLLING_COEFFICIENTS",
    "ALIGNING_COEFFICIENTS",
    "SCALING_COEFFICIENTS",
];

/// Version of a FITTYP value, if it is one tyrekit evaluates.
pub fn from_fittyp(f: f64) -> Option<MfVersion> {
    if f == 5.0 || f == 6.0 || f == 52.0 {
        Some(MfVersion::Mf52)
    } else if f == 61.0 {
        Some(MfVersion::Mf61)
    } else if f == 62.0 {
        Some(MfVersion::Mf62)
    } else {
        None
    }
}

/// Canonical FITTYP the writer uses for a version (`None` for PAC2002,
/// which has no FITTYP of its own).
pub fn canonical_fittyp(v: MfVersion) -> Option<f64> {
    match v {
        MfVersion::Pac2002 => None,
        MfVersion::Mf52 => Some(52.0),
        MfVersion::Mf61 => Some(61.0),
        MfVersion::Mf62 => Some(62.0),
    }
}

/// What a PROPERTY_FILE_FORMAT / TIRE_VERSION string says.
enum Says {
    Mf(MfVersion),
    Other(&'static str),
    Nothing,
}

fn interpret(s: &str) -> Says {
    let u: String = s
        .to_ascii_uppercase()
        .chars()
        .filter(|c| !matches!(c, ' ' | '-' | '_' | '.' | '\''))
        .collect();
    if u.contains("PAC2002") || u.contains("PAC02") {
        Says::Mf(MfVersion::Pac2002)
    } else if u.contains("FIALA") {
        Says::Other("Fiala")
    } else if u.contains("PAC89") || u.contains("PAC94") {
        Says::Other("Pacejka '89/'94 (a different coefficient set)")
    } else if u.contains("HARTY") || u.contains("HTIRE") || u.contains("TYR501") {
        Says::Other("Harty")
    } else if u.contains("FTIRE") {
        Says::Other("FTire")
    } else if u == "UA" || u.contains("UATIRE") {
        Says::Other("UA (University of Arizona)")
    } else if u.contains("MF62")
        || u.contains("MFTYRE62")
        || u.contains("MFSWIFT62")
        || u.contains("TYRE62")
    {
        Says::Mf(MfVersion::Mf62)
    } else if u.contains("MF61") || u.contains("TYRE61") || u.contains("SWIFT61") {
        Says::Mf(MfVersion::Mf61)
    } else if u.contains("MF05")
        || u.contains("MF52")
        || u.contains("MFTYRE5")
        || u.contains("MFMC")
        || u == "MF5"
    {
        Says::Mf(MfVersion::Mf52)
    } else {
        Says::Nothing
    }
}

/// `TIRE_VERSION` from a header comment such as `! : TIRE_VERSION : PAC2002`
/// or `!TIRE_VERSION:        MF-TYRE 5.0 (W-axis system)`.
fn tire_version_comment(doc: &TirDoc) -> Option<&str> {
    doc.header_comments.iter().find_map(|c| {
        let t = c.trim_start_matches([' ', ':', '\t']);
        let rest = t.strip_prefix("TIRE_VERSION")?;
        Some(rest.trim_start_matches([' ', ':', '\t', '=']).trim())
    })
}

fn refuse(file: &str, line: usize, key: &str, model: &str, why: &str) -> Error {
    Error::Tir {
        file: file.to_string(),
        line,
        key: key.to_string(),
        message: format!(
            "this appears to be a {model} tyre model file ({why}), not a Magic Formula file; \
             tyrekit reads only Magic Formula property files (MF 5.2, MF 6.1, MF 6.2, PAC2002)"
        ),
    }
}

/// Recognise the version of a parsed file, or refuse it.
pub fn detect(doc: &TirDoc, file: &str, warnings: &mut Vec<String>) -> Result<MfVersion> {
    let entry_str = |key: &str| -> Option<(String, usize)> {
        let (_, e) = doc.find(key)?;
        let s = match &e.value {
            Value::Text(s) | Value::Word(s) => s.clone(),
            Value::Number(x) => format!("{x}"),
            Value::Empty => return None,
        };
        Some((s, e.line))
    };

    // 1. Another tyre model named outright.
    if let Some((f, line)) = entry_str("FUNCTION_NAME") {
        if let Says::Other(model) = interpret(&f) {
            return Err(refuse(
                file,
                line,
                "FUNCTION_NAME",
                model,
                &format!("FUNCTION_NAME = '{f}'"),
            ));
        }
    }
    let pff = entry_str("PROPERTY_FILE_FORMAT");
    if let Some((f, line)) = &pff {
        if let Says::Other(model) = interpret(f) {
            return Err(refuse(
                file,
                *line,
                "PROPERTY_FILE_FORMAT",
                model,
                &format!("PROPERTY_FILE_FORMAT = '{f}'"),
            ));
        }
    }

    // 2. FITTYP.
    let mut fittyp_version = None;
    // As the reader does: the latest FITTYP that is a number (a later
    // non-numeric one is not used).
    let fittyp = doc
        .sections
        .iter()
        .flat_map(|s| s.entries.iter())
        .filter(|e| e.key.eq_ignore_ascii_case("FITTYP"))
        .max_by_key(|e| (matches!(e.value, Value::Number(_)), e.line));
    if let Some(e) = fittyp {
        match e.value {
            Value::Number(x) => match from_fittyp(x) {
                Some(v) => fittyp_version = Some((v, x, e.line)),
                None => {
                    return Err(Error::Tir {
                        file: file.to_string(),
                        line: e.line,
                        key: "FITTYP".into(),
                        message: format!(
                            "FITTYP = {x} is not a Magic Formula version tyrekit evaluates \
                             (expected 5, 6 or 52 for MF 5.2, 61 for MF 6.1, 62 for MF 6.2)"
                        ),
                    })
                }
            },
            _ => warnings.push(format!(
                "line {}: FITTYP: not a number ({:?}); the version is taken from other keys",
                e.line, e.value
            )),
        }
    }

    // 3. Is there any Magic Formula coefficient?
    let has_coefficients = doc.sections.iter().any(|s| {
        s.entries.iter().any(|e| {
            // Only a value the reader will use counts (`PDY1 =` does not).
            matches!(e.value, Value::Number(_))
                && lookup_key(&e.key)
                    .map(|i| MF_COEFF_SECTIONS.contains(&KEYS[i].section))
                    .unwrap_or(false)
        })
    });
    if !has_coefficients {
        if let Some((v, _, line)) = fittyp_version {
            warnings.push(format!(
                "line {line}: FITTYP: the file holds no Magic Formula coefficient; every coefficient takes its default"
            ));
            return Ok(v);
        }
        let fiala = ["CSLIP", "CALPHA", "UMIN", "UMAX"]
            .iter()
            .all(|k| doc.find(k).is_some());
        let (model, why) = if fiala {
            (
                "Fiala",
                "it has CSLIP, CALPHA, UMIN, UMAX and no Magic Formula coefficient",
            )
        } else {
            (
                "non-Magic-Formula",
                "it has no FITTYP and no Magic Formula coefficient (PCX1, PDY1, QBZ1, LFZO …)",
            )
        };
        let line = pff.as_ref().map(|p| p.1).unwrap_or(1);
        return Err(refuse(file, line, "(file)", model, why));
    }

    let pff_says = pff.as_ref().map(|(s, l)| (interpret(s), s.clone(), *l));
    if let Some((v, x, line)) = fittyp_version {
        if let Some((Says::Mf(pv), s, pl)) = &pff_says {
            if *pv != v {
                warnings.push(format!(
                    "line {pl}: PROPERTY_FILE_FORMAT = '{s}' disagrees with FITTYP = {x} (line {line}); \
                     FITTYP wins: {v:?}"
                ));
            }
        }
        return Ok(v);
    }
    if let Some((Says::Mf(v), _, _)) = pff_says {
        return Ok(v);
    }
    let tv = entry_str("TIRE_VERSION")
        .map(|(s, _)| s)
        .or_else(|| tire_version_comment(doc).map(str::to_string));
    if let Some(tv) = tv {
        if let Says::Mf(v) = interpret(&tv) {
            return Ok(v);
        }
    }
    warnings.push(
        "no FITTYP, PROPERTY_FILE_FORMAT or TIRE_VERSION names the Magic Formula version; \
         PAC2002 assumed"
            .to_string(),
    );
    Ok(MfVersion::Pac2002)
}
