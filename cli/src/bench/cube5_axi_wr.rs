//! Benchmark of cube5_axi_wr: bytes written per clock against the write response's latency and
//! the bus's bandwidth (the test bench's AXI memory, tb/axi_mem.h), and the simulation's speed.
//! Every run is held to the model: the memory's bytes afterwards and the completions must match.

use super::common::open;
use anyhow::{ensure, Result};
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_axi_rd::AxiMemImage;
use cube5_model::units::cube5_axi_wr::{AxiWrCmd, AxiWrConfig};
use cube5_tb::rtl::{AxiMemSetup, Traffic};
use cube5_tb::{variants_of, Variant};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

pub const TOP: &str = AxiWrConfig::TOP;

/// B latencies of the table's columns (cycles from a burst's last W beat to its BVALID).
const LATENCIES: [u32; 4] = [10, 50, 100, 200];

/// One run: about `n_items` items in commands of 256 beats from beat-aligned addresses inside a
/// 64 KB image, items offered every cycle, completions always taken, B latency `lat`, bandwidth
/// `bw` bytes per cycle as (num, den) (num = 0: none). Returns (bytes per clock, simulated cycles
/// per second).
fn run_one(
    variant: &'static Variant,
    cfg: AxiWrConfig,
    n_items: usize,
    lat: u32,
    bw: (u32, u32),
) -> Result<(f64, f64)> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let base = if cfg.addr_w <= 16 { 0 } else { 0x1_0000 };
    let mem = AxiMemImage {
        base,
        bytes: (0..0x1_0000).map(|_| rng.random()).collect(),
        slverr_lo: 0,
        slverr_hi: 0,
    };
    let b = u64::from(cfg.bytes());
    let lanes = cfg.bytes() / cfg.item_bytes();
    let per_cmd = 256 * lanes;
    let spans = 0x1_0000 / (256 * b);
    let n_cmds = (n_items as u64).div_ceil(u64::from(per_cmd)).max(1);
    let cmds: Vec<AxiWrCmd> = (0..n_cmds)
        .map(|k| AxiWrCmd {
            addr: base + (k % spans) * 256 * b,
            len: per_cmd,
        })
        .collect();
    let items: Vec<Vec<u8>> = (0..n_cmds * u64::from(per_cmd))
        .map(|_| (0..cfg.item_bytes()).map(|_| rng.random()).collect())
        .collect();
    let want = cfg.expected(&cmds, &items, &mem, 0)?;

    let mut dut = open(variant, cfg, &[])?;
    dut.axi_setup(&AxiMemSetup {
        data_bytes: cfg.bytes(),
        addr_bits: cfg.addr_w,
        latency_fixed: lat,
        latency_random: 0,
        bw_num: bw.0,
        bw_den: bw.1.max(1),
        max_bursts: 64,
        seed: 1,
        declared_outstanding: cfg.outstanding,
        ..Default::default()
    })?;
    dut.axi_load(mem.base, &mem.bytes)?;
    let packed: Vec<u32> = items.iter().flat_map(|i| cfg.pack_item(i)).collect();
    dut.axi_feed(&packed, cfg.item_w.div_ceil(32), &[])?;
    let flat = dut.pack(&cmds);
    let n_done = want.done.len() as u64;
    let t = Instant::now();
    let driven = dut.drive_packed(
        &flat,
        &Traffic::full_speed(),
        n_done,
        100 * want.beats + 100_000,
    )?;
    let secs = t.elapsed().as_secs_f64();

    let done: Vec<_> = driven.outputs.iter().map(|o| o.value).collect();
    ensure!(
        done == want.done,
        "{variant}: the completions differ from the model's"
    );
    ensure!(
        dut.axi_image()? == want.image,
        "{variant}: the memory after the run differs from the model's"
    );
    let c = dut.axi_counters();
    ensure!(
        c.protocol_errors == 0,
        "{variant}: AXI checker: {}",
        dut.axi_first_error()
    );
    let bytes = dut.axi_wr_counters().w_bytes;
    let cycles = driven.stats.cycles.max(1);
    Ok((bytes as f64 / cycles as f64, cycles as f64 / secs))
}

pub fn run(n_items: usize) -> Result<()> {
    println!(
        "Bytes written per clock ({n_items} items or more per run in commands of 256 beats; items"
    );
    println!(
        "offered every cycle, so the bus carries at most ItemW/8 bytes per clock), against the B"
    );
    println!("latency, unlimited bandwidth; then at latency 100 under a bandwidth limit of a quarter and");
    println!(
        "a half of the bus width per clock. Every run matches the model (memory and completions)."
    );
    println!();
    println!("| config | item limit (bytes/clock) | B latency 10 | 50 | 100 | 200 | DataW/32 bytes/clock | DataW/16 bytes/clock | sim cycles/s |");
    println!("|--------|------:|----:|---:|----:|----:|-----:|-----:|-------------:|");
    for v in variants_of(TOP) {
        let cfg: AxiWrConfig = v.config()?;
        let mut row = Vec::new();
        let mut speed = 0.0f64;
        for lat in LATENCIES {
            let (bpc, rate) = run_one(v, cfg, n_items, lat, (0, 1))?;
            row.push(format!("{bpc:.3}"));
            speed = speed.max(rate);
        }
        for den in [4, 2] {
            let (bpc, _) = run_one(v, cfg, n_items, 100, (cfg.bytes(), den))?;
            row.push(format!("{bpc:.3}"));
        }
        println!(
            "| {} | {} | {} | {speed:.2e} |",
            v.config,
            cfg.item_bytes(),
            row.join(" | ")
        );
    }
    println!();
    Ok(())
}
