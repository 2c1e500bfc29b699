//! Helpers shared by the co-simulation tests. The scoreboard and its presets live in the library
//! (`cube5_tb::harness`: `must_match`, `StreamCheck::{directed, long, gate_smoke}`); these add
//! only what several test files repeat.
#![allow(dead_code)]

use cube5_model::unit::{StreamCodec, StreamUnit, UnitConfig};
use cube5_tb::harness::{seed_from_env, StreamCheck, StreamReport};
use cube5_tb::rtl::{Driven, RtlStream, Traffic};
use cube5_tb::{must_match, Variant};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;

pub mod axi;
pub mod processor;
pub mod warp;

/// Random items per configuration in the long co-simulation runs (the acceptance figure).
pub const MILLION: usize = 1_000_000;

/// A codec the scoreboard can run: inputs it can replay and print, outputs it can compare.
pub trait Scored: StreamCodec<In: Clone + Debug, Out: Clone + Debug + PartialEq> + Clone {}

impl<C: StreamCodec<In: Clone + Debug, Out: Clone + Debug + PartialEq> + Clone> Scored for C {}

/// The seed of a test: `CUBE5_SEED` if set, else a fixed default per test.
pub fn seed(default: u64) -> u64 {
    seed_from_env(default)
}

/// The value of a run that must succeed; a failure panics with its report (seed, cycle, what).
pub fn must<T>(r: Result<T, cube5_tb::TbError>) -> T {
    r.unwrap_or_else(|e| panic!("{e}"))
}

/// `n` items from `gen`, seeded with `seed`.
pub fn random_items<T>(seed: u64, n: usize, mut gen: impl FnMut(&mut ChaCha8Rng) -> T) -> Vec<T> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| gen(&mut rng)).collect()
}

/// `must_match` on `items` in order, started over as often as `check.items` asks; once when it
/// is 0 (`StreamCheck::directed`).
pub fn must_match_items<C, G>(
    variant: &'static Variant,
    codec: C,
    gold: &mut G,
    items: Vec<C::In>,
    check: &StreamCheck,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let mut check = check.clone();
    if check.items == 0 {
        check.items = items.len();
    }
    let mut it = items.into_iter().cycle();
    must_match(variant, codec, gold, &mut |_| it.next().unwrap(), &check)
}

/// On every gate-level build of `C`'s top: the smoke run of `gen` (seed `seed_no`), then the
/// `directed` items once (seed `seed_no + 1`), each on a fresh model from `new`.
pub fn gate_smoke_then_directed<C, G, F>(
    new: impl Fn(C) -> cube5_model::Result<G>,
    gen: impl Fn(C) -> F,
    directed: impl Fn(C) -> Vec<C::In>,
    seed_no: u64,
) where
    C: Scored + UnitConfig + Copy,
    G: StreamUnit<In = C::In, Out = C::Out>,
    F: FnMut(&mut ChaCha8Rng) -> C::In,
{
    for (variant, cfg) in gate_configs::<C>() {
        let smoke = StreamCheck::gate_smoke(seed(seed_no));
        must_match(variant, cfg, &mut new(cfg).unwrap(), &mut gen(cfg), &smoke);
        let check = StreamCheck::directed(seed(seed_no + 1));
        must_match_items(variant, cfg, &mut new(cfg).unwrap(), directed(cfg), &check);
    }
}

/// On every build of `C`'s top: 100 000 items of `gen` (seed `seed_no`) at one a clock, out
/// `latency` clocks later (`assert_one_item_per_clock`, no configuration writes).
pub fn random_items_one_per_clock<C, F>(gen: impl Fn(C) -> F, seed_no: u64, latency: u64)
where
    C: StreamCodec + UnitConfig + Copy,
    F: FnMut(&mut ChaCha8Rng) -> C::In,
{
    for (variant, cfg) in configs::<C>() {
        let items = random_items(seed(seed_no), 100_000, gen(cfg));
        assert_one_item_per_clock(variant, cfg, &[], &items, latency);
    }
}

