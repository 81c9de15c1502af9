//! The `tyrekit` command line. All logic lives in the library (`tyrekit::cli`).
fn main() {
    std::process::exit(tyrekit::cli::main());
}
