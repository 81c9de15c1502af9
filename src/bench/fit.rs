//! Benchmark section `fit`. (Placeholder until its issue lands.)

/// Run this section, printing its figures.
pub fn run(_ctx: &super::BenchContext) -> crate::Result<()> {
    println!("[fit] not implemented yet");
    Ok(())
}
