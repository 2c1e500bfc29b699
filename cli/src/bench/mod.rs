//! `cube5 bench`: speed as figures, never as pass/fail. For each unit: simulated RTL cycles per
//! second (Verilator, driven in batches from Rust), items per clock, golden-model items per second,
//! and where an ideal exists the error against the f64 reference. Markdown on stdout.

mod compos;
mod frame;
mod gradient;
mod scatter;
mod shader;
mod skewed;
mod sorter;
mod trilin;

use anyhow::{anyhow, Result};

#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Items per measurement.
    #[arg(long, default_value_t = 1_000_000)]
    items: usize,
}

pub fn run(args: BenchArgs) -> Result<()> {
    if args.items == 0 {
        return Err(anyhow!("--items must be at least 1"));
    }
    trilin::run(args.items)?;
    gradient::run(args.items)?;
    shader::run(args.items)?;
    compos::run(args.items)?;
    sorter::run(args.items)?;
    scatter::run(args.items)?;
    skewed::run(args.items)?;
    frame::run(args.items)?;
    Ok(())
}
