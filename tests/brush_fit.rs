//! `fit --model brush` on the shared TyreData recording: the brush reaches
//! σ_Fy ≤ 10 % on the pure side-slip samples (the acceptance).
//! Skipped, with a message, when ../shared is absent.

use tyrekit::brush::BrushParams;
use tyrekit::data::Recording;
use tyrekit::mf::Tyre;

#[test]
fn brush_fits_tyredata_fy_within_10_percent() {
    let path = std::path::Path::new("../shared/data/measurements/TyreData.csv");
    if !path.exists() {
        eprintln!("SKIP: {} absent", path.display());
        return;
    }
    let rec = Recording::from_file(path).unwrap();
    let (b0, _) = BrushParams::from_tyre(&Tyre::builtin()).unwrap();
    let f = tyrekit::fit::brush::fit_brush(&[rec], b0).unwrap();
    println!("{f:?}");
    assert!(f.n_lateral > 500);
    assert!(f.sigma_fy <= 0.10, "σ_Fy {}", f.sigma_fy);
}
