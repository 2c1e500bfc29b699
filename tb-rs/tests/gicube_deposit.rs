//! Co-simulation of gicube_deposit (the splatting unit's energies, part M of the GI-Cube block
//! processor) against the golden model `DepositConfig::deposit`
//! (docs/numerics/gicube_processor.md, *Splatting through the cache*): every cache item, bit for
//! bit, under random idle and back-pressure, across a reset, at one item per clock.

mod support;

use cube5_model::units::gicube_deposit::{
    random_deposit_in, DepositConfig, DepositIn, DepositOut, LATENCY, OP_DEPOSIT, OP_FLUSH, OP_READ,
};
use cube5_tb::harness::{check_stream, StreamCheck};
use support::{
    assert_one_item_per_clock, configs, directed_on_every_config, expect_mismatch,
    gate_smoke_then_directed, million_across_a_reset, must_match_across_a_reset, random_items,
    seed, variant_with,
};

fn new(cfg: DepositConfig) -> cube5_model::Result<DepositConfig> {
    cfg.validate()?;
    Ok(cfg)
}

fn random_item(cfg: DepositConfig) -> impl FnMut(&mut rand_chacha::ChaCha8Rng) -> DepositIn {
    move |rng| random_deposit_in(rng, &cfg)
}

/// Items in flight that a reset may drop: the stages plus the handshake's slack.
const IN_FLIGHT: usize = LATENCY as usize + 2;

/// The extremes: the largest energy with no opacity (every corner on one weight: the largest
/// energy, 65,520 at `dr = 4`; the clamp beyond), the largest opacity (`T = 1`), `E = 0`, every
/// fraction 0, 1, 128, 255, the cell at the origin, at the volume's far faces (corners outside)
/// and at the top of the cache's range, dimensions 0 (nothing inside), 1 and the largest, reads
/// and flushes with full energies (nothing deposited).
fn directed_items(cfg: DepositConfig) -> Vec<DepositIn> {
    let side = 1u32 << cfg.mw;
    let dmax = side.min(127);
    let mut items = Vec::new();
    for dims in [[dmax; 3], [0; 3], [1, 1, 1], [dmax, 1, dmax]] {
        for cell in [
            [0; 3],
            [dims[0].saturating_sub(1); 3],
            [side - 1; 3],
            [0, side - 1, 1],
        ] {
            for (energy, opacity) in [(4095, 0), (4095, 4095), (0, 0), (1, 0), (2048, 2048)] {
                for f in [0, 1, 128, 255] {
                    for frac in [[f; 3], [f, 255 - f, 0]] {
                        for op in [OP_DEPOSIT, OP_READ, OP_FLUSH] {
                            items.push(DepositIn {
                                cell: cell.map(|c| c.min(side - 1)),
                                energy,
                                opacity,
                                frac,
                                op,
                                dims,
                            });
                        }
                    }
                }
            }
        }
    }
    items
}

#[test]
#[ignore = "sim-full: a million items per configuration with idle, back-pressure and a reset"]
fn million_random_items_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(new, random_item, 1980, 5, 32);
}

#[test]
fn random_items_with_idle_backpressure_and_reset() {
    // CI's share of the million above.
    for (i, (variant, cfg)) in configs::<DepositConfig>().into_iter().enumerate() {
        let check = StreamCheck::long(seed(1981 + i as u64), 40_000, 0).with_batch(10_000);
        must_match_across_a_reset(
            variant,
            cfg,
            &mut new(cfg).unwrap(),
            &mut random_item(cfg),
            &check,
            IN_FLIGHT,
        );
    }
}

#[test]
fn directed_extremes() {
    directed_on_every_config(new, directed_items, |n| {
        assert!(n > 1000);
        StreamCheck::directed(seed(1985))
    });
}

#[test]
fn one_item_per_clock() {
    for (variant, cfg) in configs::<DepositConfig>() {
        let items = random_items(seed(1986), 50_000, random_item(cfg));
        let out = assert_one_item_per_clock(variant, cfg, &[], &items, LATENCY);
        let want: Vec<DepositOut> = items.iter().map(|it| cfg.deposit(it)).collect();
        let got: Vec<DepositOut> = out.outputs.iter().map(|o| o.value).collect();
        assert_eq!(got, want, "{variant}: at full speed");
        let deposits = got.iter().filter(|o| o.e.iter().any(|&e| e > 0)).count();
        eprintln!("{variant}: 50,000 items at one per clock, {deposits} with energy");
    }
}

#[test]
#[ignore = "sim-full: the gate-level netlist is a `full` build (minutes of Yosys and Verilator)"]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(new, random_item, directed_items, 1987);
}

#[test]
fn a_model_with_another_step_is_caught() {
    let (variant, cfg) = configs::<DepositConfig>()[0];
    let other = DepositConfig {
        step: cfg.step + 1,
        ..cfg
    };
    let mut check = StreamCheck::new(seed(1988), 5_000).with_traffic(0.1, 0.1);
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(
            variant_with(cfg),
            cfg,
            &mut new(other).unwrap(),
            &mut random_item(cfg),
            &check,
        ),
        "a different dr changes the energies",
    );
    assert!(err.item < 100, "{variant}: caught at item {}", err.item);
}
