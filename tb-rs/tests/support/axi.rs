//! The run scaffolding the AXI manager tests (cube5_axi_rd, cube5_axi_wr, cube5_vol_fetch) share:
//! opening a top with its subordinate loaded, a reset that must leave nothing in flight, the
//! random subordinate, the pass line, the checker's refusals, and the test loops over the
//! configurations. The comparisons themselves are in `support` (`compare_*`, `axi_protocol_clean`).

use super::{axi_protocol_clean, compare_axi_outputs, compare_bursts, configs, gate_configs, seed};
use cube5_model::unit::{StreamCodec, UnitConfig};
use cube5_model::units::cube5_axi_rd::{AxiMemImage, AxiRdConfig, Burst};
use cube5_model::units::cube5_axi_wr::AxiWrConfig;
use cube5_model::units::gicube_cache::CacheConfig;
use cube5_tb::rtl::{AxiMemSetup, Driven, RtlStream, Traffic};
use cube5_tb::{Mismatch, TbError, Variant};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;
use std::path::PathBuf;

/// `variant` on `cfg`, its subordinate set up with `setup` and holding `mem`, recording the
/// waveform window of `trace` (set by `with_waves` on a re-run after a mismatch).
pub fn open<C: StreamCodec>(
    variant: &'static Variant,
    cfg: C,
    seed: u64,
    (setup, mem): (&AxiMemSetup, &AxiMemImage),
    trace: &Option<(PathBuf, (u64, u64))>,
) -> Result<RtlStream<C>, TbError> {
    let mut dut = RtlStream::new(variant, cfg, seed as u32)?;
    dut.axi_setup(setup)?;
    dut.axi_load(mem.base, &mem.bytes)?;
    if let Some((path, (from, to))) = trace {
        dut.trace_window(path, *from, *to);
    }
    Ok(dut)
}

/// Resets `dut`; no burst may still be in flight on the subordinate (its write side with
/// `write`). Returns the bursts the reset dropped.
pub fn reset_leaves_nothing_in_flight<C: StreamCodec>(
    dut: &mut RtlStream<C>,
    variant: &'static Variant,
    seed: u64,
    write: bool,
) -> Result<u64, TbError> {
    dut.reset();
    let (in_flight, dropped, what) = if write {
        let c = dut.axi_wr_counters();
        (c.in_flight, c.dropped_at_reset, "write bursts")
    } else {
        let c = dut.axi_counters();
        (c.in_flight, c.dropped_at_reset, "bursts")
    };
    if in_flight != 0 {
        return Err(TbError::Protocol {
            variant: variant.name.to_string(),
            seed,
            cycle: dut.cycle(),
            what: format!("{in_flight} {what} still in flight after the reset"),
        });
    }
    Ok(dropped)
}

