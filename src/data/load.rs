//! load — from a file to a [`Recording`]: format detection, the raw table
//! as stored, channel identification, units and axes to ISO-W SI, dropped
//! rows counted, κ from wheel speed, warm-up cut and segments (the pipeline
//! of the module docs of [`crate::data`]).
//!
//! Must never: keep a NaN or out-of-range row silently, guess units a file
//! states, or panic on a malformed file.

use super::conventions::{self, AxisSample, AxisSystem};
use super::units::{self, Dim};
use super::{csvio, sanity, slip, slip_reference, structure, tdx, ttc};
use super::{Recording, Sample, SAMPLE_CHANNELS};
use crate::error::{Error, Result};
use std::path::Path;

/// File formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Format {
    /// FSAE TTC / Calspan MATLAB export (.mat, level 5).
    TtcMat,
    /// FSAE TTC / Calspan text export (.dat): names row, units row, data.
    TtcDat,
    /// TYDEX (.tdx).
    Tydex,
    /// CSV with a header (ISO-W SI unless units are given in the header).
    Csv,
}

impl Format {
    /// Parse `mat` | `dat` | `tdx` | `tydex` | `csv`.
    pub fn parse(s: &str) -> Option<Format> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mat" | "ttc-mat" => Some(Format::TtcMat),
            "dat" | "ttc-dat" | "ttc" => Some(Format::TtcDat),
            "tdx" | "tydex" => Some(Format::Tydex),
            "csv" => Some(Format::Csv),
            _ => None,
        }
    }
    /// Detect from content (magic bytes / markers) and then extension.
    pub fn detect(path: &Path, bytes: &[u8]) -> Option<Format> {
        let head = &bytes[..bytes.len().min(4096)];
        let text = String::from_utf8_lossy(head);
        if bytes.len() >= 128 && (&bytes[126..128] == b"IM" || &bytes[126..128] == b"MI") {
            return Some(Format::TtcMat);
        }
        if text.contains("**HEADER") || text.contains("**MEASURCHANNELS") {
            return Some(Format::Tydex);
        }
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "mat" => Some(Format::TtcMat),
            "tdx" => Some(Format::Tydex),
            "dat" => Some(Format::TtcDat),
            "csv" => Some(Format::Csv),
            _ => {
                let first = text.lines().next().unwrap_or("");
                if first.contains(',') {
                    Some(Format::Csv)
                } else if first.contains('\t') {
                    Some(Format::TtcDat)
                } else {
                    None
                }
            }
        }
    }
    /// Axis system this format uses unless told otherwise.
    pub fn default_axes(self) -> AxisSystem {
        match self {
            Format::TtcMat | Format::TtcDat => AxisSystem::Sae,
            Format::Tydex => AxisSystem::TydexW,
            Format::Csv => AxisSystem::Iso,
        }
    }
}

/// One column as stored in a file.
#[derive(Clone, Debug, PartialEq)]
pub struct RawColumn {
    /// Column name as written in the file (a `[unit]` suffix may still be attached).
    pub name: String,
    /// Unit as written in the file (`None` when the file gives none).
    pub unit: Option<String>,
    /// Values as stored, in the file's units and axes.
    pub data: Vec<f64>,
}

/// A file's content before interpretation: columns with names and units.
#[derive(Clone, Debug, Default)]
pub struct RawTable {
    /// The columns, in file order.
    pub columns: Vec<RawColumn>,
    /// Header/metadata entries (TTC `source`, `testid`, `tireid`; TYDEX header …).
    pub meta: Vec<(String, String)>,
    /// Axis system the file declares, if it does.
    pub axes: Option<AxisSystem>,
}

impl RawTable {
    /// Column by name (case-insensitive).
    pub fn column(&self, name: &str) -> Option<&RawColumn> {
        self.columns
            .iter()
            .find(|c| c.name.eq_ignore_ascii_case(name))
    }
    /// Number of rows (the shortest column).
    pub fn rows(&self) -> usize {
        self.columns.iter().map(|c| c.data.len()).min().unwrap_or(0)
    }
}