/// Drives `items` at full speed (after `writes` on the configuration port) and asserts the
/// throughput contract: every item taken, the run lasts exactly one clock per item plus
/// `latency`, and the outputs leave back to back. Returns the outputs for any comparison the
/// caller adds.
pub fn assert_one_item_per_clock<C: StreamCodec>(
    variant: &'static Variant,
    codec: C,
    writes: &[(u32, Vec<u32>)],
    items: &[C::In],
    latency: u64,
) -> Driven<C::Out> {
    let mut dut = RtlStream::new(variant, codec, 1).unwrap();
    for (addr, data) in writes {
        dut.write_config(*addr, data).unwrap();
    }
    let n = items.len() as u64;
    let driven = dut.drive(items, &Traffic::full_speed(), n, 10 * n).unwrap();
    assert_eq!(driven.stats.consumed, n, "{variant}: every item taken");
    assert_eq!(
        driven.stats.cycles,
        n + latency,
        "{variant}: one item per clock plus the pipeline fill"
    );
    let first = driven.outputs.first().unwrap().cycle;
    let last = driven.outputs.last().unwrap().cycle;
    assert_eq!(last - first + 1, n, "{variant}: outputs leave back to back");
    eprintln!(
        "{variant}: {n} items in {} cycles ({:.4} items/clock)",
        driven.stats.cycles,
        n as f64 / driven.stats.cycles as f64
    );
    driven
}

/// `must_match` on a check with one reset: asserts the reset happened and dropped no more than
/// `in_flight` items (those the pipeline held at the time).
pub fn must_match_across_a_reset<C, G>(
    variant: &'static Variant,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
    in_flight: usize,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let r = must_match(variant, codec, gold, gen, check);
    assert_eq!(r.resets, 1, "{variant}: one reset");
    assert!(
        r.compared as usize >= check.items - in_flight,
        "{variant}: a reset drops at most the items in flight"
    );
    r
}

/// The RTL builds of `C`'s top with the model's configuration of each, in `.variants` order.
pub fn configs<C: cube5_model::unit::UnitConfig>() -> Vec<(&'static Variant, C)> {
    cube5_tb::variants_of(C::TOP)
        .into_iter()
        .map(|v| (v, v.config().unwrap_or_else(|e| panic!("{v}: {e}"))))
        .collect()
}

/// The gate-level builds of `C`'s top (lines flagged `gate`) with the model's configuration.
pub fn gate_configs<C: cube5_model::unit::UnitConfig>() -> Vec<(&'static Variant, C)> {
    cube5_tb::gate_variants_of(C::TOP)
        .into_iter()
        .map(|v| (v, v.config().unwrap_or_else(|e| panic!("{v}: {e}"))))
        .collect()
}

/// Opens the first variant of `C`'s top with the configuration of another variant whose port
/// widths differ: the test bench must refuse it with a set-up error that names the port.
pub fn assert_foreign_codec_is_refused<C>()
where
    C: cube5_model::unit::UnitConfig + StreamCodec + Copy,
{
    let all = configs::<C>();
    let (variant, own) = all[0];
    let foreign = all
        .iter()
        .map(|&(_, c)| c)
        .find(|c| c.in_width() != own.in_width() || c.out_width() != own.out_width())
        .expect("two variants with different port widths");
    match RtlStream::new(variant, foreign, 1) {
        Err(cube5_tb::TbError::Setup { what, .. }) => {
            assert!(
                what.contains("in_data_i") || what.contains("out_data_o"),
                "the refusal names the port: {what}"
            );
        }
        Err(e) => panic!("{variant}: expected a width refusal, got {e}"),
        Ok(_) => panic!("{variant}: a codec of other widths was accepted"),
    }
}

/// The foreign codec refused (`assert_foreign_codec_is_refused`), then one configuration write
/// (`write`: address, words) on the first variant of `C`'s top: accepted when the top has a
/// configuration port (`has_port`), refused when it has none.
pub fn assert_codec_and_config_port<C>(write: (u32, &[u32]), has_port: bool)
where
    C: cube5_model::unit::UnitConfig + StreamCodec + Copy,
{
    assert_foreign_codec_is_refused::<C>();
    let (variant, cfg) = configs::<C>()[0];
    let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
    assert_eq!(
        dut.write_config(write.0, write.1).is_ok(),
        has_port,
        "{variant}: a configuration port is expected: {has_port}"
    );
}

