//! Benchmark section `diagnose`. (Placeholder until its issue lands.)

/// Run this section, printing its figures.
pub fn run(_ctx: &super::BenchContext) -> crate::Result<()> {
    println!("[diagnose] not implemented yet");
    Ok(())
}
