//! The load generator (to be written).

use clap::Args;

/// Arguments of `termrast bench serve`.
#[derive(Debug, Args, Clone)]
pub struct BenchServeArgs {}

/// Runs the benchmark.
pub fn run(
    _args: &BenchServeArgs,
    _out: &mut impl std::io::Write,
) -> Result<(), super::ServeError> {
    Ok(())
}
