//! `cube5 bench`: speed as figures, never as pass/fail. For each unit: simulated RTL cycles per
//! second (Verilator, driven in batches from Rust), items per clock, golden-model items per second,
//! and where an ideal exists the error against the f64 reference. Markdown on stdout.
//!
//! One file per RTL top, named as the top; each loops over the top's variants
//! (`cube5_tb::variants_of`) and names none. What they share is in [`common`].

mod common;
mod cube5_axi_wr;
mod cube5_compos;
mod cube5_frame;
mod cube5_gradient;
mod cube5_rblock;
mod cube5_sepconv;
mod cube5_shader;
mod cube5_skewmem;
mod cube5_trilin;
mod cube5_warp;
mod gicube_bucket;
mod gicube_packet_loop;
mod gicube_processor;
mod gicube_ray_queues;
mod gicube_sample;
mod gicube_scatter;
mod gicube_sorter;
mod gicube_step;

use anyhow::{anyhow, Result};

#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Items per measurement.
    #[arg(long, default_value_t = 1_000_000)]
    items: usize,
    #[arg(long = "unit", help = unit_help())]
    units: Vec<String>,
}

/// One benchmark: the RTL top it measures, the short name it also answers to, and its run.
struct Bench {
    top: &'static str,
    alias: &'static str,
    run: fn(usize) -> Result<()>,
}

/// The benchmarks, in the order they run.
const BENCHES: &[Bench] = &[
    Bench {
        top: cube5_trilin::TOP,
        alias: "trilin",
        run: cube5_trilin::run,
    },
    Bench {
        top: cube5_gradient::TOP,
        alias: "gradient",
        run: cube5_gradient::run,
    },
    Bench {
        top: cube5_sepconv::TOP,
        alias: "sepconv",
        run: cube5_sepconv::run,
    },
    Bench {
        top: cube5_shader::TOP,
        alias: "shader",
        run: cube5_shader::run,
    },
    Bench {
        top: cube5_compos::TOP,
        alias: "compos",
        run: cube5_compos::run,
    },
    Bench {
        top: gicube_sorter::TOP,
        alias: "sorter",
        run: gicube_sorter::run,
    },
    Bench {
        top: gicube_bucket::TOP,
        alias: "bucket",
        run: gicube_bucket::run,
    },
    Bench {
        top: gicube_packet_loop::TOP,
        alias: "packet",
        run: gicube_packet_loop::run,
    },
    Bench {
        top: gicube_scatter::TOP,
        alias: "scatter",
        run: gicube_scatter::run,
    },
    Bench {
        top: gicube_ray_queues::TOP,
        alias: "queues",
        run: gicube_ray_queues::run,
    },
    Bench {
        top: gicube_step::TOP,
        alias: "step",
        run: gicube_step::run,
    },
    Bench {
        top: gicube_sample::TOP,
        alias: "sample",
        run: gicube_sample::run,
    },
    Bench {
        top: gicube_processor::TOP,
        alias: "processor",
        run: gicube_processor::run,
    },
    Bench {
        top: cube5_skewmem::TOP,
        alias: "skewed",
        run: cube5_skewmem::run,
    },
    Bench {
        top: cube5_rblock::TOP,
        alias: "rblock",
        run: cube5_rblock::run,
    },
    Bench {
        top: cube5_frame::TOP,
        alias: "frame",
        run: cube5_frame::run,
    },
    Bench {
        top: cube5_warp::TOP,
        alias: "warp",
        run: cube5_warp::run,
    },
    Bench {
        top: cube5_axi_wr::TOP,
        alias: "axi_wr",
        run: cube5_axi_wr::run,
    },
];

/// `--unit`'s help: every name it takes.
fn unit_help() -> String {
    let names: Vec<String> = BENCHES
        .iter()
        .map(|b| format!("{} ({})", b.top, b.alias))
        .collect();
    format!(
        "Only these units (repeatable; default all), by RTL top or the short name in brackets: {}",
        names.join(", ")
    )
}

/// The benchmark `--unit name` asks for.
fn find(name: &str) -> Option<&'static Bench> {
    BENCHES.iter().find(|b| b.top == name || b.alias == name)
}

pub fn run(args: BenchArgs) -> Result<()> {
    if args.items == 0 {
        return Err(anyhow!("--items must be at least 1"));
    }
    let mut chosen = Vec::new();
    for name in &args.units {
        let bench = find(name).ok_or_else(|| {
            let known: Vec<&str> = BENCHES.iter().map(|b| b.top).collect();
            anyhow!("--unit {name}: unknown (known: {})", known.join(", "))
        })?;
        chosen.push(bench.top);
    }
    for bench in BENCHES {
        if chosen.is_empty() || chosen.contains(&bench.top) {
            println!("## {}\n", bench.top);
            (bench.run)(args.items)?;
        }
    }
    Ok(())
}
