//! Co-simulation of cube5_sepconv against the golden model (docs/numerics/sepconv.md).

mod support;

use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_sepconv::{Sepconv, SepconvConfig, SepconvIn, SepconvKernel};
use cube5_tb::harness::{check_stream, must_match, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::Variant;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use support::{
    assert_foreign_codec_is_refused, assert_one_item_per_clock, configs, expect_mismatch,
    gate_configs, must_match_across_a_reset, must_match_items, random_items, seed, MILLION,
};

const LATENCY: u64 = 2;

/// Random items: taps uniform over the whole two's complement range, or (one in four) drawn from
/// the extremes, or (one in four) small around zero where the rounding ties of small values lie.
fn random_item(cfg: SepconvConfig) -> impl FnMut(&mut ChaCha8Rng) -> SepconvIn {
    move |rng| {
        let (lo, hi) = (cfg.tap_min(), cfg.tap_max());
        let class = rng.random_range(0..4);
        let taps = std::array::from_fn(|_| match class {
            0 => [lo, lo + 1, -1, 0, 1, hi - 1, hi][rng.random_range(0..7)],
            1 => rng.random_range(-8..=8),
            _ => rng.random_range(lo..=hi),
        });
        SepconvIn {
            taps,
            kernel: SepconvKernel::from_bits(rng.random_range(0..2)),
        }
    }
}

/// Weights exercised: 0, one LSB, 1.0, 2.0 (Sobel, binomial), a Gaussian, the largest.
fn weights(cfg: SepconvConfig) -> Vec<u32> {
    vec![
        0,
        1,
        cfg.weight_from_f64(1.0),
        cfg.weight_from_f64(2.0),
        cfg.weight_from_f64(std::f64::consts::E.sqrt()), // sigma = 1
        cfg.weight_max(),
    ]
}

/// Every combination of extreme taps with both kernels.
fn directed_items(cfg: SepconvConfig) -> Vec<SepconvIn> {
    let (lo, hi) = (cfg.tap_min(), cfg.tap_max());
    let values = [lo, lo + 1, -2, -1, 0, 1, 2, hi - 1, hi];
    let mut items = Vec::new();
    for &a in &values {
        for &b in &values {
            for &c in &values {
                for kernel in [SepconvKernel::Smooth, SepconvKernel::Diff] {
                    items.push(SepconvIn {
                        taps: [a, b, c],
                        kernel,
                    });
                }
            }
        }
    }
    items
}

#[test]
fn million_random_items_per_config_with_idle_backpressure_and_reset() {
    for (i, (variant, cfg)) in configs::<SepconvConfig>().into_iter().enumerate() {
        let mut rng: ChaCha8Rng = rand::SeedableRng::seed_from_u64(seed(400 + i as u64));
        let w = rng.random_range(0..=cfg.weight_max());
        let mut gold = Sepconv::new(cfg, w).unwrap();
        // The weight is written once, before the first item; it must survive the reset.
        let check = StreamCheck::long(seed(410 + i as u64), MILLION, 5)
            .with_config_writes(gold.config_writes());
        must_match_across_a_reset(variant, cfg, &mut gold, &mut random_item(cfg), &check, 1000);
    }
}

/// The directed items at every weight of `weights`, each weight loaded through the port.
fn directed_at_every_weight(variant: &'static Variant, cfg: SepconvConfig, seed_no: u64) {
    for w in weights(cfg) {
        let mut gold = Sepconv::new(cfg, w).unwrap();
        let writes = gold.config_writes();
        let check = StreamCheck::directed(seed(seed_no)).with_config_writes(writes);
        must_match_items(variant, cfg, &mut gold, directed_items(cfg), &check);
    }
}

#[test]
fn directed_extremes_at_every_weight() {
    for (variant, cfg) in configs::<SepconvConfig>() {
        directed_at_every_weight(variant, cfg, 41);
    }
}

#[test]
fn one_item_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<SepconvConfig>() {
        let gold = Sepconv::new(cfg, cfg.weight_from_f64(2.0)).unwrap();
        let items = random_items(seed(42), 100_000, random_item(cfg));
        let writes = gold.config_writes();
        let driven = assert_one_item_per_clock(variant, cfg, &writes, &items, LATENCY);
        let want = gold.clone().run(&items);
        assert!(driven.outputs.iter().zip(&want).all(|(t, g)| t.value == *g));
    }
}