/// On every build of `C`'s top: `MILLION` random items of `gen` with idle, back-pressure and one
/// reset in batch `reset_batch` (seed `seed_base + ` the variant's index), on a fresh model from
/// `new`; the reset drops at most `in_flight` items (`must_match_across_a_reset`).
pub fn million_across_a_reset<C, G, F>(
    new: impl Fn(C) -> cube5_model::Result<G>,
    gen: impl Fn(C) -> F,
    seed_base: u64,
    reset_batch: usize,
    in_flight: usize,
) where
    C: Scored + UnitConfig + Copy,
    G: StreamUnit<In = C::In, Out = C::Out>,
    F: FnMut(&mut ChaCha8Rng) -> C::In,
{
    for (i, (variant, cfg)) in configs::<C>().into_iter().enumerate() {
        must_match_across_a_reset(
            variant,
            cfg,
            &mut new(cfg).unwrap(),
            &mut gen(cfg),
            &StreamCheck::long(seed(seed_base + i as u64), MILLION, reset_batch),
            in_flight,
        );
    }
}

/// On every build of `C`'s top: the `directed` items through `check` (given their number), on a
/// fresh model from `new`.
pub fn directed_on_every_config<C, G>(
    new: impl Fn(C) -> cube5_model::Result<G>,
    directed: impl Fn(C) -> Vec<C::In>,
    check: impl Fn(usize) -> StreamCheck,
) where
    C: Scored + UnitConfig + Copy,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    for (variant, cfg) in configs::<C>() {
        let items = directed(cfg);
        let check = check(items.len());
        must_match_items(variant, cfg, &mut new(cfg).unwrap(), items, &check);
    }
}

/// The mismatch a run must end in (a mutated model, a corrupted output); panics with `why` if it
/// passed or failed in another way.
pub fn expect_mismatch<T: Debug>(
    run: Result<T, cube5_tb::TbError>,
    why: &str,
) -> cube5_tb::Mismatch {
    match run {
        Err(cube5_tb::TbError::Mismatch(m)) => *m,
        Err(e) => panic!("{why}: the run failed otherwise: {e}"),
        Ok(r) => panic!("{why}: the run passed ({r:?})"),
    }
}

/// The variant whose configuration is `cfg` (a test that needs one particular configuration says
/// which by its value, never by the variant's name); panics if no `.variants` line has it.
pub fn variant_with<C>(cfg: C) -> &'static Variant
where
    C: cube5_model::unit::UnitConfig + PartialEq + Debug,
{
    configs::<C>()
        .into_iter()
        .find(|(_, c)| *c == cfg)
        .map(|(v, _)| v)
        .unwrap_or_else(|| panic!("no variant of {} has the configuration {cfg:?}", C::TOP))
}

/// Tops with an AXI4 read port (tb/axi_mem.h): `run(None)`, and on a mismatch the same run again
/// with a VCD window of the 64 cycles before the first difference (`CUBE5_NO_WAVES=1`: not).
pub fn with_waves<R>(
    variant: &'static Variant,
    seed: u64,
    run: impl Fn(Option<(std::path::PathBuf, (u64, u64))>) -> Result<R, cube5_tb::TbError>,
) -> Result<R, cube5_tb::TbError> {
    match run(None) {
        Err(cube5_tb::TbError::Mismatch(mut m)) if std::env::var_os("CUBE5_NO_WAVES").is_none() => {
            let dir = std::path::PathBuf::from(
                std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into()),
            )
            .join("cube5-waves");
            let _ = std::fs::create_dir_all(&dir);
            let path = dir.join(format!("{variant}-seed{seed}.vcd"));
            let window = (m.cycle.saturating_sub(64), m.cycle + 8);
            let _ = run(Some((path.clone(), window)));
            m.waveform = path.exists().then_some(path);
            Err(cube5_tb::TbError::Mismatch(m))
        }
        other => other,
    }
}

