//! The integration tests, one binary: every `tests/*.rs` file is a module here
//! except the three that are their own binaries (Cargo.toml, `autotests =
//! false`): `diagnose_devset` (the dev-set runs, ≈ 25 min, run alone by name),
//! `alloc` (the allocation tests behind one counting global allocator) and
//! this one.
//!
//! Why one binary: each test binary is a full thin-LTO, one-codegen-unit link
//! of the crate (≈ 24 s of CPU each on the CI machine); 70 of them were a
//! quarter of CI's time. Run one file's tests with
//! `cargo test --release --test suite FILE::` (e.g. `devset_fit::`).
//!
//! A test file that is in none of the three is a test that never runs:
//! [`every_test_file_belongs_to_a_binary`] fails then.

// Helpers shared by several test files, loaded once (each file `use`s them).
mod common;
#[path = "common/devset.rs"]
mod devset;
mod fit_support;
#[allow(dead_code)]
#[path = "fit_support/standin.rs"]
mod standin;
mod tir_common;

/// Every `tests/*.rs` file is compiled into one of the test binaries.
#[test]
fn every_test_file_belongs_to_a_binary() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let (suite, alloc, cargo) = (
        read("tests/suite.rs"),
        read("tests/alloc.rs"),
        read("Cargo.toml"),
    );
    let mut missing = Vec::new();
    for e in std::fs::read_dir(root.join("tests")).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        if !name.ends_with(".rs") {
            continue;
        }
        let included = format!("#[path = \"{name}\"]");
        let own = format!("path = \"tests/{name}\"");
        if !(suite.contains(&included) || alloc.contains(&included) || cargo.contains(&own)) {
            missing.push(name);
        }
    }
    assert!(
        missing.is_empty(),
        "test files in no test binary (add `#[path = \"F\"] mod F;` to tests/suite.rs): {missing:?}"
    );
}

#[path = "brush_carcass.rs"]
mod brush_carcass;
#[path = "brush_closed_form.rs"]
mod brush_closed_form;
#[path = "brush_fit.rs"]
mod brush_fit;
#[path = "brush_fmu.rs"]
mod brush_fmu;
#[path = "brush_params.rs"]
mod brush_params;
#[path = "brush_study.rs"]
mod brush_study;
#[path = "data_cli.rs"]
mod data_cli;
#[path = "data_conventions.rs"]
mod data_conventions;
#[path = "data_formats.rs"]
mod data_formats;
#[path = "data_misuse.rs"]
mod data_misuse;
#[path = "data_rig.rs"]
mod data_rig;
#[path = "data_sanity.rs"]
mod data_sanity;
#[path = "data_slip_reference.rs"]
mod data_slip_reference;
#[path = "data_tyredata.rs"]
mod data_tyredata;
#[path = "devset_fit.rs"]
mod devset_fit;
#[path = "diagnose_candidate.rs"]
mod diagnose_candidate;
#[path = "diagnose_cli.rs"]
mod diagnose_cli;
#[path = "diagnose_effects.rs"]
mod diagnose_effects;
#[path = "diagnose_load.rs"]
mod diagnose_load;
#[path = "diagnose_locate.rs"]
mod diagnose_locate;
#[path = "diagnose_pressure.rs"]
mod diagnose_pressure;
#[path = "diagnose_proof.rs"]
mod diagnose_proof;
#[path = "diagnose_reestimate.rs"]
mod diagnose_reestimate;
#[path = "diagnose_reference.rs"]
mod diagnose_reference;
#[path = "diagnose_refit.rs"]
mod diagnose_refit;
#[path = "diagnose_replay.rs"]
mod diagnose_replay;
#[path = "diagnose_report.rs"]
mod diagnose_report;
#[path = "diagnose_speed_friction.rs"]
mod diagnose_speed_friction;
#[path = "diagnose_tyres.rs"]
mod diagnose_tyres;
#[path = "fit_channels.rs"]
mod fit_channels;
#[path = "fit_drive_brake.rs"]
mod fit_drive_brake;
#[path = "fit_geometry.rs"]
mod fit_geometry;
#[path = "fit_grad_pure.rs"]
mod fit_grad_pure;
#[path = "fit_hold_ranges.rs"]
mod fit_hold_ranges;
#[path = "fit_identify.rs"]
mod fit_identify;
#[path = "fit_lm.rs"]
mod fit_lm;
#[path = "fit_mf_roundtrip.rs"]
mod fit_mf_roundtrip;
#[path = "fit_mf_tyredata.rs"]
mod fit_mf_tyredata;
#[path = "fit_moments.rs"]
mod fit_moments;
#[path = "fit_provenance.rs"]
mod fit_provenance;
#[path = "fit_pso.rs"]
mod fit_pso;
#[path = "fit_report.rs"]
mod fit_report;
#[path = "fit_stages.rs"]
mod fit_stages;
#[path = "fit_standin.rs"]
mod fit_standin;
#[path = "fit_transient.rs"]
mod fit_transient;
#[path = "fit_validity.rs"]
mod fit_validity;
#[path = "fit_workflow.rs"]
mod fit_workflow;
#[path = "fmu_demo.rs"]
mod fmu_demo;
#[path = "fmu_import.rs"]
mod fmu_import;
#[path = "fmu_portable.rs"]
mod fmu_portable;
#[path = "fuzz.rs"]
mod fuzz;
#[path = "mf_autodiff.rs"]
mod mf_autodiff;
#[path = "mf_batch.rs"]
mod mf_batch;
#[path = "mf_cli.rs"]
mod mf_cli;
#[path = "mf_physics.rs"]
mod mf_physics;
#[path = "mf_road.rs"]
mod mf_road;
#[path = "mfeval_reference.rs"]
mod mfeval_reference;
#[path = "reader_bounds.rs"]
mod reader_bounds;
#[path = "tir_files.rs"]
mod tir_files;
#[path = "tir_fuzz.rs"]
mod tir_fuzz;
#[path = "tir_syntax.rs"]
mod tir_syntax;
#[path = "tir_units.rs"]
mod tir_units;
#[path = "transient_bounds.rs"]
mod transient_bounds;
#[path = "transient_extension.rs"]
mod transient_extension;
#[path = "transient_lowspeed.rs"]
mod transient_lowspeed;
#[path = "transient_lugre.rs"]
mod transient_lugre;
#[path = "transient_params.rs"]
mod transient_params;
#[path = "transient_relaxation.rs"]
mod transient_relaxation;
#[path = "transient_reverse.rs"]
mod transient_reverse;
#[path = "transient_scenario.rs"]
mod transient_scenario;
#[path = "tyre_validation.rs"]
mod tyre_validation;
