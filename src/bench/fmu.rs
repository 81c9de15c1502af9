//! Benchmark section `fmu`. (Placeholder until its issue lands.)

/// Run this section, printing its figures.
pub fn run(_ctx: &super::BenchContext) -> crate::Result<()> {
    println!("[fmu] not implemented yet");
    Ok(())
}
