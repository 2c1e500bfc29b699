//! Benchmark of the GI-Cube ray queues (`gicube_ray_queues`): speed of the RTL and the model, and
//! on processor-like traffic the rays moved per clock, the overflow rate and the occupancy, counted
//! on the RTL's outputs (which must equal the model's).

use super::common::{open, speed_table, Compare};
use anyhow::{ensure, Result};
use cube5_model::unit::{StreamUnit, UnitConfig};
use cube5_model::units::gicube_ray_queues::{
    QueueTraffic, QueuesIn, QueuesOut, RayQueues, RayQueuesConfig, RayQueuesUnit,
};
use cube5_tb::rtl::Traffic;
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = RayQueuesConfig::TOP;

/// Processor-like traffic in the processor model's cycle order (docs/numerics/gicube_processor.md,
/// *The frame*): each processor cycle is one item that pops the active queue (kept until it
/// empties, then the fullest queue: the sorter's choice by ray count) and pushes the ray the cycle
/// before took (the ring: it stays in its block, moves to another queue with probability `moves`,
/// or finishes with probability `finish` and is not pushed), then, if the host's next ray has room
/// in its queue (the host's ready), a second item that pushes it; a host ray that finds its
/// queue full waits (a stall). The host never runs out of rays. Moves and host rays go to any
/// queue, or, when `converge`, to one eighth of them (rays converging near a light or the eye,
/// [372]). Returns the items, the processor cycles, the host's stalls and the ring's pushes.
fn ring_items(
    cfg: RayQueuesConfig,
    n: usize,
    moves: f64,
    finish: f64,
    converge: bool,
    rng: &mut ChaCha8Rng,
) -> (Vec<QueuesIn>, u64, u64, u64) {
    let nq = cfg.queues();
    let targets = if converge { (nq / 8).max(1) } else { nq };
    let mut counts: RayQueues<()> = RayQueues::new(nq, cfg.queue_len);
    let mut items = Vec::with_capacity(n + 1);
    let (mut active, mut ring, mut host_q) = (0u32, None::<u32>, rng.random_range(0..targets));
    let (mut cycles, mut stalls, mut ring_pushes) = (0u64, 0u64, 0u64);
    let data = |rng: &mut ChaCha8Rng| cfg.mask(std::array::from_fn(|_| rng.random()));
    while items.len() < n {
        cycles += 1;
        if counts.is_empty(active) {
            active = (0..nq).max_by_key(|&q| counts.len(q)).unwrap_or(0);
        }
        let push_q = ring.take();
        ring_pushes += u64::from(push_q.is_some());
        items.push(QueuesIn {
            pop: true,
            pop_q: active,
            push: push_q.is_some(),
            push_q: push_q.unwrap_or(0),
            data: data(rng),
        });
        let s = counts.step(Some(active), push_q.map(|q| (q, ())));
        if s.popped.is_some() {
            let r: f64 = rng.random();
            ring = if r < finish {
                None
            } else if r < finish + moves {
                Some(rng.random_range(0..targets))
            } else {
                Some(active)
            };
        }
        if counts.is_full(host_q) {
            stalls += 1;
        } else {
            items.push(QueuesIn {
                push: true,
                push_q: host_q,
                data: data(rng),
                ..Default::default()
            });
            counts.step(None, Some((host_q, ())));
            host_q = rng.random_range(0..targets);
        }
    }
    (items, cycles, stalls, ring_pushes)
}

pub fn run(n_items: usize) -> Result<()> {
    println!("One item is one pop and one push at most (random fill / drain / mixed traffic).\n");
    speed_table(
        |cfg: RayQueuesConfig| {
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            let mut t = QueueTraffic::new(cfg);
            let items: Vec<QueuesIn> = (0..n_items).map(|_| t.next_item(&mut rng)).collect();
            Ok((RayQueuesUnit::new(cfg)?, items, vec![]))
        },
        Compare::Outputs,
    )?;

    println!("Processor-like traffic at full speed in the processor model's cycle order, counted");
    println!("on the RTL's outputs (equal to the model's): per processor cycle one item pops the");
    println!(
        "active queue (kept until empty, then the fullest) and pushes the ray the cycle before"
    );
    println!("took (it stays in its block, moves with probability 1/4, finishes with probability");
    println!(
        "`finish`); a second item pushes the host's next ray when its queue has room (else the"
    );
    println!("host stalls). Moves and host rays go to any queue, or to one of Q/8 (converging).");
    println!("Clocks per cycle = items / cycles (one push per item); rays per clock = (dequeued +");
    println!("enqueued) / clocks; occupancy = rays held / (Q QueueLen), mean over items.\n");
    println!("| config | traffic | items | clocks / processor cycle | rays/clock | dequeued/clock | ring overflow (% of ring pushes) | host stalls (% of cycles) | mean occupancy | max queue count | queues emptied |");
    println!("|--------|---------|------:|-------------------------:|-----------:|---------------:|---------------------------------:|--------------------------:|---------------:|----------------:|---------------:|");
    for v in variants_of(TOP) {
        let cfg: RayQueuesConfig = v.config()?;
        for (name, finish, converge) in [
            ("finish 1/8, uniform", 0.125, false),
            ("finish 1/64, uniform", 1.0 / 64.0, false),
            ("finish 1/64, converging", 1.0 / 64.0, true),
        ] {
            let mut rng = ChaCha8Rng::seed_from_u64(12);
            let (items, pcycles, stalls, ring_pushes) =
                ring_items(cfg, n_items, 0.25, finish, converge, &mut rng);
            let n = items.len() as u64;
            let mut dut = open(v, cfg, &[])?;
            let driven = dut.drive(&items, &Traffic::full_speed(), n, 2 * n + 100)?;
            let gold = RayQueuesUnit::new(cfg)?.run(&items);
            let outs: Vec<QueuesOut> = driven.outputs.iter().map(|o| o.value).collect();
            ensure!(outs == gold, "{v}: RTL and model disagree on {name}");
            let count = |f: fn(&QueuesOut) -> bool| outs.iter().filter(|o| f(o)).count() as f64;
            let (popped, pushed, ovf) = (
                count(|o| o.popped),
                count(|o| o.pushed),
                count(|o| o.overflow),
            );
            let cap = f64::from(cfg.queues() * cfg.queue_len);
            let occ = outs.iter().map(|o| f64::from(o.total)).sum::<f64>() / n as f64 / cap;
            let clocks = driven.stats.cycles as f64;
            let max_q = outs
                .iter()
                .map(|o| o.pop_len.max(o.push_len))
                .max()
                .unwrap_or(0);
            // Host rays are offered only with room: every overflow is a ring push.
            println!(
                "| {} | {name} | {n} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.1}% | {max_q} | {} |",
                v.config,
                n as f64 / pcycles as f64,
                (popped + pushed) / clocks,
                popped / clocks,
                100.0 * ovf / (ring_pushes as f64).max(1.0),
                100.0 * stalls as f64 / pcycles as f64,
                100.0 * occ,
                count(|o| o.emptied),
            );
        }
    }
    println!();
    Ok(())
}
