//! `tyrekit brush study` — Guan & Dang's study of the tread's stiffness
//! (`crate::brush::sensitivity`): C_y and K_z and their elasticities to the
//! tread shear stiffness c_py over c_py0/32..32·c_py0, printed as a table and
//! written as `brush_study.csv` and `brush_study.svg`.
//!
//! Must never: write a partial CSV without an error, or plot non-finite values.

use crate::brush::{
    sensitivity, string_cornering_stiffness, BrushParams, StudyRow, BETA_MIN, STUDY_FACTORS,
};
use crate::error::{Error, Result};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// `tyrekit brush …`.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// The paper's study: sensitivity of the cornering stiffness and of the
    /// vertical stiffness to the tread's shear stiffness (CSV, SVG, table).
    Study(StudyArgs),
}

/// Arguments of `tyrekit brush study`.
#[derive(clap::Args, Debug)]
pub struct StudyArgs {
    /// Tyre file (its [BRUSH] section, or the brush derived from its MF);
    /// the built-in tyre when absent.
    #[arg(long)]
    pub tir: Option<PathBuf>,
    /// Output directory for brush_study.csv and brush_study.svg.
    #[arg(long, default_value = "brush-study")]
    pub out: PathBuf,
    /// Contact points M (default 64, the solver's maximum: the study wants the
    /// converged model, not the real-time one).
    #[arg(long, default_value_t = crate::brush::M_MAX)]
    pub points: usize,
    /// Tread compression-to-shear modulus ratio β = E_c/G (≥ 3; 3 is the
    /// unconfined block, the largest vertical sensitivity).
    #[arg(long, default_value_t = BETA_MIN)]
    pub beta: f64,
}

/// Run `tyrekit brush …`.
pub fn run(c: Command) -> Result<()> {
    match c {
        Command::Study(a) => study(a),
    }
}

fn study(a: StudyArgs) -> Result<()> {
    let tyre = match &a.tir {
        Some(p) => super::load_tyre(p)?,
        None => crate::mf::Tyre::builtin(),
    };
    if !(a.beta.is_finite() && a.beta >= BETA_MIN) {
        return Err(Error::Input(format!(
            "brush study --beta {}: expected a number >= {BETA_MIN} (E_c/G of rubber)",
            a.beta
        )));
    }
    if !(1..=crate::brush::M_MAX).contains(&a.points) {
        return Err(Error::Input(format!(
            "brush study --points {}: expected 1..={}",
            a.points,
            crate::brush::M_MAX
        )));
    }
    let (b0, _) = BrushParams::from_tyre(&tyre)?;
    let b = BrushParams {
        points: a.points,
        ..b0
    };
    let rows = sensitivity(&b, &STUDY_FACTORS, a.beta)?;
    let patch = b.patch(b.fz0);
    let c_string = string_cornering_stiffness(&b, patch.a);
    println!(
        "brush study at FNOMIN {:.0} N: a = {:.4} m, CPY0 = {:.4e} N/m2, carcass h = {:.4e} m/N, SIGMA_C = {:.3} m, VERTICAL_STIFFNESS {:.4e} N/m, beta = {}, M = {}",
        b.fz0, patch.a, b.cpy, b.compliance, b.sigma_c, b.cz, a.beta, b.points
    );
    println!(
        "limits: c_py -> inf: string C_y = (sigma_c + a)^2/(sigma_c h) = {c_string:.4e} N/rad; c_py -> 0: C_y -> 2 c_py a^2 -> 0"
    );
    println!("cpy/cpy0   cpy [N/m2]   C_y [N/rad]   K_z [N/m]   dlnCy/dlncpy  dlnKz/dlncpy  ratio");
    for r in &rows {
        println!(
            "{:8.4}  {:11.4e}  {:12.5e}  {:10.5e}  {:12.4}  {:12.4}  {:6.1}",
            r.cpy_rel,
            r.cpy,
            r.cy,
            r.kz,
            r.e_cy,
            r.e_kz,
            r.e_cy / r.e_kz
        );
    }
    std::fs::create_dir_all(&a.out).map_err(|e| Error::io(&a.out, e))?;
    let csv = a.out.join("brush_study.csv");
    write_csv(&csv, &rows)?;
    let svg = a.out.join("brush_study.svg");
    plot(&svg, &rows)?;
    println!("wrote {} and {}", csv.display(), svg.display());
    Ok(())
}

