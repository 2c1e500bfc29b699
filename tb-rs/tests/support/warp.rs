//! Whole-frame runs of the warps (cube5_warp, cube5_pwarp): one item (`Go`, `Line`) emits many
//! outputs, so a frame is driven here (registers, base plane, emitting items) rather than through
//! `check_stream` (one out per item), and a difference is named by frame and position.

use super::{configs, gate_configs, seed};
use cube5_model::unit::{StreamCodec, StreamUnit, UnitConfig};
use cube5_model::units::cube5_warp::{BaseCodes, WarpIn, WarpKind, WarpUnit};
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One frame of a warp test: the items it sends, and how one of its outputs is named.
pub trait WarpFrame {
    /// The unit's configuration (its codec; the golden model is `WarpUnit<Cfg>`).
    type Cfg: WarpKind
        + StreamCodec<In = WarpIn, Out = <Self::Cfg as WarpKind>::Out>
        + UnitConfig
        + Copy;
    /// What one output is ("pixel", "sample").
    const OUT: &'static str;

    fn items(&self, cfg: &Self::Cfg) -> Vec<WarpIn>;
    /// Output `at` of this frame (counted from its first), which is frame `i` of the run.
    fn describe(&self, i: usize, at: usize) -> String;
}

/// The golden model of `F`'s unit on `cfg`.
fn gold<F: WarpFrame>(cfg: F::Cfg) -> WarpUnit<F::Cfg> {
    WarpUnit::new(cfg).unwrap()
}

/// A random base plane: all ones one time in ten, else uniformly random codes.
pub fn random_base(rng: &mut ChaCha8Rng, w: usize, h: usize, color_w: u32) -> BaseCodes {
    if rng.random_bool(0.1) {
        flat_bases(w, h, color_w).remove(0).0
    } else {
        BaseCodes::random(rng, w, h, color_w)
    }
}

/// The all-ones and the all-zero base plane of `w x h` texels, with their names.
pub fn flat_bases(w: usize, h: usize, color_w: u32) -> Vec<(BaseCodes, &'static str)> {
    let max = (1u32 << color_w) - 1;
    [(max, "all-ones plane"), (0, "all-zero plane")]
        .into_iter()
        .map(|(code, what)| {
            let codes = vec![[code; 3]; w * h];
            let plane = BaseCodes {
                width: w,
                height: h,
                codes,
            };
            (plane, what)
        })
        .collect()
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
    let mut gold = gold::<F>(cfg);
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
        let n = gold::<F>(*cfg).run(&f.items(cfg)).len();
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

/// On every configuration: `directed` frames (seed `seed_no` + the configuration's index) at full
/// speed, under idle and back-pressure, and under heavy back-pressure.
pub fn directed_under_idle_and_backpressure<F: WarpFrame>(
    directed: impl Fn(&F::Cfg, &mut ChaCha8Rng) -> Vec<F>,
    seed_no: u64,
) {
    for (i, (variant, cfg)) in configs::<F::Cfg>().into_iter().enumerate() {
        let s = seed(seed_no + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let frames = directed(&cfg, &mut rng);
        for (idle, stall) in [(0.0, 0.0), (0.3, 0.3), (0.0, 0.7)] {
            let t = Traffic::random(&mut rng, idle, stall);
            check_frames(variant, cfg, &frames, &t, s, None);
        }
        eprintln!("{variant}: {} directed frames bit-exact", frames.len());
    }
}

/// On every configuration, six times: six `random` frames, both sides reset at a random cycle in
/// the first three, the last three after the reset.
pub fn a_reset_in_mid_stream<F: WarpFrame>(
    random: impl Fn(&mut ChaCha8Rng, &F::Cfg) -> F,
    seed_no: u64,
) {
    for (i, (variant, cfg)) in configs::<F::Cfg>().into_iter().enumerate() {
        let s = seed(seed_no + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        for _ in 0..6 {
            let frames: Vec<F> = (0..6).map(|_| random(&mut rng, &cfg)).collect();
            let t = Traffic::random(&mut rng, 0.2, 0.3);
            let cut = rng.random_range(1..3000);
            check_frames(variant, cfg, &frames, &t, s, Some((3, cut)));
        }
    }
}

/// On every gate-level build: `n` `random` frames and the `directed` ones under idle and
/// back-pressure, with a reset 900 cycles into the first four.
pub fn gate_level_smoke<F: WarpFrame>(
    n: usize,
    random: impl Fn(&mut ChaCha8Rng, &F::Cfg) -> F,
    directed: impl Fn(&F::Cfg, &mut ChaCha8Rng) -> Vec<F>,
    seed_no: u64,
) {
    for (variant, cfg) in gate_configs::<F::Cfg>() {
        let s = seed(seed_no);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mut frames: Vec<F> = (0..n).map(|_| random(&mut rng, &cfg)).collect();
        frames.extend(directed(&cfg, &mut rng));
        let t = Traffic::random(&mut rng, 0.2, 0.2);
        check_frames(variant, cfg, &frames, &t, s, Some((4, 900)));
        eprintln!("{variant}: gate-level smoke, {} frames", frames.len());
    }
}

/// The comparison bites: the first configuration's RTL against the model of `wrong(cfg)` must
/// differ on four `random` frames.
pub fn a_wrong_model_is_caught<F: WarpFrame>(
    random: impl Fn(&mut ChaCha8Rng, &F::Cfg) -> F,
    wrong: impl Fn(F::Cfg) -> F::Cfg,
    what: &str,
    seed_no: u64,
) {
    let (variant, cfg) = configs::<F::Cfg>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(seed(seed_no));
    let frames: Vec<F> = (0..4).map(|_| random(&mut rng, &cfg)).collect();
    let items: Vec<_> = frames.iter().flat_map(|f| f.items(&cfg)).collect();
    let want = gold::<F>(wrong(cfg)).run(&items);
    let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
    let n = want.len() as u64;
    let driven = dut
        .drive(&items, &Traffic::full_speed(), n, 1 << 24)
        .unwrap();
    let got: Vec<_> = driven.outputs.iter().map(|t| t.value.clone()).collect();
    assert!(got != want, "{variant}: {what} went unnoticed");
}