/// How the effective rolling radius in κ = Ω·Re/(V·cos α) − 1 is chosen.
#[derive(Clone, Debug, Default)]
pub enum ReChoice {
    /// The recorded RE channel, sample by sample. On a drive/brake rig the
    /// recorded RE is typically V/Ω, which slip itself disturbs: κ from it is
    /// biased towards zero in drive/brake runs.
    Recorded,
    /// The recorded loaded radius RL (underestimates Re by a few %).
    Loaded,
    /// The model's Re(Fz, …) via `Tyre::evaluate(...).re`.
    Model(Box<crate::mf::Tyre>),
    /// Re(Fz) fitted (Re = a + b·Fz, least squares) to the recorded RE over
    /// free-rolling samples (|α| < 1°, |Fx| < 5 % Fz), where it is undisturbed;
    /// falls back to [`ReChoice::Recorded`] then [`ReChoice::Loaded`].
    #[default]
    FreeRolling,
}

impl ReChoice {
    /// Parse `recorded` | `loaded` | `free-rolling` (the model choice needs a tyre).
    pub fn parse(s: &str) -> Option<ReChoice> {
        match s.trim().to_ascii_lowercase().as_str() {
            "recorded" | "re" => Some(ReChoice::Recorded),
            "loaded" | "rl" => Some(ReChoice::Loaded),
            "free-rolling" | "freerolling" | "auto" => Some(ReChoice::FreeRolling),
            _ => None,
        }
    }
}

/// Where κ comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KappaSource {
    /// A recorded κ channel when the format has one (CSV/TYDEX `kappa`,
    /// MFeval's `SR`), otherwise computed from wheel speed.
    #[default]
    Auto,
    /// Always computed from Ω, Re, V and α.
    Computed,
    /// Only the recorded channel (missing → κ missing).
    Recorded,
}

/// Options of [`load`].
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Force a format instead of detecting it.
    pub format: Option<Format>,
    /// Force an axis system instead of the format's/file's.
    pub axes: Option<AxisSystem>,
    /// Effective rolling radius for κ.
    pub re: ReChoice,
    /// Where κ comes from.
    pub kappa: KappaSource,
    /// Detect and cut the warm-up.
    pub remove_warmup: bool,
    /// Segmentation tolerances.
    pub segmentation: structure::SegmentOptions,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            format: None,
            axes: None,
            re: ReChoice::default(),
            kappa: KappaSource::default(),
            remove_warmup: true,
            segmentation: structure::SegmentOptions::default(),
        }
    }
}

/// What loading did to the file: the honest account users need.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LoadReport {
    /// Path of the file, as given.
    pub file: String,
    /// Format the file was read as (`Format` debug name, e.g. `TtcMat`).
    pub format: String,
    /// Axis system the file was read in (an [`AxisSystem::name`]), before conversion to ISO-W.
    pub axes: String,
    /// Rows in the file.
    pub rows_read: usize,
    /// Rows dropped, by reason ("Fy: NaN", "alpha: out of range [-1.571, 1.571]" …).
    pub dropped: Vec<(String, usize)>,
    /// Total rows dropped (a row is counted once, under its first failing channel).
    pub dropped_total: usize,
    /// Sample channels the file lacks.
    pub missing: Vec<String>,
    /// Extra channels kept, with their units.
    pub extra_units: Vec<(String, String)>,
    /// How κ was obtained.
    pub kappa: String,
    /// Which speed Vx (and so κ) refers to when only the belt speed is
    /// recorded, with the evidence ([`slip_reference`]); empty otherwise.
    pub slip_reference: String,
    /// The warm-up cut, if any.
    pub warmup: Option<structure::WarmupCut>,
    /// Other remarks (unknown units of extra channels, time going backwards …).
    pub notes: Vec<String>,
    /// Channels rejected as broken, each with the reason (their values are
    /// NaN, the rows kept: [`sanity`]).
    pub rejected: Vec<String>,
    /// File metadata (TTC source/testid/tireid, TYDEX header).
    pub meta: Vec<(String, String)>,
}

/// A loaded recording with its report.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The recording, ISO-W SI.
    pub recording: Recording,
    /// What loading did to the file.
    pub report: LoadReport,
}

/// The loader's word when no slip ratio can be had.
const KAPPA_MISSING: &str = "missing (no usable wheel speed / radius to compute it, no slip-ratio channel SR, and the run does not roll freely: drive/brake rows cannot be used)";

fn rec_err(file: &str, location: impl Into<String>, message: impl Into<String>) -> Error {
    Error::Recording {
        file: file.to_string(),
        location: location.into(),
        message: message.into(),
    }
}

