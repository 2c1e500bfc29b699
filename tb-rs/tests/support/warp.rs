//! Whole-frame runs of the warps (cube5_warp, cube5_pwarp): one item (`Go`, `Line`) emits many
//! outputs, so a frame is driven here (registers, base plane, emitting items) rather than through
//! `check_stream` (one out per item), and a difference is named by frame and position.

use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_model::units::cube5_warp::BaseCodes;
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::Variant;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;

/// One frame of a warp test: the items it sends, and how one of its outputs is named.
pub trait WarpFrame {
    /// The unit's configuration (its codec).
    type Cfg: StreamCodec<In: Clone + Debug, Out: Clone + Debug + PartialEq> + Copy;
    /// The golden model.
    type Gold: StreamUnit<
        In = <Self::Cfg as StreamCodec>::In,
        Out = <Self::Cfg as StreamCodec>::Out,
    >;
    /// What one output is ("pixel", "sample").
    const OUT: &'static str;

    fn gold(cfg: Self::Cfg) -> Self::Gold;
    fn items(&self, cfg: &Self::Cfg) -> Vec<<Self::Cfg as StreamCodec>::In>;
    /// Output `at` of this frame (counted from its first), which is frame `i` of the run.
    fn describe(&self, i: usize, at: usize) -> String;
}

/// A random base plane: all ones one time in ten, else uniformly random codes.
pub fn random_base(rng: &mut ChaCha8Rng, w: usize, h: usize, color_w: u32) -> BaseCodes {
    let max = (1u32 << color_w) - 1;
    if rng.random_bool(0.1) {
        BaseCodes {
            width: w,
            height: h,
            codes: vec![[max; 3]; w * h],
        }
    } else {
        BaseCodes::random(rng, w, h, color_w)
    }
}

/// Runs `frames` through the RTL under `traffic` and through the model, and compares every
/// output; with `reset_after` = (frames, cycles), resets both that many cycles into the run of the
/// first `frames` frames, then runs the rest (each complete) after the reset. Panics with the seed,
/// the frame, the output, its registers and both outputs on the first difference. Returns the
/// cycles taken.
pub fn check_frames<F: WarpFrame>(
    variant: &'static Variant,
    cfg: F::Cfg,
    frames: &[F],
    traffic: &Traffic,
    seed: u64,
    reset_after: Option<(usize, u64)>,
) -> u64 {
    let out = F::OUT;
    let mut dut = RtlStream::new(variant, cfg, seed as u32).unwrap();
    let mut gold = F::gold(cfg);
    let (before, after) = match reset_after {
        Some((n, _)) => frames.split_at(n.min(frames.len())),
        None => (&frames[..0], frames),
    };
    let mut cycles = 0;
    if let Some((_, cut)) = reset_after {
        let items: Vec<_> = before.iter().flat_map(|f| f.items(&cfg)).collect();
        let driven = dut.drive(&items, traffic, u64::MAX, cut).unwrap();
        let consumed = driven.stats.consumed as usize;
        let want = gold.run(&items[..consumed]);
        let got: Vec<_> = driven.outputs.iter().map(|t| t.value.clone()).collect();
        assert!(
            got.len() <= want.len(),
            "{variant}: seed {seed}: extra outputs before the reset"
        );
        compare(variant, seed, before, &got, &want[..got.len()], &cfg);
        eprintln!(
            "{variant}: reset after {} cycles: {consumed} of {} items taken, {} {out}s out (of {} the model owes)",
            driven.stats.cycles,
            items.len(),
            got.len(),
            want.len()
        );
        dut.reset();
        gold.reset();
        cycles += driven.stats.cycles;
    }
    let items: Vec<_> = after.iter().flat_map(|f| f.items(&cfg)).collect();
    let want = gold.run(&items);
    let n = want.len() as u64;
    let driven = dut
        .drive(&items, traffic, n, 64 * (n + items.len() as u64) + 10_000)
        .unwrap();
    assert_eq!(
        driven.stats.protocol_errors, 0,
        "{variant}: seed {seed}: a stalled output dropped valid or changed"
    );
    let got: Vec<_> = driven.outputs.iter().map(|t| t.value.clone()).collect();
    compare(variant, seed, after, &got, &want, &cfg);
    assert_eq!(
        got.len(),
        want.len(),
        "{variant}: seed {seed}: the RTL produced {} of {} {out}s (deadlock or lost {out})",
        got.len(),
        want.len()
    );
    assert_eq!(driven.stats.consumed, items.len() as u64);
    cycles + driven.stats.cycles
}

/// The first differing output, named by its frame (`WarpFrame::describe`).
fn compare<F: WarpFrame>(
    variant: &Variant,
    seed: u64,
    frames: &[F],
    got: &[<F::Cfg as StreamCodec>::Out],
    want: &[<F::Cfg as StreamCodec>::Out],
    cfg: &F::Cfg,
) {
    let Some(k) = (0..got.len().min(want.len())).find(|&k| got[k] != want[k]) else {
        return;
    };
    // Which frame: count each frame's outputs as the model emits them.
    let mut at = k;
    let mut who = String::from("(past the frames)");
    for (i, f) in frames.iter().enumerate() {
        let n = F::gold(*cfg).run(&f.items(cfg)).len();
        if at < n {
            who = f.describe(i, at);
            break;
        }
        at -= n;
    }
    panic!(
        "{variant}: seed {seed}: {} #{k} differs: {who}\n  RTL   {:?}\n  model {:?}",
        F::OUT,
        got[k],
        want[k]
    );
}
