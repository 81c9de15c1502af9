//! The FMU as a user gets it (issue #18): the packaged `binaries/linux64` library
//! needs no glibc symbol version above the stated floor and is stripped; and
//! `cargo install` + `tyrekit package` from an empty directory, far from the
//! source tree, writes a working `./TyreKit.fmu`.
//!
//! The portable build needs `cargo-zigbuild` and `ziglang` (PyPI), which
//! `scripts/test-all` installs into `.venv`; build.rs finds them there.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The glibc floor README states: the library loads on glibc >= 2.17.
const GLIBC_FLOOR: (u32, u32) = (2, 17);

fn package(bin: &Path, cwd: &Path, out: Option<&Path>) -> PathBuf {
    let mut cmd = Command::new(bin);
    cmd.arg("package")
        .current_dir(cwd)
        .env_remove("CARGO_TARGET_DIR");
    if let Some(o) = out {
        cmd.arg("--out").arg(o);
    }
    let o = cmd.output().expect("running tyrekit package");
    assert!(
        o.status.success(),
        "tyrekit package: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let printed = String::from_utf8_lossy(&o.stdout).trim().to_string();
    cwd.join(printed)
}

fn entry(fmu: &Path, name: &str) -> Vec<u8> {
    let f = std::fs::File::open(fmu).unwrap();
    let mut z = zip::ZipArchive::new(f).expect("an .fmu is a zip");
    let mut e = z
        .by_name(name)
        .unwrap_or_else(|_| panic!("{name} not in {}", fmu.display()));
    let mut b = Vec::new();
    e.read_to_end(&mut b).unwrap();
    b
}

/// A fixed folder under cargo's target/tmp, emptied at each use (bounded:
/// one per name, not one per run).
fn target_scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("portable-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The highest `GLIBC_x.y` version the library's dynamic symbols need.
fn max_glibc(so: &Path) -> (u32, u32) {
    let o = Command::new("objdump")
        .arg("-T")
        .arg(so)
        .output()
        .expect("objdump (binutils)");
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    text.split(|c: char| c.is_whitespace() || c == '(' || c == ')')
        .filter_map(|w| w.strip_prefix("GLIBC_"))
        .filter_map(|v| {
            let mut it = v.split('.').map(|x| x.parse::<u32>().ok());
            Some((it.next()??, it.next().flatten().unwrap_or(0)))
        })
        .max()
        .expect("no GLIBC symbol versions found: not a glibc-linked library?")
}

#[test]
fn packaged_library_needs_at_most_the_glibc_floor_and_is_stripped() {
    let dir = target_scratch("glibc");
    let fmu = package(
        Path::new(env!("CARGO_BIN_EXE_tyrekit")),
        &dir,
        Some(&dir.join("t.fmu")),
    );
    let so = dir.join("TyreKit.so");
    std::fs::write(&so, entry(&fmu, "binaries/linux64/TyreKit.so")).unwrap();
    let (a, b) = max_glibc(&so);
    assert!(
        (a, b) <= GLIBC_FLOOR,
        "the FMU library needs GLIBC_{a}.{b}, above the floor {}.{}: build with cargo-zigbuild \
         (scripts/test-all installs it into .venv; see README, Portability)",
        GLIBC_FLOOR.0,
        GLIBC_FLOOR.1
    );
    // Stripped: no static symbol table, and the 34 FMI 2.0 CS exports remain.
    let h = Command::new("objdump").arg("-h").arg(&so).output().unwrap();
    assert!(
        !String::from_utf8_lossy(&h.stdout).contains(".symtab"),
        "library not stripped"
    );
    let nm = Command::new("nm")
        .args(["-D", "--defined-only"])
        .arg(&so)
        .output()
        .unwrap();
    let n = String::from_utf8_lossy(&nm.stdout)
        .lines()
        .filter(|l| l.contains(" T fmi2"))
        .count();
    assert_eq!(n, 34, "FMI 2.0 co-simulation exports");
}

/// `cargo install --path . --root TMP` (reusing this build's target dir, so it
/// only links), then the installed `tyrekit package` in an empty directory:
/// `./TyreKit.fmu` with this interface's GUID, the embedded library, no path
/// of the build machine in it, and loadable by an independent importer.
#[test]
fn installed_tool_packages_from_an_empty_directory() {
    let root = target_scratch("install");
    let target = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .unwrap()
        .to_path_buf();
    let st = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(["install", "--quiet", "--locked", "--offline", "--path"])
        .arg(env!("CARGO_MANIFEST_DIR"))
        .arg("--root")
        .arg(&root)
        .env("CARGO_TARGET_DIR", &target)
        .status()
        .expect("running cargo install");
    assert!(st.success(), "cargo install failed");
    // Outside the source tree (target/ is inside it): the system's temp dir.
    let tmp = crate::common::scratch("portable-empty");
    let empty = tmp.path();
    let fmu = package(&root.join("bin").join("tyrekit"), empty, None);
    assert_eq!(
        fmu,
        empty.join("TyreKit.fmu"),
        "default output outside a source tree"
    );
    assert!(fmu.is_file());
    let xml = String::from_utf8(entry(&fmu, "modelDescription.xml")).unwrap();
    assert!(xml.contains(tyrekit::fmi::GUID));
    let so = entry(&fmu, "binaries/linux64/TyreKit.so");
    assert!(so
        .windows(tyrekit::fmi::GUID.len())
        .any(|w| w == tyrekit::fmi::GUID.as_bytes()));
    let doc = String::from_utf8(entry(&fmu, "documentation/index.html")).unwrap();
    assert!(
        !doc.contains(env!("CARGO_MANIFEST_DIR")),
        "build path in the documentation"
    );

    // Working: the fmi crate (rust-fmi) instantiates it and steps it, free rolling.
    use fmi::fmi2::import::Fmi2Import;
    use fmi::fmi2::instance::{CoSimulation, Common};
    use fmi::traits::FmiImport;
    let import: Fmi2Import = fmi::import::from_path(&fmu).expect("fmi crate imports the FMU");
    let vr = |n: &str| {
        import
            .model_description()
            .model_variables
            .variables
            .iter()
            .find(|v| v.name == n)
            .unwrap()
            .value_reference
    };
    let (fx, kappa) = (vr("Fx"), vr("kappa"));
    let mut inst = import
        .instantiate_cs("install-test", false, false)
        .expect("instantiate");
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    inst.do_step(0.0, 1e-3, true).expect("do_step");
    let mut y = [0.0; 2];
    inst.get_real(&[fx, kappa], &mut y).unwrap();
    // Untouched start values: free rolling (see fmi::start): κ ≈ 0, |Fx| < 2 % of FNOMIN (4000 N).
    assert!(
        y[1].abs() < 1e-6 && y[0].abs() < 80.0,
        "Fx {} kappa {}",
        y[0],
        y[1]
    );
    drop(inst);
}
