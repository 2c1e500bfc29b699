//! Co-simulation of cube5_gradient against the golden model (docs/numerics/gradient.md).

mod support;

use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_gradient::{
    block_index, block_offset, block_where, Gradient, GradientConfig, GradientIn, GradientMode,
    GradientOut,
};
use cube5_tb::harness::{check_stream, StreamCheck};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use support::{
    assert_codec_and_config_port, assert_one_item_per_clock, configs, directed_on_every_config,
    expect_mismatch, gate_smoke_then_directed, million_across_a_reset, must_match_items,
    random_items, seed,
};

const LATENCY: u64 = 5;

/// Random items: a mixture of uniform blocks (large gradients), near-constant blocks (small
/// gradients of both signs, zero), and linear ramps in random directions (every magnitude
/// ordering of the components). Steps: mostly in [-1, 1], some at the extremes and beyond.
fn random_item(cfg: GradientConfig) -> impl FnMut(&mut ChaCha8Rng) -> GradientIn {
    move |rng| {
        let max = i64::from(cfg.sample_max());
        let samples: [u32; 27] = match rng.random_range(0..4) {
            0 | 1 => std::array::from_fn(|_| rng.random_range(0..=cfg.sample_max())),
            2 => {
                let base = rng.random_range(0..=max);
                let spread = rng.random_range(0..=8);
                std::array::from_fn(|_| {
                    (base + rng.random_range(-spread..=spread)).clamp(0, max) as u32
                })
            }
            _ => {
                let slope = max / 2;
                let (a, b, c) = (
                    rng.random_range(-slope..=slope),
                    rng.random_range(-slope..=slope),
                    rng.random_range(-slope..=slope),
                );
                let base = rng.random_range(0..=max);
                std::array::from_fn(|i| {
                    let (di, dj, dk) = block_offset(i);
                    let d = a * i64::from(di) + b * i64::from(dj) + c * i64::from(dk);
                    (base + d).clamp(0, max) as u32
                })
            }
        };
        let one = 1i32 << cfg.weight_w;
        let step = |rng: &mut ChaCha8Rng| match rng.random_range(0..8) {
            0 => rng.random_range(cfg.step_min()..=cfg.step_max()),
            1 => [
                0,
                one,
                -one,
                one - 1,
                -one + 1,
                cfg.step_min(),
                cfg.step_max(),
            ][rng.random_range(0..7)],
            _ => rng.random_range(-one..=one),
        };
        GradientIn {
            samples,
            dx: step(rng),
            dy: step(rng),
            mode: GradientMode::from_bits(rng.random_range(0..4)),
        }
    }
}

/// Extremes: all 0, all max, half-spaces and checkerboards at max against 0, every mode, steps at
/// 0, one LSB, one half, one, beyond one, and the ends of the field's range.
fn directed_items(cfg: GradientConfig) -> Vec<GradientIn> {
    let max = cfg.sample_max();
    let one = 1i32 << cfg.weight_w;
    let blocks = [
        [0; 27],
        [max; 27],
        block_where(max, |di, dj, dk| di + dj + dk > 0),
        block_where(max, |di, dj, dk| di + dj + dk < 0),
        block_where(max, |di, dj, dk| di > 0 || dj > 0 || dk > 0),
        block_where(max, |di, dj, dk| di < 0 || dj < 0 || dk < 0),
        block_where(max, |di, _, _| di > 0),
        block_where(max, |_, dj, _| dj < 0),
        block_where(max, |_, _, dk| dk > 0),
        block_where(max, |di, dj, dk| (di + dj + dk) & 1 == 0),
        block_where(max, |di, dj, dk| di * dj * dk != 0),
        block_where(max, |di, dj, dk| di == 1 && dj == 1 && dk == 1),
        block_where(max, |di, dj, dk| di == -1 && dj == -1 && dk == -1),
    ];
    let steps = [
        0,
        1,
        -1,
        one / 2,
        -one / 2,
        one - 1,
        -one + 1,
        one,
        -one,
        one + 1,
        -one - 1,
        cfg.step_min(),
        cfg.step_max(),
    ];
    let mut items = Vec::new();
    for samples in blocks {
        for mode in [
            GradientMode::N6,
            GradientMode::N10,
            GradientMode::N26,
            GradientMode::Reserved,
        ] {
            for &dx in &steps {
                for &dy in &[0, one / 2, -one, cfg.step_min(), cfg.step_max()] {
                    items.push(GradientIn {
                        samples,
                        dx,
                        dy,
                        mode,
                    });
                }
            }
        }
    }
    items
}

#[test]
fn million_random_items_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(Gradient::new, random_item, 300, 5, 1000);
}

#[test]
fn directed_extremes() {
    directed_on_every_config(Gradient::new, directed_items, |_| {
        StreamCheck::directed(seed(31))
    });
}

