use tyrekit::tir::TyreParams;
fn main() {
    for a in std::env::args().skip(1) {
        match TyreParams::from_file(std::path::Path::new(&a)) {
            Ok(t) => {
                println!(
                    "== {a}: {:?} side {:?} defaulted {} warnings {}",
                    t.version,
                    t.side,
                    t.defaulted.len(),
                    t.warnings.len()
                );
                for w in &t.warnings {
                    println!("   W {w}");
                }
                if std::env::var("DUMP").is_ok() {
                    println!("{}", t.to_tir_string());
                }
            }
            Err(e) => println!("== {a}: ERROR {e}"),
        }
    }
}