/// The runs of one case: `work` (cut `cycles` in when `reset` = `(cycles, after)` follows), then
/// the reset, which must leave no burst in flight (on the write side with `write`), then `after`.
/// `go(dut, work, cut)` drives one list of work and compares what came out. Returns the bursts the
/// reset dropped (0 without a reset).
pub fn run_with_reset<C: StreamCodec, W>(
    dut: &mut RtlStream<C>,
    (variant, seed): (&'static Variant, u64),
    write: bool,
    (work, reset): (&W, &Option<(u64, W)>),
    mut go: impl FnMut(&mut RtlStream<C>, &W, Option<u64>) -> Result<(), TbError>,
) -> Result<u64, TbError> {
    go(dut, work, reset.as_ref().map(|r| r.0))?;
    let Some((_, after)) = reset else {
        return Ok(0);
    };
    let dropped = reset_leaves_nothing_in_flight(dut, variant, seed, write)?;
    go(dut, after, None)?;
    Ok(dropped)
}

/// Drives `cmds` on a read manager for at most `limit` cycles, then compares, AR first (a wrong
/// burst explains a wrong output): its bursts with `bursts` (ARSIZE `size`, `burst` names one),
/// then its outputs with `want` (a `noun` each, `describe` names one), in full if `exact`, else as
/// a prefix (a reset cuts the run). Returns the run and the bursts seen on AR.
pub fn drive_reads<C: StreamCodec<Out: PartialEq + Debug>>(
    dut: &mut RtlStream<C>,
    (variant, seed): (&'static Variant, u64),
    (cmds, traffic): (&[C::In], &Traffic),
    (want, noun, describe): (&[C::Out], &str, impl Fn(usize) -> String),
    (bursts, size, burst): (&[Burst], u32, impl Fn(usize) -> String),
    (exact, limit): (bool, u64),
) -> Result<(Driven<C::Out>, usize), TbError> {
    let driven = dut.drive(cmds, traffic, want.len() as u64, limit)?;
    axi_protocol_clean(dut, &driven.stats, variant, seed)?;
    let n_ars = compare_bursts(
        &dut.axi_take_ar()?,
        "AR",
        bursts,
        size,
        variant,
        seed,
        burst,
    )?;
    compare_axi_outputs(
        dut,
        &driven,
        want,
        (n_ars, bursts.len()),
        exact,
        limit,
        (variant, seed),
        noun,
        describe,
    )?;
    Ok((driven, n_ars))
}

/// A bandwidth limit of `U(1..=twice)` half-bytes per cycle on half the seeds, else none.
pub fn random_bandwidth(rng: &mut ChaCha8Rng, twice: u32) -> (u32, u32) {
    if rng.random_bool(0.5) {
        (rng.random_range(1..=twice), 2)
    } else {
        (0, 1)
    }
}

/// A passing run's report, after its line (`line`, behind the variant and seed); a failure
/// panics with its report.
pub fn must_pass<R>(
    variant: &'static Variant,
    seed: u64,
    run: Result<R, TbError>,
    line: impl Fn(&R) -> String,
) -> R {
    match run {
        Ok(r) => {
            eprintln!("{variant}: seed {seed}: {}", line(&r));
            r
        }
        Err(e) => panic!("{e}"),
    }
}

/// The subordinate's checker bites, and its report reaches the test: each `(setup, rule)` run
/// (`check`, at seed 77) fails as a protocol error naming the rule and the seed.
pub fn assert_checker_refuses<R: Debug>(
    variant: &'static Variant,
    refusals: Vec<(AxiMemSetup, &str)>,
    check: impl Fn(AxiMemSetup, u64) -> Result<R, TbError>,
) {
    for (setup, rule) in refusals {
        match check(setup, 77) {
            Err(e @ TbError::Protocol { .. }) => {
                let text = e.to_string();
                assert!(text.contains(rule), "{text}");
                assert!(text.contains("CUBE5_SEED=77"), "{text}");
            }
            Err(e) => panic!("{variant}: expected a protocol error about {rule}, got {e}"),
            Ok(r) => panic!("{variant}: the checker let it pass ({r:?})"),
        }
    }
}

/// On every configuration, three runs (seeds 400 + 10 x the configuration's index + k) that each
/// reset in mid-stream and return the bursts the reset dropped; some reset must land with bursts
/// in flight.
pub fn resets_land_with_bursts_in_flight<C: UnitConfig + Copy>(
    run: impl Fn(&'static Variant, C, u64) -> u64,
) {
    for (i, (variant, cfg)) in configs::<C>().into_iter().enumerate() {
        let dropped: u64 = (0..3)
            .map(|k| run(variant, cfg, seed(400 + 10 * i as u64 + k)))
            .sum();
        assert!(
            dropped > 0,
            "{variant}: some reset landed with bursts in flight"
        );
    }
}

/// On every configuration: runs (seeds 600 + 100 x the configuration's index + k, `k` from 0)
/// until they have taken a million items; `run` gets `k` and returns the items of its run.
pub fn a_million_per_config<C: UnitConfig + Copy>(
    run: impl Fn(&'static Variant, C, u64, u64) -> u64,
) {
    for (i, (variant, cfg)) in configs::<C>().into_iter().enumerate() {
        let mut items = 0u64;
        let mut k = 0u64;
        while items < 1_000_000 {
            items += run(variant, cfg, seed(600 + 100 * i as u64 + k), k);
            k += 1;
        }
    }
}

/// On every gate-level build (seed 500): `plain(variant, cfg, 500)`, then `with_reset(variant,
/// cfg, 501, rng)` with `rng` seeded 500 (for the reset's cycle and the work after it).
pub fn gate_smoke<C: UnitConfig + Copy>(
    plain: impl Fn(&'static Variant, C, u64),
    with_reset: impl Fn(&'static Variant, C, u64, &mut ChaCha8Rng),
) {
    for (variant, cfg) in gate_configs::<C>() {
        let s = seed(500);
        plain(variant, cfg, s);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        with_reset(variant, cfg, s + 1, &mut rng);
    }
}

/// On every configuration, `n` random runs (seeds 100 + 10 x the configuration's index + k).
pub fn random_runs<C: UnitConfig + Copy>(n: u64, run: impl Fn(&'static Variant, C, u64)) {
    for (i, (variant, cfg)) in configs::<C>().into_iter().enumerate() {
        for k in 0..n {
            run(variant, cfg, seed(100 + 10 * i as u64 + k));
        }
    }
}

/// A mismatch found after a run at `dut`'s cycle: `input` names what was sent, `rtl` and `model`
/// what each did.
pub fn mismatch<C: StreamCodec>(
    dut: &RtlStream<C>,
    (variant, seed): (&'static Variant, u64),
    input: String,
    rtl: String,
    model: String,
    what: &str,
) -> TbError {
    TbError::from(Mismatch {
        variant: variant.name.to_string(),
        seed,
        cycle: dut.cycle(),
        input,
        rtl,
        model,
        what: what.into(),
        ..Default::default()
    })
}

/// `err_o` against the model's after `cmds` commands: sticky, set by `some` (the response that
/// is not OKAY, e.g. "some BRESP") since reset.
pub fn err_flag_matches<C: StreamCodec>(
    dut: &RtlStream<C>,
    (variant, seed): (&'static Variant, u64),
    cmds: usize,
    want: bool,
    some: &str,
) -> Result<(), TbError> {
    if dut.axi_counters().err_flag == want {
        return Ok(());
    }
    Err(mismatch(
        dut,
        (variant, seed),
        format!("{cmds} commands"),
        format!("err_o = {}", !want),
        format!("err_o = {want}"),
        &format!("err_o differs (sticky: {some} != OKAY since reset)"),
    ))
}

/// A random subordinate of `cfg`'s port and stream traffic, as the AXI tests' random cases draw
/// them: latency 10..200, AR and R gaps up to 40 %, a bandwidth limit of up to the bus width per
/// cycle on half the seeds, idle 30 % and back-pressure up to 60 %.
pub fn random_conditions<C: AxiPort>(
    rng: &mut ChaCha8Rng,
    cfg: C,
    mem: &AxiMemImage,
) -> (AxiMemSetup, cube5_tb::rtl::Traffic) {
    let bw = random_bandwidth(rng, 2 * cfg.bus().0);
    let gaps = (rng.random_range(0..400), rng.random_range(0..400));
    let setup = mem_setup(cfg, mem, (10, 190), gaps, bw, rng.random());
    let stall = rng.random_range(0.0..0.6);
    (setup, cube5_tb::rtl::Traffic::random(rng, 0.3, stall))
}

/// A unit with an AXI4 manager port: its bus as (data bytes, address bits) and the bursts it
/// declares in flight (its Outstanding, the subordinate's checked limit).
pub trait AxiPort {
    fn bus(&self) -> (u32, u32);
    fn outstanding(&self) -> u32;
}

impl AxiPort for AxiRdConfig {
    fn bus(&self) -> (u32, u32) {
        (self.bytes(), self.addr_w)
    }
    fn outstanding(&self) -> u32 {
        self.outstanding
    }
}

impl AxiPort for AxiWrConfig {
    fn bus(&self) -> (u32, u32) {
        (self.bytes(), self.addr_w)
    }
    fn outstanding(&self) -> u32 {
        self.outstanding
    }
}

impl AxiPort for CacheConfig {
    fn bus(&self) -> (u32, u32) {
        (self.data_w / 8, self.addr_w)
    }
    fn outstanding(&self) -> u32 {
        self.outstanding
    }
}

/// The subordinate of `cfg`'s port: latency `fixed + U(0..random)`, AR/R gaps (permille),
/// bandwidth `bw` bytes per cycle as `(num, den)` (`num = 0`: unlimited), the unit's Outstanding
/// as its declared limit.
pub fn mem_setup<C: AxiPort>(
    cfg: C,
    mem: &AxiMemImage,
    lat: (u32, u32),
    gaps: (u32, u32),
    bw: (u32, u32),
    seed: u64,
) -> AxiMemSetup {
    AxiMemSetup {
        declared_outstanding: cfg.outstanding(),
        ..super::axi_mem_setup(cfg.bus(), mem, lat, gaps, bw, seed)
    }
}

/// A reset in mid-stream: the items after it drawn by `after` from a generator seeded `s ^
/// 0x5eed`, then the cycle it lands at, in `at` (the tests' one order of draws).
pub fn reset_after<T>(
    s: u64,
    at: std::ops::Range<u64>,
    after: impl FnOnce(&mut ChaCha8Rng) -> T,
) -> Option<(u64, T)> {
    let mut rng = ChaCha8Rng::seed_from_u64(s ^ 0x5eed);
    let after = after(&mut rng);
    Some((rng.random_range(at), after))
}