/// After a run of an AXI top: the output's stall rule and the subordinate's protocol checker.
pub fn axi_protocol_clean<C: StreamCodec>(
    dut: &RtlStream<C>,
    stats: &cube5_tb::ffi::bridge::RunResult,
    variant: &'static Variant,
    seed: u64,
) -> Result<(), cube5_tb::TbError> {
    let protocol = |cycle: u64, what: String| cube5_tb::TbError::Protocol {
        variant: variant.name.to_string(),
        seed,
        cycle,
        what,
    };
    if stats.protocol_errors > 0 {
        return Err(protocol(
            stats.first_protocol_error_cycle,
            "a stalled output dropped valid or changed".into(),
        ));
    }
    let counters = dut.axi_counters();
    if counters.protocol_errors > 0 {
        return Err(protocol(
            counters.first_error_cycle,
            format!(
                "AXI checker: {} ({} violations)",
                dut.axi_first_error(),
                counters.protocol_errors
            ),
        ));
    }
    Ok(())
}

/// Address-channel handshakes (`dut.axi_take_ar()` or `axi_take_aw()`; `ch` is "AR" or "AW")
/// against the model's bursts, in order (address, beats, `size`, INCR, ID 0); `context` names burst
/// `k` for the report. Returns the count.
pub fn compare_bursts(
    ars: &[cube5_tb::rtl::ArHandshake],
    ch: &str,
    bursts: &[cube5_model::units::cube5_axi_rd::Burst],
    size: u32,
    variant: &'static Variant,
    seed: u64,
    context: impl Fn(usize) -> String,
) -> Result<usize, cube5_tb::TbError> {
    for (k, ar) in ars.iter().enumerate() {
        let model = bursts.get(k);
        let got = cube5_model::units::cube5_axi_rd::Burst {
            addr: ar.addr,
            beats: ar.len + 1,
        };
        if model != Some(&got) || ar.size != size || ar.burst != 1 || ar.id != 0 {
            return Err(cube5_tb::TbError::from(cube5_tb::Mismatch {
                variant: variant.name.to_string(),
                seed,
                item: k as u64,
                cycle: ar.cycle,
                input: context(k),
                rtl: format!("{got:?} size {} burst {} id {}", ar.size, ar.burst, ar.id),
                model: model.map_or("(no burst expected)".into(), |b| {
                    format!("{b:?} size {size} burst 1 id 0")
                }),
                what: format!(
                    "{ch} burst differs (address, beats; {ch}SIZE, {ch}BURST = INCR, {ch}ID = 0)"
                ),
                ..Default::default()
            }));
        }
    }
    Ok(ars.len())
}