fn write_csv(path: &Path, rows: &[StudyRow]) -> Result<()> {
    let mut w = csv::Writer::from_path(path)
        .map_err(|e| Error::Other(format!("{}: {e}", path.display())))?;
    let err = |e: csv::Error| Error::Other(format!("{}: {e}", path.display()));
    w.write_record([
        "cpy_rel",
        "cpy_N_per_m2",
        "cy_N_per_rad",
        "kz_N_per_m",
        "elasticity_cy",
        "elasticity_kz",
    ])
    .map_err(err)?;
    for r in rows {
        w.write_record([r.cpy_rel, r.cpy, r.cy, r.kz, r.e_cy, r.e_kz].map(|x| format!("{x:.6e}")))
            .map_err(err)?;
    }
    w.flush().map_err(|e| Error::io(path, e))
}

fn plot(path: &Path, rows: &[StudyRow]) -> Result<()> {
    let perr =
        |e: &dyn std::fmt::Display| Error::Other(format!("{}: cannot draw: {e}", path.display()));
    if rows
        .iter()
        .any(|r| ![r.cy, r.kz, r.e_cy, r.e_kz].iter().all(|x| x.is_finite()))
    {
        return Err(Error::Other(format!(
            "{}: the study has non-finite values; not plotted",
            path.display()
        )));
    }
    let x = |r: &StudyRow| r.cpy_rel.log2();
    let (x0, x1) = (x(&rows[0]), x(&rows[rows.len() - 1]));
    let i0 = rows.iter().position(|r| r.cpy_rel == 1.0).unwrap_or(0);
    let root = SVGBackend::new(path, (1100, 450)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| perr(&e))?;
    let (left, right) = root.split_horizontally(550);
    // Left: stiffnesses relative to the file's tread.
    let ymax = rows
        .iter()
        .map(|r| (r.cy / rows[i0].cy).max(r.kz / rows[i0].kz))
        .fold(0.0, f64::max)
        * 1.05;
    let mut ch = ChartBuilder::on(&left)
        .margin(8)
        .caption("C_y/C_y0 (blue), K_z/K_z0 (red)", ("sans-serif", 16))
        .x_label_area_size(32)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1, 0.0..ymax)
        .map_err(|e| perr(&e))?;
    ch.configure_mesh()
        .x_desc("log2(c_py / c_py0)")
        .y_desc("stiffness / value at c_py0")
        .draw()
        .map_err(|e| perr(&e))?;
    for (col, f) in [
        (
            &BLUE,
            (|r: &StudyRow, z: &StudyRow| r.cy / z.cy) as fn(&StudyRow, &StudyRow) -> f64,
        ),
        (&RED, |r, z| r.kz / z.kz),
    ] {
        ch.draw_series(LineSeries::new(
            rows.iter().map(|r| (x(r), f(r, &rows[i0]))),
            col,
        ))
        .map_err(|e| perr(&e))?;
        ch.draw_series(
            rows.iter()
                .map(|r| Circle::new((x(r), f(r, &rows[i0])), 3, col.filled())),
        )
        .map_err(|e| perr(&e))?;
    }
    // Right: elasticities.
    let mut ch = ChartBuilder::on(&right)
        .margin(8)
        .caption(
            "d ln C_y/d ln c_py (blue), d ln K_z/d ln c_py (red)",
            ("sans-serif", 16),
        )
        .x_label_area_size(32)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1, 0.0..1.0)
        .map_err(|e| perr(&e))?;
    ch.configure_mesh()
        .x_desc("log2(c_py / c_py0)")
        .y_desc("elasticity")
        .draw()
        .map_err(|e| perr(&e))?;
    for (col, f) in [
        (&BLUE, (|r: &StudyRow| r.e_cy) as fn(&StudyRow) -> f64),
        (&RED, |r| r.e_kz),
    ] {
        ch.draw_series(LineSeries::new(rows.iter().map(|r| (x(r), f(r))), col))
            .map_err(|e| perr(&e))?;
        ch.draw_series(
            rows.iter()
                .map(|r| Circle::new((x(r), f(r)), 3, col.filled())),
        )
        .map_err(|e| perr(&e))?;
    }
    root.present().map_err(|e| perr(&e))?;
    Ok(())
}