#[test]
fn a_weight_write_applies_to_items_accepted_after_it() {
    // Items still in flight when w changes keep the w they were accepted with: drive a batch but
    // stop waiting for its last outputs, write a new w, then drive a second batch.
    for (variant, cfg) in configs::<SepconvConfig>() {
        let (w1, w2) = (cfg.weight_from_f64(2.0), cfg.weight_max());
        let mut gold = Sepconv::new(cfg, w1).unwrap();
        let mut dut = RtlStream::new(variant, cfg, 7).unwrap();
        for (addr, data) in gold.config_writes() {
            dut.write_config(addr, &data).unwrap();
        }
        let mut rng = rand::SeedableRng::seed_from_u64(seed(43));
        let mut gen = random_item(cfg);
        let first: Vec<SepconvIn> = (0..1000).map(|_| gen(&mut rng)).collect();
        let second: Vec<SepconvIn> = (0..1000).map(|_| gen(&mut rng)).collect();
        let mut want = gold.run(&first);
        gold.set_weight(w2).unwrap();
        want.extend(gold.run(&second));

        let full = Traffic::full_speed();
        let a = dut.drive(&first, &full, 0, 10_000).unwrap();
        let in_flight = first.len() - a.outputs.len();
        assert!(
            in_flight >= 1,
            "{variant}: items are in flight at the write"
        );
        for (addr, data) in gold.config_writes() {
            dut.write_config(addr, &data).unwrap();
        }
        // Address 1 is ignored.
        dut.write_config(1, &[0]).unwrap();
        let b = dut
            .drive(&second, &full, (in_flight + second.len()) as u64, 10_000)
            .unwrap();
        let got: Vec<i64> = a
            .outputs
            .iter()
            .chain(&b.outputs)
            .map(|t| t.value)
            .collect();
        assert_eq!(got.len(), want.len());
        if let Some(k) = (0..got.len()).find(|&k| got[k] != want[k]) {
            panic!(
                "{variant}: item {k} ({:?}): rtl {} model {}",
                first.iter().chain(&second).nth(k),
                got[k],
                want[k]
            );
        }
    }
}

#[test]
fn gate_level_netlist_smoke() {
    let (variant, cfg) = gate_configs::<SepconvConfig>()[0];
    let mut gold = Sepconv::new(cfg, cfg.weight_from_f64(2.0)).unwrap();
    let writes = gold.config_writes();
    let smoke = StreamCheck::gate_smoke(seed(44)).with_config_writes(writes);
    must_match(variant, cfg, &mut gold, &mut random_item(cfg), &smoke);
    directed_at_every_weight(variant, cfg, 45);
}

/// A golden model that rounds ties down instead of up.
struct TiesDown(Sepconv);

impl StreamUnit for TiesDown {
    type In = SepconvIn;
    type Out = i64;

    fn run(&mut self, inputs: &[SepconvIn]) -> Vec<i64> {
        let s = self.0.config().out_shift;
        inputs
            .iter()
            .map(|it| (self.0.exact(it) + (1 << (s - 1)) - 1) >> s)
            .collect()
    }
}

#[test]
fn the_weight_register_and_the_rounding_are_checked() {
    let (variant, cfg) = configs::<SepconvConfig>()[0];
    // 2.25: an odd raw weight, so y = 4a + 9b + 4c reaches every residue of the shift by 2 (with
    // w = 2.0 every y is a multiple of 4 and the rounding never sees a tie).
    let w = cfg.weight_from_f64(2.25);
    assert_eq!(w % 2, 1);
    let mut check = StreamCheck::new(seed(46), 20_000).with_traffic(0.1, 0.1);
    check.waveform_on_mismatch = false;

    // The RTL loaded with w one LSB off the model's: the configuration port reaches the datapath.
    let off_by_one = check.clone().with_config_writes(vec![(0, vec![w + 1])]);
    let err = expect_mismatch(
        check_stream(
            variant,
            cfg,
            &mut Sepconv::new(cfg, w).unwrap(),
            &mut random_item(cfg),
            &off_by_one,
        ),
        "a different w must be caught",
    );
    assert_eq!(err.what, "output differs");

    // A write to any other address leaves w alone.
    let other_address =
        check
            .clone()
            .with_config_writes(vec![(0, vec![w]), (1, vec![w + 1]), (15, vec![0])]);
    must_match(
        variant,
        cfg,
        &mut Sepconv::new(cfg, w).unwrap(),
        &mut random_item(cfg),
        &other_address,
    );

    // Round half down instead of up.
    let loaded = check.with_config_writes(vec![(0, vec![w])]);
    let err = expect_mismatch(
        check_stream(
            variant,
            cfg,
            &mut TiesDown(Sepconv::new(cfg, w).unwrap()),
            &mut random_item(cfg),
            &loaded,
        ),
        "the rounding direction of ties must be caught",
    );
    assert_eq!(err.what, "output differs");
}

#[test]
fn codec_and_variant_are_checked_against_the_rtl() {
    assert_foreign_codec_is_refused::<SepconvConfig>();
}