/// Read a file into its raw table.
pub fn read_raw(path: &Path, format: Option<Format>) -> Result<(RawTable, Format)> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let file = path.display().to_string();
    // A gzip'd recording (`r01.dat.gz`) is read as the file inside it; the
    // format is told from the content and the name without `.gz`.
    let (bytes, inner) = if bytes.starts_with(&[0x1f, 0x8b]) {
        (gunzip(&bytes, &file)?, path.with_extension(""))
    } else {
        (bytes, path.to_path_buf())
    };
    let path = inner.as_path();
    let format = match format.or_else(|| Format::detect(path, &bytes)) {
        Some(f) => f,
        None => {
            return Err(rec_err(
                &file,
                "file",
                "cannot tell the format (not a MAT file, no TYDEX markers, unknown extension); use --format mat|dat|tdx|csv",
            ))
        }
    };
    let raw = match format {
        Format::TtcMat => ttc::read_mat(&bytes, &file)?,
        Format::TtcDat => ttc::read_dat(&bytes, &file)?,
        Format::Tydex => tdx::read(&bytes, &file)?,
        Format::Csv => csvio::read(&bytes, &file)?,
    };
    Ok((raw, format))
}

/// Largest size a gzip'd recording may inflate to (bytes): far above any
/// real test (a million rows of 20 channels is ≈ 200 MB of text), far below
/// what would exhaust memory.
pub const GZIP_MAX_INFLATED: u64 = 1 << 30;

/// Inflate a gzip'd recording, refusing one that inflates past
/// [`GZIP_MAX_INFLATED`] (a decompression bomb) with an error naming the file.
fn gunzip(bytes: &[u8], file: &str) -> Result<Vec<u8>> {
    use std::io::Read;
    let mut out = Vec::new();
    let mut dec = flate2::read::MultiGzDecoder::new(bytes).take(GZIP_MAX_INFLATED + 1);
    dec.read_to_end(&mut out)
        .map_err(|e| rec_err(file, "gzip", format!("cannot inflate: {e}")))?;
    if out.len() as u64 > GZIP_MAX_INFLATED {
        return Err(rec_err(
            file,
            "gzip",
            format!(
                "inflates to more than {} MiB; refused",
                GZIP_MAX_INFLATED >> 20
            ),
        ));
    }
    Ok(out)
}

/// Read, convert and structure a recording.
pub fn load(path: &Path, opts: &LoadOptions) -> Result<Loaded> {
    let (raw, format) = read_raw(path, opts.format)?;
    from_raw(raw, format, &path.display().to_string(), opts)
}

/// The core channels and their aliases (case-insensitive, unit suffix removed).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ch {
    Time,
    Vx,
    Speed,
    Omega,
    Fz,
    Kappa,
    Alpha,
    Gamma,
    Phit,
    P,
    Fx,
    Fy,
    Mx,
    My,
    Mz,
}

const ALIASES: &[(Ch, Dim, &[&str])] = &[
    (
        Ch::Time,
        Dim::Time,
        &["time", "t", "et", "elapsed_time", "runtime"],
    ),
    (Ch::Vx, Dim::Speed, &["vx", "longvel", "vx_w"]),
    (
        Ch::Speed,
        Dim::Speed,
        &["v", "speed", "roadspeed", "road_speed", "vel"],
    ),
    (
        Ch::Omega,
        Dim::AngularSpeed,
        &[
            "omega",
            "w",
            "n",
            "wheelspeed",
            "wheel_speed",
            "rotspeed",
            "rotveloc",
            "omega_w",
        ],
    ),
    (Ch::Fz, Dim::Force, &["fz", "fzw", "fzc", "fz_w", "load"]),
    (
        Ch::Kappa,
        Dim::Ratio,
        &["kappa", "longslip", "long_slip", "slipratio", "slip_ratio"],
    ),
    (
        Ch::Alpha,
        Dim::Angle,
        &["alpha", "sa", "slipangl", "slipangle", "slip_angle"],
    ),
    (
        Ch::Gamma,
        Dim::Angle,
        &[
            "gamma",
            "ia",
            "inclangl",
            "inclination",
            "camber",
            "incl_angle",
        ],
    ),
    (
        Ch::Phit,
        Dim::InvLength,
        &["phit", "phi_t", "turnslip", "turn_slip"],
    ),
    (
        Ch::P,
        Dim::Pressure,
        &["p", "pressure", "inflpres", "infl_pressure"],
    ),
    (Ch::Fx, Dim::Force, &["fx", "fxw", "fxc", "fx_w"]),
    (Ch::Fy, Dim::Force, &["fy", "fyw", "fyc", "fy_w"]),
    (Ch::Mx, Dim::Moment, &["mx", "mxw", "mxc", "mx_w"]),
    (Ch::My, Dim::Moment, &["my", "myw", "myc", "my_w"]),
    (Ch::Mz, Dim::Moment, &["mz", "mzw", "mzc", "mz_w"]),
];

