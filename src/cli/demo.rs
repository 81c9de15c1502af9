//! `tyrekit demo` — package the FMU, load it as a master would (unzip + dlopen)
//! and run two short co-simulations of the default tyre, printing the results:
//! a slip-angle ramp (input_mode = velocities: vy swept at constant vx, free
//! rolling) and a braking slip ramp (input_mode = slips: kappa_in swept).
//! Must never: compute tyre forces itself (every number printed comes out of the FMU).

use crate::fmi::master::{callbacks, Fmu};
use crate::fmi::packaging;
use crate::fmi::vars::vr;
use std::path::PathBuf;

/// Arguments of `tyrekit demo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Tyre property file to package (default: the built-in tyre).
    #[arg(long, value_name = "FILE")]
    pub tir: Option<PathBuf>,
    /// Normal load (N).
    #[arg(long, default_value_t = 4000.0)]
    pub fz: f64,
    /// Speed (m/s).
    #[arg(long, default_value_t = 20.0)]
    pub vx: f64,
}

/// Run the command.
pub fn run(args: Args) -> crate::Result<()> {
    let fmu_path = packaging::package(&packaging::Options {
        tir: args.tir.clone(),
        ..Default::default()
    })?;
    println!("packaged {}", fmu_path.display());
    let dir = packaging::scratch_dir("demo");
    let result = simulate(&fmu_path, &dir, &args);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn simulate(fmu_path: &std::path::Path, dir: &std::path::Path, args: &Args) -> crate::Result<()> {
    let fmu = Fmu::open(fmu_path, dir)?;
    println!(
        "FMU library: {}",
        packaging::EMBEDDED_BUILD
    );
    let cb = callbacks();
    let outs = [vr::FX, vr::FY, vr::MZ, vr::MX, vr::KAPPA, vr::ALPHA, vr::RE];
    let mut y = [0.0; 7];
    let (h, n, every) = (1e-3, 1000usize, 100usize);

    println!(
        "\n1) slip-angle ramp: vx = {} m/s, Fz = {} N, free rolling, vy ramp to |alpha| = 12 deg in {} s (input_mode = velocities)",
        args.vx,
        args.fz,
        h * n as f64
    );
    println!(
        "{:>6} {:>9} {:>10} {:>10} {:>9} {:>9}",
        "t [s]", "alpha[deg]", "Fy [N]", "Mz [N m]", "Mx [N m]", "Fx [N]"
    );
    let s = fmu.slave("slip_angle_ramp", &cb, &[])?;
    let omega = free_rolling_omega(&s, args)?;
    for k in 0..=n {
        let t = k as f64 * h;
        let a = (12.0f64).to_radians() * t / (h * n as f64);
        // vy = vx tan(a): |alpha| ramps to 12 deg; its sign is the transient
        // model's ISO-W convention, printed as the FMU reports it.
        s.set_real(&[vr::VY, vr::OMEGA], &[args.vx * a.tan(), omega])?;
        s.do_step(t, h)?;
        s.get_real(&outs, &mut y)?;
        if k % every == 0 {
            println!(
                "{:>6.3} {:>9.2} {:>10.1} {:>10.2} {:>9.2} {:>9.1}",
                t + h,
                y[5].to_degrees(),
                y[1],
                y[2],
                y[3],
                y[0]
            );
        }
    }
    drop(s);

    println!(
        "\n2) braking slip ramp: vx = {} m/s, Fz = {} N, kappa 0 -> -0.3 in {} s (input_mode = slips)",
        args.vx,
        args.fz,
        h * n as f64
    );
    println!(
        "{:>6} {:>9} {:>10} {:>9}",
        "t [s]", "kappa", "Fx [N]", "My [N m]"
    );
    let s = fmu.slave("braking_ramp", &cb, &[(vr::INPUT_MODE, "slips")])?;
    s.set_real(&[vr::VX, vr::FZ, vr::KAPPA_IN], &[args.vx, args.fz, 0.0])?;
    s.exit_initialization()?;
    let mut z = [0.0; 3];
    for k in 0..=n {
        let t = k as f64 * h;
        let kappa = -0.3 * t / (h * n as f64);
        s.set_real(&[vr::KAPPA_IN], &[kappa])?;
        s.do_step(t, h)?;
        s.get_real(&[vr::KAPPA, vr::FX, vr::MY], &mut z)?;
        if k % every == 0 {
            println!("{:>6.3} {:>9.4} {:>10.1} {:>9.2}", t + h, z[0], z[1], z[2]);
        }
    }
    Ok(())
}

/// Initialise `s` at the demo's `vx` and `Fz` rolling freely (κ = 0) and
/// return that spin rate. The FMU starts free rolling at FNOMIN and its start
/// vx; ω is rescaled to the demo's vx, and after initialisation (outputs = the
/// start inputs) corrected with the Re the FMU reports at the demo's load (Re
/// depends on Ω only through the centrifugal growth, so |κ| is then ~1e-6).
fn free_rolling_omega(s: &crate::fmi::master::Slave, args: &Args) -> crate::Result<f64> {
    let mut start = [0.0; 2];
    s.get_real(&[vr::VX, vr::OMEGA], &mut start)?;
    let guess = start[1] * args.vx / start[0];
    s.set_real(&[vr::VX, vr::FZ, vr::VY, vr::OMEGA], &[args.vx, args.fz, 0.0, guess])?;
    s.exit_initialization()?;
    let mut re = [0.0];
    s.get_real(&[vr::RE], &mut re)?;
    Ok(args.vx / re[0])
}
