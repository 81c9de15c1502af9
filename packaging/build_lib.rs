//! build_lib — part of build.rs: builds the FMU's shared library (this
//! package's cdylib) in a nested `cargo build` and leaves it in `OUT_DIR`, where
//! the `tyrekit` binary embeds it (`include_bytes!`). So an installed binary
//! (`cargo install --path .`) packages a working FMU from any directory, without
//! the source tree, and the library it ships always matches its own sources.
//!
//! Cargo cannot make a build script depend on the cdylib of its own package, so
//! the library is built by a second cargo run over the same manifest into its own
//! target directory (`<target>/fmu-lib`, kept between builds, so only changed
//! sources recompile; a separate directory so the outer build's lock is never
//! waited for). That run sees `TYREKIT_NESTED_LIB_BUILD` and skips this step.
//!
//! Portability: when `cargo-zigbuild` is found (on PATH or in the project's
//! `.venv/bin`, where `scripts/test-all` installs it from PyPI with `ziglang`),
//! the library is linked against glibc 2.17 symbol versions
//! (`--target x86_64-unknown-linux-gnu.2.17`), so it loads on any Linux with
//! glibc ≥ 2.17; otherwise with the host's toolchain (then it needs the host's
//! glibc). Either way it is stripped (`strip = "symbols"`; the 34 FMI exports
//! stay in the dynamic symbol table). `TYREKIT_FMU_BUILD=host` forces the host
//! build, `=zig` requires zigbuild.
//! Must never: recurse, write into the source tree, or let a library without
//! this interface's GUID be embedded.

use std::path::{Path, PathBuf};
use std::process::Command;

/// glibc symbol-version floor of the portable build.
pub const GLIBC_FLOOR: &str = "2.17";
const TRIPLE: &str = "x86_64-unknown-linux-gnu";

fn find_zigbuild(root: &Path) -> Option<PathBuf> {
    let venv = root.join(".venv").join("bin").join("cargo-zigbuild");
    let on_path = std::env::var_os("PATH").and_then(|p| {
        std::env::split_paths(&p)
            .map(|d| d.join("cargo-zigbuild"))
            .find(|c| c.is_file())
    });
    on_path.or_else(|| venv.is_file().then_some(venv))
}

fn fail(msg: String) -> ! {
    eprintln!("error: building the FMU library for embedding: {msg}");
    std::process::exit(1);
}

/// Build the library, copy it to `OUT_DIR/fmu_lib.so` and write
/// `OUT_DIR/fmu_lib.txt` (how it was built). No-op inside the nested build.
pub fn embed(guid: &str) {
    println!("cargo:rerun-if-env-changed=TYREKIT_FMU_BUILD");
    // The library's sources: everything under src/ but the binary's own
    // files (src/main.rs, src/cli, src/bench), so editing the command line
    // does not rebuild the embedded library.
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let binary_only = ["main.rs", "cli", "bench"];
    match std::fs::read_dir(root.join("src")) {
        Ok(entries) => {
            for e in entries.flatten() {
                let name = e.file_name();
                if !binary_only.iter().any(|b| name == *b) {
                    println!("cargo:rerun-if-changed=src/{}", name.to_string_lossy());
                }
            }
        }
        Err(_) => println!("cargo:rerun-if-changed=src"),
    }
    println!("cargo:rerun-if-changed=Cargo.toml");
    println!("cargo:rerun-if-changed=Cargo.lock");
    if std::env::var_os("TYREKIT_NESTED_LIB_BUILD").is_some() {
        return;
    }
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR"));
    // The cargo target directory is the ancestor of OUT_DIR holding CACHEDIR.TAG.
    let target_dir = out_dir
        .ancestors()
        .find(|d| d.join("CACHEDIR.TAG").is_file())
        .map(|d| d.join("fmu-lib"))
        .unwrap_or_else(|| out_dir.join("fmu-lib"));
    let mode = std::env::var("TYREKIT_FMU_BUILD").unwrap_or_default();
    let zig = match mode.as_str() {
        "host" => None,
        "zig" => Some(find_zigbuild(&root).unwrap_or_else(|| {
            fail(
                "TYREKIT_FMU_BUILD=zig but cargo-zigbuild is neither on PATH nor in .venv/bin"
                    .into(),
            )
        })),
        "" => find_zigbuild(&root),
        other => fail(format!("TYREKIT_FMU_BUILD={other}: expected host or zig")),
    };
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = match &zig {
        Some(z) => {
            let mut c = Command::new(z);
            c.arg("zigbuild")
                .arg("--target")
                .arg(format!("{TRIPLE}.{GLIBC_FLOOR}"));
            // cargo-zigbuild runs `cargo` and finds zig via `python3 -m ziglang`:
            // put the venv (if that is where it lives) first on PATH.
            if let Some(dir) = z.parent() {
                let path = std::env::var_os("PATH").unwrap_or_default();
                let mut dirs = vec![dir.to_path_buf()];
                dirs.extend(std::env::split_paths(&path));
                if let Some(cargo_dir) = Path::new(&cargo).parent() {
                    dirs.insert(1, cargo_dir.to_path_buf());
                }
                c.env("PATH", std::env::join_paths(dirs).unwrap_or(path));
            }
            c
        }
        None => {
            let mut c = Command::new(&cargo);
            c.arg("build");
            c
        }
    };
    // Only the library and what it needs: the binary-only dependencies (feature
    // `cli`: clap, zip, indicatif) are not compiled for it.
    cmd.args([
        "--release",
        "--lib",
        "--no-default-features",
        "--quiet",
        "--manifest-path",
    ])
    .arg(root.join("Cargo.toml"))
    .arg("--target-dir")
    .arg(&target_dir);
    if root.join("Cargo.lock").is_file() {
        cmd.arg("--locked");
    }
    // The outer build's flags and jobserver are not the nested build's.
    for k in [
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_TARGET_DIR",
        "CARGO_BUILD_TARGET",
        "CARGO_MAKEFLAGS",
        "MAKEFLAGS",
        "MFLAGS",
        "RUSTC",
    ] {
        cmd.env_remove(k);
    }
    cmd.env("TYREKIT_NESTED_LIB_BUILD", "1")
        .env("CARGO_PROFILE_RELEASE_STRIP", "symbols");
    let status = cmd
        .status()
        .unwrap_or_else(|e| fail(format!("cannot run {:?}: {e}", cmd.get_program())));
    if !status.success() {
        fail(format!(
            "{:?} failed ({status}); set TYREKIT_FMU_BUILD=host to build without cargo-zigbuild",
            cmd.get_program()
        ));
    }
    let built = match &zig {
        Some(_) => target_dir
            .join(TRIPLE)
            .join("release")
            .join("libtyrekit.so"),
        None => target_dir.join("release").join("libtyrekit.so"),
    };
    let bytes = std::fs::read(&built).unwrap_or_else(|e| fail(format!("{}: {e}", built.display())));
    if !bytes.windows(guid.len()).any(|w| w == guid.as_bytes()) {
        fail(format!("{} does not contain GUID {guid}", built.display()));
    }
    let how = match &zig {
        Some(_) => format!("portable: cargo-zigbuild, glibc >= {GLIBC_FLOOR}, stripped"),
        None => "host toolchain (needs the build machine's glibc or newer), stripped".to_string(),
    };
    std::fs::write(out_dir.join("fmu_lib.so"), &bytes)
        .unwrap_or_else(|e| fail(format!("writing OUT_DIR: {e}")));
    std::fs::write(out_dir.join("fmu_lib.txt"), how)
        .unwrap_or_else(|e| fail(format!("writing OUT_DIR: {e}")));
}
