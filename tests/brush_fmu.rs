//! `tyrekit package --force-model brush`: the packaged XML says
//! `force_model` start = "brush" under its own GUID, the library accepts that
//! GUID and an instance of it starts with the brush force model (and the
//! default XML's instance with the Magic Formula).

use tyrekit::fmi::logging::Logger;
use tyrekit::fmi::packaging::model_description;
use tyrekit::fmi::{vars, Instance, GUID};

fn guid_of(xml: &str) -> &str {
    let at = xml.find("guid=\"").unwrap() + 6;
    &xml[at..at + xml[at..].find('"').unwrap()]
}

#[test]
fn brush_variant_has_its_guid_and_start() {
    let x = model_description(Some("brush")).unwrap();
    let g = guid_of(x);
    assert_ne!(g, GUID);
    let fm = x.find("name=\"force_model\"").unwrap();
    let start = &x[fm..][x[fm..].find("start=\"").unwrap()..];
    assert!(start.starts_with("start=\"brush\""));
    assert_eq!(guid_of(model_description(Some("mf")).unwrap()), GUID);
    assert!(model_description(Some("magic"))
        .unwrap_err()
        .to_string()
        .contains("mf or brush"));
    let v = vars::START_VARIANTS.iter().find(|v| v.2 == g).unwrap();
    assert_eq!((v.0, v.1), ("force_model", "brush"));

    // An instance of each interface, on a resources folder with the built-in tyre.
    let dir = std::env::temp_dir().join(format!("brush-fmu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    tyrekit::tir::TyreParams::builtin()
        .write(&dir.join("tyre.tir"))
        .unwrap();
    let loc = dir.to_str().unwrap();
    let log = || Logger::new(None, "t", false);
    let b = Instance::new_variant(log(), Some(loc), Some(("force_model", "brush"))).unwrap();
    assert!(b.sim.model.options.brush.is_some());
    let mf = Instance::new(log(), Some(loc)).unwrap();
    assert!(mf.sim.model.options.brush.is_none());
    let _ = std::fs::remove_dir_all(&dir);
}