/// After an AXI top's run, its outputs against the model's `want`, item by item (`noun` names an
/// item, `describe` its inputs); with `exact` (no reset cut the run) also that every item came out
/// within `limit` cycles and that `n_ars` of the model's `bursts` were issued.
#[allow(clippy::too_many_arguments)]
pub fn compare_axi_outputs<C: StreamCodec>(
    dut: &RtlStream<C>,
    driven: &Driven<C::Out>,
    want: &[C::Out],
    (n_ars, bursts): (usize, usize),
    exact: bool,
    limit: u64,
    (variant, seed): (&'static Variant, u64),
    noun: &str,
    describe: impl Fn(usize) -> String,
) -> Result<(), cube5_tb::TbError>
where
    C::Out: PartialEq + Debug,
{
    for (k, taken) in driven.outputs.iter().enumerate() {
        if want.get(k) != Some(&taken.value) {
            return Err(cube5_tb::TbError::from(cube5_tb::Mismatch {
                variant: variant.name.to_string(),
                seed,
                item: k as u64,
                cycle: taken.cycle,
                input: describe(k),
                rtl: format!("{:?}", taken.value),
                model: want
                    .get(k)
                    .map_or(format!("(no {noun} expected)"), |b| format!("{b:?}")),
                what: format!("output {noun} differs"),
                ..Default::default()
            }));
        }
    }
    if exact {
        let missing = |what: String| cube5_tb::TbError::Deadlock {
            variant: variant.name.to_string(),
            seed,
            cycle: dut.cycle(),
            what,
        };
        if driven.outputs.len() != want.len() {
            return Err(missing(format!(
                "{} of {} {noun}s out within {limit} cycles",
                driven.outputs.len(),
                want.len()
            )));
        }
        if n_ars != bursts {
            return Err(missing(format!("{n_ars} of {bursts} bursts issued")));
        }
    }
    Ok(())
}

/// The test bench's AXI subordinate for a `data_bytes`-wide, `addr_bits` bus over `mem`: latency
/// `fixed + U(0..random)`, ARREADY/RVALID gaps in per mille, bandwidth `bw` bytes per cycle as
/// `(num, den)` (`num = 0`: unlimited), `mem`'s SLVERR window.
pub fn axi_mem_setup(
    (data_bytes, addr_bits): (u32, u32),
    mem: &cube5_model::units::cube5_axi_rd::AxiMemImage,
    lat: (u32, u32),
    gaps: (u32, u32),
    bw: (u32, u32),
    seed: u64,
) -> cube5_tb::rtl::AxiMemSetup {
    cube5_tb::rtl::AxiMemSetup {
        data_bytes,
        addr_bits,
        latency_fixed: lat.0,
        latency_random: lat.1,
        ar_gap_permille: gaps.0,
        r_gap_permille: gaps.1,
        bw_num: bw.0,
        bw_den: bw.1.max(1),
        max_bursts: 64,
        seed,
        slverr_lo: mem.slverr_lo,
        slverr_hi: mem.slverr_hi,
        aw_gap_permille: 0,
        w_gap_permille: 0,
        b_gap_permille: 0,
        declared_outstanding: 0,
    }
}

/// The AXI tests' memory: a 64 KB image of random bytes at 0 for a 16-bit address space (it is
/// the whole space, so commands that wrap reach memory), else at 0x10000; an SLVERR window of 64
/// bytes inside.
pub fn axi_random_image(
    addr_w: u32,
    rng: &mut impl rand::Rng,
) -> cube5_model::units::cube5_axi_rd::AxiMemImage {
    let base = if addr_w <= 16 { 0 } else { 0x1_0000 };
    let bytes: Vec<u8> = (0..0x1_0000).map(|_| rng.random()).collect();
    let lo = base + rng.random_range(0..0x1_0000u64 / 64) * 64;
    cube5_model::units::cube5_axi_rd::AxiMemImage {
        base,
        bytes,
        slverr_lo: lo,
        slverr_hi: lo + 64,
    }
}

/// A random volume of `dims` in blocks of `block`: ~30 % of the blocks all zero, the rest random
/// voxels of `voxel_w` bits in `1..`; its block LUT (`BlockLut::from_volume` at threshold 0, so
/// the zero blocks are empty) with ~10 % of the blocks masked. For the accelerator's data-path
/// tests (cube5_section_buf, fetch_to_beams).
pub fn random_blocked_volume(
    dims: [usize; 3],
    block: u32,
    voxel_w: u32,
    rng: &mut ChaCha8Rng,
) -> (
    cube5_model::volume::Volume,
    cube5_model::units::cube5_skewmem::BlockLut,
) {
    use rand::Rng;
    let b = block as usize;
    let nb = dims.map(|n| n.div_ceil(b));
    let zero: Vec<bool> = (0..nb.iter().product::<usize>())
        .map(|_| rng.random_bool(0.3))
        .collect();
    let max = (1u32 << voxel_w) - 1;
    let mut data = Vec::with_capacity(dims.iter().product());
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let blk = x / b + nb[0] * (y / b + nb[1] * (z / b));
                data.push(if zero[blk] {
                    0
                } else {
                    rng.random_range(1..=max) as u16
                });
            }
        }
    }
    let vol = cube5_model::volume::Volume::new(dims, [1.0; 3], voxel_w, data).unwrap();
    let mut lut = cube5_model::units::cube5_skewmem::BlockLut::from_volume(&vol, b, 0).unwrap();
    for e in &mut lut.entries {
        e.masked = rng.random_bool(0.1);
    }
    (vol, lut)
}

/// `cube5_section_buf`'s input for `cmds`: each section command, then the fetch's items of its
/// sweep, up to the one marked `last` (the items of all the sweeps, in order).
pub fn section_buf_input(
    cmds: &[cube5_model::units::cube5_section_buf::SectionCmd],
    items: Vec<cube5_model::units::cube5_vol_fetch::FetchItem>,
) -> Vec<cube5_model::units::cube5_section_buf::SbufIn> {
    use cube5_model::units::cube5_section_buf::SbufIn;
    let mut input = Vec::new();
    let mut it = items.into_iter();
    for c in cmds {
        input.push(SbufIn::Section(*c));
        for item in it.by_ref() {
            let last = item.last;
            input.push(SbufIn::Item(item));
            if last {
                break;
            }
        }
    }
    input
}