/// Sample channel name of each core channel (road speed V stands for Vx).
const CH_NAMES: [(Ch, &str); 15] = [
    (Ch::Time, "time"),
    (Ch::Vx, "Vx"),
    (Ch::Speed, "Vx"),
    (Ch::Omega, "omega"),
    (Ch::Fz, "Fz"),
    (Ch::Kappa, "kappa"),
    (Ch::Alpha, "alpha"),
    (Ch::Gamma, "gamma"),
    (Ch::Phit, "phit"),
    (Ch::P, "P"),
    (Ch::Fx, "Fx"),
    (Ch::Fy, "Fy"),
    (Ch::Mx, "Mx"),
    (Ch::My, "My"),
    (Ch::Mz, "Mz"),
];

/// Known extra channels and their dimension (radii, slips, temperatures).
fn extra_dim(name: &str) -> Option<Dim> {
    let n = name.to_ascii_lowercase();
    match n.as_str() {
        "rl" | "re" | "r_l" | "r_e" | "rloaded" | "reff" | "radload" | "radeff" | "re_sr" => {
            Some(Dim::Length)
        }
        "sr" | "sl" | "nfx" | "nfy" => Some(Dim::Ratio),
        "rst" | "ambtmp" => Some(Dim::Temperature),
        _ if n.starts_with("tst") || n.contains("tmp") || n.contains("temp") => {
            Some(Dim::Temperature)
        }
        _ => None,
    }
}

/// SI unit this crate stores an extra channel in ("-" when unknown).
pub fn extra_si_unit(name: &str) -> &'static str {
    extra_dim(name).map_or("-", |d| d.si())
}

/// Canonical extra name: radii as `Rl`/`Re`, the rest as written.
fn extra_name(name: &str) -> String {
    match name.to_ascii_lowercase().as_str() {
        "rl" | "r_l" | "rloaded" | "radload" => "Rl".into(),
        "re" | "r_e" | "reff" | "radeff" => "Re".into(),
        _ => name.to_string(),
    }
}

/// Range checks on ISO-W SI values: (channel, min, max).
const RANGES: [(&str, f64, f64); 13] = [
    ("time", f64::MIN, f64::MAX),
    ("Vx", -150.0, 150.0),
    ("omega", -3000.0, 3000.0),
    ("Fz", -500.0, 2e5),
    ("kappa", -10.0, 10.0),
    (
        "alpha",
        -std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_2,
    ),
    ("gamma", -0.6, 0.6),
    ("phit", -100.0, 100.0),
    ("P", 0.0, 2e7),
    ("Fx", -2e5, 2e5),
    ("Fy", -2e5, 2e5),
    ("Mx", -5e4, 5e4),
    ("Mz", -5e4, 5e4),
];

