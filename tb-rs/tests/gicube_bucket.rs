//! Co-simulation of gicube_bucket against the golden model (docs/numerics/gicube_bucket.md).

mod support;

use cube5_model::units::gicube_bucket::{
    random_position, BucketConfig, BucketIn, BucketUnit, Distribution, Position,
};
use cube5_model::units::gicube_packet_loop::POS_FRAC_W;
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    configs, directed_on_every_config, expect_mismatch, gate_smoke_then_directed,
    million_across_a_reset, random_items_one_per_clock, seed, variant_with,
};

fn random_item(cfg: BucketConfig) -> impl FnMut(&mut ChaCha8Rng) -> BucketIn {
    move |rng| BucketIn((0..cfg.lanes).map(|_| random_position(rng, &cfg)).collect())
}

/// Every block corner and centre along the three axes, the volume's last voxel and first voxel
/// outside, the largest position, and fractions 0 and all-ones.
fn directed_items(cfg: BucketConfig) -> Vec<BucketIn> {
    let n = cfg.vol_side();
    let side = cfg.block_side();
    let mut coords: Vec<u32> = Vec::new();
    for k in 0..=cfg.vol_blocks {
        for off in [0i64, -1, i64::from(side / 2)] {
            let v = i64::from(k * side) + off;
            if (0..4096).contains(&v) {
                coords.push(v as u32);
            }
        }
    }
    coords.extend([n - 1, n, (n + 1).min(4095), 4095]);
    coords.sort_unstable();
    coords.dedup();
    let mut positions = Vec::new();
    for (i, &a) in coords.iter().enumerate() {
        let b = coords[(i * 7 + 3) % coords.len()];
        let c = coords[(i * 13 + 5) % coords.len()];
        for frac in [0, (1 << POS_FRAC_W) - 1] {
            for [x, y, z] in [[a, b, c], [b, c, a], [c, a, b], [a, a, a]] {
                positions.push(Position([
                    x << POS_FRAC_W | frac,
                    y << POS_FRAC_W | frac,
                    z << POS_FRAC_W | frac,
                ]));
            }
        }
    }
    positions
        .chunks(cfg.lanes as usize)
        .filter(|c| c.len() == cfg.lanes as usize)
        .map(|c| BucketIn(c.to_vec()))
        .collect()
}

#[test]
fn million_random_positions_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(BucketUnit::new, random_item, 400, 3, 10);
}

#[test]
fn directed_block_and_volume_edges() {
    directed_on_every_config(BucketUnit::new, directed_items, |n| {
        assert!(n > 20);
        StreamCheck::new(seed(410), 3 * n).with_traffic(0.3, 0.3)
    });
}

#[test]
fn one_item_per_cycle_when_never_stalled() {
    // An item is `cfg.lanes` positions: that many per clock.
    random_items_one_per_clock(random_item, 411, 1);
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(BucketUnit::new, random_item, directed_items, 412);
}

#[test]
fn every_block_reaches_its_own_queue_in_the_rtl() {
    // The bijection of the contract, on the RTL: one position per block, all (proc, queue) distinct.
    for (variant, cfg) in configs::<BucketConfig>() {
        let b = cfg.vol_blocks;
        let side = cfg.block_side();
        let mut rng = ChaCha8Rng::seed_from_u64(seed(414));
        let mut positions = Vec::new();
        for bx in 0..b {
            for by in 0..b {
                for bz in 0..b {
                    let p = [bx, by, bz].map(|k| {
                        (k * side + rng.random_range(0..side)) << POS_FRAC_W
                            | rng.random_range(0..1 << POS_FRAC_W)
                    });
                    positions.push(Position(p));
                }
            }
        }
        let lanes = cfg.lanes as usize;
        while positions.len() % lanes != 0 {
            positions.push(positions[0]);
        }
        let items: Vec<BucketIn> = positions
            .chunks(lanes)
            .map(|c| BucketIn(c.to_vec()))
            .collect();
        let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
        let n = items.len() as u64;
        let out = dut
            .drive(&items, &Traffic::full_speed(), n, 10 * n)
            .unwrap();
        let mut seen = vec![false; (cfg.procs() * cfg.queues()) as usize];
        for r in out
            .outputs
            .iter()
            .flat_map(|t| t.value.0.clone())
            .take((b * b * b) as usize)
        {
            assert!(!r.outside && r.queue < cfg.queues() && r.proc < cfg.procs());
            let slot = (r.proc * cfg.queues() + r.queue) as usize;
            assert!(
                !seen[slot],
                "{variant}: two blocks share processor {} queue {}",
                r.proc, r.queue
            );
            seen[slot] = true;
        }
        assert!(seen.iter().all(|&s| s), "{variant}: every queue is used");
    }
}

#[test]
fn a_model_with_the_wrong_distribution_is_caught() {
    // Same widths, other scheme: the scoreboard must see the difference within a few items.
    let slab = BucketConfig {
        dist: Distribution::Slab,
        ..BucketConfig::SKEW
    };
    let mut check = StreamCheck::new(seed(415), 5_000).with_traffic(0.1, 0.1);
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(
            variant_with(BucketConfig::SKEW),
            BucketConfig::SKEW,
            &mut BucketUnit::new(slab).unwrap(),
            &mut random_item(BucketConfig::SKEW),
            &check,
        ),
        "slab and skewed distributions differ",
    );
    assert!(err.item < 50, "caught at item {}", err.item);
}