#[test]
fn n10_rounding_ties_both_signs() {
    // One partner sample of value v on the next (or previous) plane with a step of one LSB gives
    // A - B = +-v * 2^WeightW: ties of the final shift by 2 WeightW - 4 whenever v * 2^WeightW is
    // an odd multiple of 2^(2 WeightW - 5), i.e. v = (2k+1) 2^(WeightW-5).
    for (variant, cfg) in configs::<GradientConfig>() {
        let unit = Gradient::new(cfg).unwrap();
        let s = 2 * cfg.weight_w - 4;
        let mut items = Vec::new();
        for k in 0..64u32 {
            let v = ((2 * k + 1) << (cfg.weight_w - 5)).min(cfg.sample_max());
            for (plane, dx) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
                let mut samples = [0u32; 27];
                let partner = if dx > 0 { -plane } else { plane };
                samples[block_index(partner, 0, plane)] = v;
                let item = GradientIn {
                    samples,
                    dx,
                    dy: 0,
                    mode: GradientMode::N10,
                };
                let d = unit.n10_difference(&item);
                assert_eq!(d.abs() % (1 << s), 1 << (s - 1), "a tie");
                items.push(item);
            }
        }
        let check = StreamCheck::new(seed(32), items.len()).with_traffic(0.2, 0.2);
        must_match_items(
            variant,
            cfg,
            &mut Gradient::new(cfg).unwrap(),
            items,
            &check,
        );
    }
}

#[test]
fn one_item_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<GradientConfig>() {
        let items = random_items(seed(33), 100_000, random_item(cfg));
        let driven = assert_one_item_per_clock(variant, cfg, &[], &items, LATENCY);
        let gold = Gradient::new(cfg).unwrap().run(&items);
        assert!(driven.outputs.iter().zip(&gold).all(|(t, g)| t.value == *g));
    }
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(Gradient::new, random_item, directed_items, 34);
}

/// A golden model with one contract detail changed: co-simulation must reject each, which shows
/// the stimulus reaches that detail (signed fields, the N10 geometry and rounding, the reserved
/// mode, the magnitude rounding), beyond what trilin's flipped-bit check proves.
#[derive(Debug, Clone, Copy)]
enum Mutation {
    /// N10 rounds ties down instead of up.
    N10TiesDown,
    /// N10 takes its partner rays on the wrong side (the step's sign ignored).
    N10PartnerSideFlipped,
    /// Mode 3 behaves as N26 instead of N6.
    ReservedAsN26,
    /// The magnitude truncates instead of rounding half up.
    MagnitudeTruncates,
    /// gz loses its sign in the output field (two's complement not respected).
    GzUnsigned,
}

struct Mutant {
    unit: Gradient,
    mutation: Mutation,
}

impl StreamUnit for Mutant {
    type In = GradientIn;
    type Out = GradientOut;

    fn run(&mut self, inputs: &[GradientIn]) -> Vec<GradientOut> {
        let cfg = self.unit.config();
        inputs
            .iter()
            .map(|item| {
                let mut out = self.unit.gradient(item);
                match self.mutation {
                    Mutation::N10TiesDown if item.mode == GradientMode::N10 => {
                        let s = 2 * cfg.weight_w - 4;
                        let d = self.unit.n10_difference(item);
                        let down = (d + (1 << (s - 1)) - 1) >> s;
                        out = self.with_gz(out, down);
                    }
                    Mutation::N10PartnerSideFlipped if item.mode == GradientMode::N10 => {
                        let flip = |d: i32| (-d).clamp(cfg.step_min(), cfg.step_max());
                        let g = self.unit.components(&GradientIn {
                            dx: flip(item.dx),
                            dy: flip(item.dy),
                            ..*item
                        });
                        out = self.with_gz(out, g[2]);
                    }
                    Mutation::ReservedAsN26 if item.mode == GradientMode::Reserved => {
                        out = self.unit.gradient(&GradientIn {
                            mode: GradientMode::N26,
                            ..*item
                        });
                    }
                    Mutation::MagnitudeTruncates => {
                        let mut a = [out.gx, out.gy, out.gz].map(|g| i64::from(g).abs());
                        a.sort_unstable_by(|x, y| y.cmp(x));
                        out.mag = ((30 * a[0] + 13 * a[1] + 9 * a[2]) >> 5) as u32;
                    }
                    Mutation::GzUnsigned => {
                        out.gz = (out.gz as u32 & ((1 << cfg.grad_w()) - 1)) as i32;
                    }
                    _ => {}
                }
                out
            })
            .collect()
    }
}

impl Mutant {
    fn with_gz(&self, out: GradientOut, gz: i64) -> GradientOut {
        let g = [i64::from(out.gx), i64::from(out.gy), gz];
        GradientOut {
            gz: gz as i32,
            mag: self.unit.magnitude(g),
            ..out
        }
    }
}

#[test]
fn each_mutated_contract_detail_is_caught() {
    for (variant, cfg) in [
        configs::<GradientConfig>()[0],
        configs::<GradientConfig>()[1],
    ] {
        for mutation in [
            Mutation::N10TiesDown,
            Mutation::N10PartnerSideFlipped,
            Mutation::ReservedAsN26,
            Mutation::MagnitudeTruncates,
            Mutation::GzUnsigned,
        ] {
            let mut check = StreamCheck::new(seed(36), 50_000).with_traffic(0.1, 0.1);
            check.waveform_on_mismatch = false;
            let mut mutant = Mutant {
                unit: Gradient::new(cfg).unwrap(),
                mutation,
            };
            let err = expect_mismatch(
                check_stream(variant, cfg, &mut mutant, &mut random_item(cfg), &check),
                "a mutated golden model must not match the RTL",
            );
            assert_eq!(err.what, "output differs", "{variant} {mutation:?}: {err}");
            eprintln!("{variant} {mutation:?}: caught at item {}", err.item);
        }
    }
}

#[test]
fn codec_and_variant_are_checked_against_the_rtl() {
    assert_codec_and_config_port::<GradientConfig>((0, &[1]), false);
}