/// Interpret a raw table: see the module documentation for the steps.
pub fn from_raw(raw: RawTable, format: Format, file: &str, opts: &LoadOptions) -> Result<Loaded> {
    let ttc = matches!(format, Format::TtcMat | Format::TtcDat);
    let axes = opts.axes.or(raw.axes).unwrap_or(format.default_axes());
    let n = raw.rows();
    let mut report = LoadReport {
        file: file.to_string(),
        format: format!("{format:?}"),
        axes: axes.name().into(),
        rows_read: n,
        meta: raw.meta.clone(),
        ..Default::default()
    };
    if n == 0 {
        return Err(rec_err(file, "data", "no data rows"));
    }
    // Identify the core channels; everything else is extra.
    let mut core: Vec<(Ch, Vec<f64>)> = Vec::new();
    let mut core_units: Vec<(Ch, Option<String>)> = Vec::new();
    let mut extra: Vec<(String, Vec<f64>)> = Vec::new();
    for col in &raw.columns {
        let (name, hdr_unit) = units::split_header(&col.name);
        let unit = col.unit.clone().or(hdr_unit);
        let lname = name.to_ascii_lowercase();
        // TTC: SR/SL are Calspan's own slip ratios, kept as extras; elsewhere SR is κ.
        let is_kappa_alias = !ttc && (lname == "sr" || lname == "slip");
        let found = ALIASES
            .iter()
            .find(|(_, _, al)| al.contains(&lname.as_str()))
            .map(|(c, d, _)| (*c, *d))
            .or(if is_kappa_alias {
                Some((Ch::Kappa, Dim::Ratio))
            } else {
                None
            });
        if let Some((ch, dim)) = found {
            if core.iter().any(|(c, _)| *c == ch) {
                report.notes.push(format!(
                    "column '{}' duplicates an earlier {ch:?} column: kept as extra",
                    col.name
                ));
                report
                    .extra_units
                    .push((name.clone(), unit.clone().unwrap_or_default()));
                extra.push((name.clone(), col.data[..n].to_vec()));
                continue;
            }
            // CSV without units is ISO-W SI by definition of the format.
            let conv = match &unit {
                Some(u) => units::to_si(dim, u).ok_or_else(|| {
                    rec_err(
                        file,
                        format!("channel '{name}'"),
                        format!(
                            "unknown unit '{u}' for a {dim:?} channel (expected e.g. {})",
                            dim.si()
                        ),
                    )
                })?,
                None if format == Format::Csv => units::ToSi {
                    scale: 1.0,
                    offset: 0.0,
                },
                None => {
                    return Err(rec_err(
                        file,
                        format!("channel '{name}'"),
                        "the file gives no unit for this channel",
                    ));
                }
            };
            let data: Vec<f64> = col.data[..n]
                .iter()
                .map(|&x| x * conv.scale + conv.offset)
                .collect();
            core.push((ch, data));
            core_units.push((ch, unit.clone()));
        } else {
            let ename = extra_name(&name);
            let mut data = col.data[..n].to_vec();
            let mut unit_out = unit.clone().unwrap_or_default();
            if let (Some(dim), Some(u)) = (extra_dim(&name), unit.as_ref()) {
                if let Some(c) = units::to_si(dim, u) {
                    data.iter_mut().for_each(|x| *x = *x * c.scale + c.offset);
                    unit_out = dim.si().into();
                } else {
                    report
                        .notes
                        .push(format!("extra channel '{name}': unit '{u}' not converted"));
                }
            } else if let (Some(dim), None) = (extra_dim(&name), unit.as_ref()) {
                unit_out = dim.si().into();
            }
            report.extra_units.push((ename.clone(), unit_out));
            extra.push((ename, data));
        }
    }
    let get = |c: Ch| {
        core.iter()
            .find(|(x, _)| *x == c)
            .map(|(_, v)| v.as_slice())
    };
    let nan = vec![f64::NAN; n];
    let col = |c: Ch| get(c).unwrap_or(&nan);
    let rl_col = extra
        .iter()
        .find(|(nm, _)| nm == "Rl")
        .map(|(_, v)| v.clone());

    // Build ISO-W samples.
    let alpha_raw = col(Ch::Alpha);
    let conv = conventions::ToIso::new(axes);
    let mut samples: Vec<Sample> = Vec::with_capacity(n);
    for i in 0..n {
        let a = AxisSample {
            fx: col(Ch::Fx)[i],
            fy: col(Ch::Fy)[i],
            fz: col(Ch::Fz)[i],
            mx: col(Ch::Mx)[i],
            my: col(Ch::My)[i],
            mz: col(Ch::Mz)[i],
            alpha: alpha_raw[i],
            gamma: col(Ch::Gamma)[i],
            kappa: col(Ch::Kappa)[i],
            phit: col(Ch::Phit)[i],
            rl: rl_col.as_ref().map_or(f64::NAN, |r| r[i]),
        };
        let w = conv.apply(&a);
        let vx = match (get(Ch::Vx), get(Ch::Speed)) {
            (Some(v), _) => v[i],
            (None, Some(v)) => {
                v[i] * if w.alpha.is_finite() {
                    w.alpha.cos()
                } else {
                    1.0
                }
            }
            _ => f64::NAN,
        };
        samples.push(Sample {
            time: col(Ch::Time)[i],
            vx,
            omega: col(Ch::Omega)[i].abs(),
            fz: w.fz,
            kappa: w.kappa,
            alpha: w.alpha,
            gamma: w.gamma,
            phit: w.phit,
            p: col(Ch::P)[i],
            fx: w.fx,
            fy: w.fy,
            mx: w.mx,
            my: w.my,
            mz: w.mz,
        });
    }
    if axes == AxisSystem::TydexC && rl_col.is_none() {
        return Err(rec_err(
            file,
            "channel 'RL'",
            "TYDEX C recordings need the loaded radius to move moments to the contact point",
        ));
    }
    let mut channels: Vec<String> = Vec::new();
    let has = |c: Ch| get(c).is_some();
    for (name, ok) in [
        ("time", has(Ch::Time)),
        ("Vx", has(Ch::Vx) || has(Ch::Speed)),
        ("omega", has(Ch::Omega)),
        ("Fz", has(Ch::Fz)),
        ("kappa", has(Ch::Kappa)),
        ("alpha", has(Ch::Alpha)),
        ("gamma", has(Ch::Gamma)),
        ("phit", has(Ch::Phit)),
        ("P", has(Ch::P)),
        ("Fx", has(Ch::Fx)),
        ("Fy", has(Ch::Fy)),
        ("Mx", has(Ch::Mx)),
        ("My", has(Ch::My)),
        ("Mz", has(Ch::Mz)),
    ] {
        if ok {
            channels.push(name.into());
        }
    }
    if !has(Ch::Time) {
        // A recording without time gets the row index as time, said loudly.
        report
            .notes
            .push("no time channel: time = row index (s)".into());
        samples
            .iter_mut()
            .enumerate()
            .for_each(|(i, s)| s.time = i as f64);
        channels.insert(0, "time".into());
    }
    if !has(Ch::Fz) {
        return Err(rec_err(
            file,
            "channel 'FZ'",
            "no normal load channel (FZ/Fz): cannot interpret a tyre recording without it",
        ));
    }

    // Sign and unit slips stop here; broken channels are rejected (rows kept).
    let unit_of = |name: &str| {
        let ch = CH_NAMES.iter().find(|(_, n)| *n == name)?.0;
        core_units.iter().find(|(c, _)| *c == ch)?.1.clone()
    };
    sanity::check_conventions(&samples, &channels, axes, &unit_of, file)?;
    sanity::check_wheel_speed(&mut samples, &mut channels, &mut report);
    sanity::check_radii(&samples, &mut extra, &mut report);
    sanity::check_pinned_slip(&mut samples, &mut channels, &mut extra, &mut report);
    // Belt speed only: which speed the tyre's slip refers to is read from the
    // free-rolling samples ([`slip_reference`]); Vx follows it.
    if let (None, Some(v)) = (get(Ch::Vx), get(Ch::Speed)) {
        let evidence = channels
            .iter()
            .any(|c| c == "omega")
            .then(|| slip_reference::detect(&samples, v))
            .flatten();
        report.slip_reference = match evidence {
            Some(e) => {
                for (s, &vi) in samples.iter_mut().zip(v) {
                    s.vx = e.reference.vx(vi, s.alpha);
                }
                e.describe()
            }
            None => format!(
                "{} (textbook default: the free-rolling samples cannot decide)",
                slip_reference::SlipReference::WheelPlane.describe()
            ),
        };
    }
    let has_kappa = channels.iter().any(|c| c == "kappa");
    let rl_col = extra
        .iter()
        .find(|(nm, _)| nm == "Rl")
        .map(|(_, v)| v.clone());

    // κ from wheel speed, if asked or needed (before the row filter so that
    // non-finite κ is counted as a dropped row).
    let want_computed = match opts.kappa {
        KappaSource::Computed => true,
        KappaSource::Recorded => false,
        KappaSource::Auto => !has_kappa,
    };
    // Rows whose κ cannot be known (drive/brake rows without any slip
    // information): dropped and counted below, with that reason.
    let mut kappa_unknown: Option<Vec<bool>> = None;
    if want_computed {
        let re = extra
            .iter()
            .find(|(nm, _)| nm == "Re")
            .map(|(_, v)| v.as_slice());
        let rl = rl_col.as_deref();
        let sr = extra
            .iter()
            .find(|(nm, _)| nm.eq_ignore_ascii_case("SR"))
            .map(|(_, v)| v.as_slice());
        let omega_ok = channels.iter().any(|c| c == "omega");
        let computed = if omega_ok {
            slip::compute_kappa(&mut samples, re, rl, sr, &opts.re)
        } else {
            None
        };
        match computed {
            Some(slip::KappaComputed { how, slip_radius }) => {
                if let Some(r) = slip_radius {
                    extra.push((slip::SLIP_RADIUS_CHANNEL.to_string(), r));
                }
                if has_kappa {
                    report
                        .notes
                        .push("recorded κ replaced by κ computed from wheel speed".into());
                }
                report.kappa = how;
                if !channels.iter().any(|c| c == "kappa") {
                    channels.push("kappa".into());
                }
            }
            // No usable wheel speed, but the rig's own slip ratio: κ is it
            // (the channel the wheel speed would otherwise be checked against).
            None if !has_kappa && sr.is_some_and(slip::plausible_slip_ratio) => {
                let sr = sr.unwrap_or_default();
                for (s, &x) in samples.iter_mut().zip(sr) {
                    s.kappa = x;
                }
                channels.push("kappa".into());
                report.kappa = "κ = the recorded slip ratio SR (no usable wheel speed to compute or check it; a replay prescribes these slips)".into();
            }
            // No usable wheel speed or slip channel on a freely rolling run
            // (a cornering-only test): free rolling, κ = 0, said so.
            None if !has_kappa
                && sanity::free_rolling_run(&samples, channels.iter().any(|c| c == "Fx")) =>
            {
                samples.iter_mut().for_each(|s| s.kappa = 0.0);
                channels.push("kappa".into());
                let why = if has(Ch::Omega) || has(Ch::Kappa) {
                    "no usable wheel speed"
                } else {
                    "no wheel speed or slip channel recorded"
                };
                report.kappa = format!(
                    "κ = 0: {why}, and the run rolls freely (Fx/Fz within {} of its free-rolling level on 95 % of the loaded rows)",
                    sanity::FREE_ROLLING_FX
                );
            }
            // Neither, on a recording that also drives and brakes: κ = 0
            // where it rolls freely for seconds on end (its cornering
            // blocks), and the drive/brake rows, whose slip is unknown, go.
            None if !has_kappa => match sanity::free_rolling_stretches(&samples) {
                Some(mask) => {
                    for (s, &m) in samples.iter_mut().zip(&mask) {
                        s.kappa = if m { 0.0 } else { f64::NAN };
                    }
                    channels.push("kappa".into());
                    let free = mask.iter().filter(|m| **m).count();
                    report.kappa = format!(
                        "κ = 0 on the freely rolling stretches ({free} rows: Fx/Fz within {} of its free-rolling level for {} s or longer); no wheel speed or slip channel gives the slip of the other {} rows, which are dropped",
                        sanity::FREE_ROLLING_FX,
                        sanity::FREE_ROLLING_STRETCH_S,
                        mask.len() - free
                    );
                    kappa_unknown = Some(mask);
                }
                None => report.kappa = KAPPA_MISSING.into(),
            },
            None => report.kappa = KAPPA_MISSING.into(),
        }
    } else if has_kappa {
        report.kappa = "recorded channel".into();
    } else {
        report.kappa = "missing".into();
    }
    // A force channel that does not follow its slip is dead (needs κ).
    sanity::check_dead_forces(&mut samples, &mut channels, &mut report);
    // An aligning moment that does not follow Fy is dead (needs live Fy).
    sanity::check_dead_moment(&mut samples, &mut channels, &mut report);
    let sample_ch_order = SAMPLE_CHANNELS;
    channels.sort_by_key(|c| sample_ch_order.iter().position(|x| x == c).unwrap_or(99));
    for c in SAMPLE_CHANNELS {
        if !channels.iter().any(|x| x == c) {
            report.missing.push(c.to_string());
        }
    }

    // Drop rows with NaN/out-of-range values in the channels the file has.
    let checks: Vec<(usize, f64, f64)> = RANGES
        .iter()
        .filter(|(c, _, _)| channels.iter().any(|x| x == c))
        .map(|(c, lo, hi)| {
            (
                SAMPLE_CHANNELS.iter().position(|x| x == c).unwrap_or(0),
                *lo,
                *hi,
            )
        })
        .collect();
    // A channel bad on more than `sanity::REJECT_SHARE` of the rows is
    // broken: it is rejected, the rows stay (κ counts only rows that move:
    // standing rows have no slip ratio and are dropped as before).
    let mut checks = checks;
    for &(k, lo, hi) in checks.clone().iter() {
        let c = SAMPLE_CHANNELS[k];
        if !sanity::REJECTABLE.contains(&c) || (c == "kappa" && kappa_unknown.is_some()) {
            continue;
        }
        let rows = samples
            .iter()
            .filter(|s| c != "kappa" || (s.vx.is_finite() && s.vx.abs() > 1.0));
        let (mut total, mut nan, mut out) = (0usize, 0usize, 0usize);
        for s in rows {
            let x = s.values()[k];
            total += 1;
            nan += usize::from(!x.is_finite());
            out += usize::from(x.is_finite() && (x < lo || x > hi));
        }
        if total > 0 && (nan + out) as f64 > sanity::REJECT_SHARE * total as f64 {
            let why = if out >= nan {
                format!(
                    "{:.1} % of its values outside [{lo}, {hi}] (ISO-W SI)",
                    100.0 * out as f64 / total as f64
                )
            } else {
                format!(
                    "{:.1} % of its values NaN or infinite",
                    100.0 * nan as f64 / total as f64
                )
            };
            sanity::reject(&mut samples, &mut channels, &mut report, c, why);
            report.missing.push(c.to_string());
            checks.retain(|x| x.0 != k);
        }
    }
    let mut counts = vec![0usize; SAMPLE_CHANNELS.len() * 2];
    let mut keep = vec![true; n];
    let mut unknown_slip = 0usize;
    for (i, s) in samples.iter().enumerate() {
        if kappa_unknown.as_ref().is_some_and(|m| !m[i]) {
            unknown_slip += 1;
            keep[i] = false;
            continue;
        }
        let v = s.values();
        for &(k, lo, hi) in &checks {
            let x = v[k];
            if !x.is_finite() {
                counts[2 * k] += 1;
                keep[i] = false;
                break;
            }
            if x < lo || x > hi {
                counts[2 * k + 1] += 1;
                keep[i] = false;
                break;
            }
        }
    }
    for (k, c) in SAMPLE_CHANNELS.iter().enumerate() {
        if counts[2 * k] > 0 {
            report
                .dropped
                .push((format!("{c}: NaN or infinite"), counts[2 * k]));
        }
        if counts[2 * k + 1] > 0 {
            let (_, lo, hi) = RANGES
                .iter()
                .find(|(x, _, _)| x == c)
                .copied()
                .unwrap_or(("", 0.0, 0.0));
            report.dropped.push((
                format!("{c}: outside [{lo}, {hi}] (ISO-W SI)"),
                counts[2 * k + 1],
            ));
        }
    }
    if unknown_slip > 0 {
        report.dropped.push((
            "kappa: unknown (driving or braking, and no wheel speed or slip channel)".into(),
            unknown_slip,
        ));
    }
    report.dropped_total = keep.iter().filter(|k| !**k).count();
    if report.dropped_total > 0 {
        let mut j = 0;
        samples.retain(|_| {
            j += 1;
            keep[j - 1]
        });
        for (_, v) in extra.iter_mut() {
            let mut j = 0;
            v.retain(|_| {
                j += 1;
                keep[j - 1]
            });
        }
    }
    if samples.is_empty() {
        return Err(rec_err(
            file,
            "data",
            format!("all {n} rows were dropped: {:?}", report.dropped),
        ));
    }
    if samples.windows(2).any(|w| w[1].time < w[0].time) {
        report
            .notes
            .push("time goes backwards somewhere: segments are split there".into());
    }

    let mut rec = Recording {
        source: raw
            .meta
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case("source"))
            .map(|(_, v)| format!("{file} ({v})"))
            .unwrap_or_else(|| file.to_string()),
        samples,
        channels,
        extra,
        ..Default::default()
    };
    structure::apply(
        &mut rec,
        opts.remove_warmup,
        &opts.segmentation,
        &mut report,
    );
    Ok(Loaded {
        recording: rec,
        report,
    })
}
