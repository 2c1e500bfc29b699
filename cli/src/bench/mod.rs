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
    /// Only these units (repeatable; default all): trilin, gradient, shader, compos, sorter,
    /// scatter, skewed, frame.
    #[arg(long = "unit")]
    units: Vec<String>,
}

/// The benchmarks, by unit name, in the order they run.
type BenchFn = fn(usize) -> Result<()>;
const BENCHES: &[(&str, BenchFn)] = &[
    ("trilin", trilin::run),
    ("gradient", gradient::run),
    ("shader", shader::run),
    ("compos", compos::run),
    ("sorter", sorter::run),
    ("scatter", scatter::run),
    ("skewed", skewed::run),
    ("frame", frame::run),
];

pub fn run(args: BenchArgs) -> Result<()> {
    if args.items == 0 {
        return Err(anyhow!("--items must be at least 1"));
    }
    let names: Vec<&str> = BENCHES.iter().map(|(n, _)| *n).collect();
    if let Some(bad) = args.units.iter().find(|u| !names.contains(&u.as_str())) {
        return Err(anyhow!(
            "--unit {bad}: unknown (known: {})",
            names.join(", ")
        ));
    }
    for (name, bench) in BENCHES {
        if args.units.is_empty() || args.units.iter().any(|u| u == name) {
            bench(args.items)?;
        }
    }
    Ok(())
}
