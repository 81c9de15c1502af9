//! `tyrekit package --force-model brush`: the packaged XML says
//! `force_model` start = "brush" under the SAME GUID as the Magic Formula
//! package (the GUID covers the interface, not chosen start values), and an
//! instance on that unpacked FMU starts with the brush force model, one on the
//! default package with the Magic Formula — one library serves both.

use std::path::{Path, PathBuf};
use tyrekit::fmi::logging::Logger;
use tyrekit::fmi::{Instance, GUID};

/// Package with `args` into its own folder and unpack it there; returns the
/// unpacked FMU's root.
fn packaged(name: &str, args: &[&str]) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("brush-fmu-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    let fmu = dir.join("TyreKit.fmu");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .arg("package")
        .arg("--out")
        .arg(&fmu)
        .args(args)
        .output()
        .expect("running tyrekit package");
    assert!(
        out.status.success(),
        "tyrekit package {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let root = dir.join("unpacked");
    let mut zip = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    zip.extract(&root).unwrap();
    root
}

fn xml(root: &Path) -> String {
    std::fs::read_to_string(root.join("modelDescription.xml")).unwrap()
}

fn guid_of(xml: &str) -> &str {
    let at = xml.find("guid=\"").unwrap() + 6;
    &xml[at..at + xml[at..].find('"').unwrap()]
}

fn force_model_start(xml: &str) -> &str {
    let r = tyrekit::fmi::start::start_span(xml, "force_model").expect("force_model start");
    &xml[r]
}

fn instance(root: &Path) -> Box<Instance> {
    let loc = root.join("resources");
    Instance::new(Logger::new(None, "t", false), Some(loc.to_str().unwrap()))
        .unwrap_or_else(|(_, e)| panic!("instantiate {}: {e}", root.display()))
}

#[test]
fn brush_package_shares_the_guid_and_starts_with_the_brush() {
    let brush = packaged("brush", &["--force-model", "brush"]);
    let mf = packaged("mf", &[]);
    let (xb, xm) = (xml(&brush), xml(&mf));
    assert_eq!(guid_of(&xb), GUID, "brush package: the library's GUID");
    assert_eq!(guid_of(&xm), GUID, "default package: the library's GUID");
    assert_eq!(force_model_start(&xb), "brush");
    assert_eq!(force_model_start(&xm), "mf");
    // Same library bytes in both packages.
    let so = |r: &Path| std::fs::read(r.join("binaries/linux64/TyreKit.so")).unwrap();
    assert!(
        so(&brush) == so(&mf),
        "the two packages ship different libraries"
    );

    let b = instance(&brush);
    assert!(
        b.sim.model.options.brush.is_some(),
        "brush package starts with the brush"
    );
    let m = instance(&mf);
    assert!(
        m.sim.model.options.brush.is_none(),
        "default package starts with the MF"
    );
    // fmi2Reset returns to the packaged choice, not the built-in XML's.
    let mut b = b;
    b.reset().unwrap();
    assert!(
        b.sim.model.options.brush.is_some(),
        "reset keeps the packaged brush"
    );
}

#[test]
fn unknown_force_model_is_refused_at_packaging() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("brush-fmu-bad");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(["package", "--force-model", "magic", "--out"])
        .arg(dir.join("x.fmu"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("mf") && err.contains("brush"), "{err}");
    assert!(!dir.join("x.fmu").exists());
}

/// An unpacked FMU whose XML holds a force_model start the library does not
/// know is refused at instantiation, naming the file (no silent fallback).
#[test]
fn unknown_chosen_start_in_the_packaged_xml_is_an_error() {
    let root = packaged("edited", &[]);
    let x = xml(&root);
    let r = tyrekit::fmi::start::start_span(&x, "force_model").unwrap();
    let mut bad = x.clone();
    bad.replace_range(r, "magic");
    // The instance reads the copy in resources/ (what fmpy extracts).
    std::fs::write(root.join("resources").join("modelDescription.xml"), bad).unwrap();
    let loc = root.join("resources");
    let Err((_, e)) = Instance::new(Logger::new(None, "t", false), Some(loc.to_str().unwrap()))
    else {
        panic!("an unknown force_model start was accepted")
    };
    assert!(
        e.contains("modelDescription.xml") && e.contains("magic"),
        "{e}"
    );
}
