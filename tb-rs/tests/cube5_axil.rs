//! Co-simulation of the AXI4-Lite register block (cube5_axil: cube5_axil_regs holding one
//! generated map) against the cycle-level register-file model (docs/accel-regs.md, "The register
//! block"), with the AXI4-Lite manager of tb/axil_mgr.h in the clock loop: random delays on AW, W
//! and AR, back-pressure on B and R, a protocol checker on all five channels, the hardware side's
//! RO values and W1C sets changing every cycle. Every response, the first-cycle `hw_q_o` and
//! strobes, and the interrupt level in every cycle are compared (cube5_tb::axil).

mod support;

use cube5_model::accel_host::{AccelHost, FrameRegs, HostError};
use cube5_model::regs::cube5_accel::TABLE_CLASS;
use cube5_model::regs::cube5_axil_regs::MAP_ACCEL;
use cube5_model::units::cube5_axil::{AxilConfig, AxilTxn, BusWrite, RESP_OKAY, RESP_SLVERR};
use cube5_tb::axil::{random_txn, stall_pattern, AxilBench, TxnMix};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{configs, gate_configs, must, seed, MILLION};

/// `n` random transactions in batches, each batch under its own back-pressure; every
/// `reset_every` batches the batch is cut short in mid-stream and the block reset.
fn random_run(
    bench: &mut AxilBench,
    seed: u64,
    n: usize,
    mix: TxnMix,
    p_stall: f64,
    reset_every: Option<usize>,
) -> u64 {
    let cfg = *bench.config();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let batch = 20_000;
    let mut done = 0;
    let mut answered = 0;
    let mut k = 0;
    while done < n {
        let m = batch.min(n - done);
        let txns: Vec<AxilTxn> = (0..m).map(|_| random_txn(&mut rng, &cfg, mix)).collect();
        let stall = stall_pattern(&mut rng, p_stall);
        k += 1;
        let cut = reset_every.is_some_and(|e| k % e == 0);
        if cut {
            let at = rng.random_range(10..(m as u64).max(11));
            let r = must(bench.run(&txns, &stall, Some(at)));
            assert!(!r.complete, "cut at {at} cycles still answered everything");
            answered += r.responses;
            bench.reset();
        } else {
            let r = must(bench.run(&txns, &stall, None));
            assert!(r.complete);
            answered += r.responses;
        }
        done += m;
    }
    answered
}

/// A million random transactions per configuration (about 4 s each): delays on AW, W and AR,
/// back-pressure on B and R, and every tenth batch cut in mid-stream by a reset.
#[test]
fn a_million_random_transactions_with_delays_back_pressure_and_resets_match_the_model() {
    let s = seed(0x111);
    for (v, _cfg) in configs::<AxilConfig>() {
        let mut bench = must(AxilBench::open(v, s));
        let n = random_run(&mut bench, s, MILLION, TxnMix::RANDOM, 0.3, Some(10));
        assert!(n > 900_000, "{v}: {n} responses");
    }
}

/// Directed extremes: every offset of the address space the map spans and a little past it,
/// written with all ones, all zeros, each single byte strobe and no strobe, read back after each;
/// the highest address of the bus; the longest delays the manager can give.
#[test]
fn directed_extremes_match_the_model() {
    let s = seed(0xd1);
    for (v, cfg) in configs::<AxilConfig>() {
        let mut bench = must(AxilBench::open(v, s));
        let words = cfg.map().words();
        let top = (1u32 << cfg.addr_w) - 4;
        let mut txns = Vec::new();
        let t = |read, addr, data, strb, delay| AxilTxn {
            read,
            addr,
            data,
            strb,
            delay,
            w_delay: delay,
        };
        for o in (0..words + 3).chain([top / 4]) {
            for (data, strb) in [
                (u32::MAX, 0xf),
                (0, 0xf),
                (u32::MAX, 0x1),
                (u32::MAX, 0x2),
                (u32::MAX, 0x4),
                (u32::MAX, 0x8),
                (0x5a5a_5a5a, 0x0),
                (0xa5a5_a5a5, 0xf),
            ] {
                txns.push(t(false, o * 4, data, strb, 0));
                txns.push(t(true, o * 4, 0, 0, 0));
            }
        }
        txns.push(t(false, top + 3, u32::MAX, 0xf, 255));
        txns.push(t(true, top + 1, 0, 0, 255));
        let r = must(bench.run(&txns, &[], None));
        assert!(r.complete);
        // Back-to-back under constant back-pressure on both response channels.
        let stall = vec![1u8, 1, 0];
        must(bench.run(&txns, &stall, None));
    }
}

/// Unmapped offsets and wrong-direction accesses answer SLVERR; registers answer OKAY (the
/// scoreboard compares every response; this checks the test reaches both codes).
#[test]
fn error_responses_are_reached() {
    for (v, cfg) in configs::<AxilConfig>() {
        let map = cfg.map();
        let file = cube5_model::units::cube5_axil::RegFile::new(map);
        let past = map.words() + 1;
        assert_eq!(file.write_resp(past), RESP_SLVERR, "{v}");
        assert_eq!(file.read(past, 0).resp, RESP_SLVERR, "{v}");
        assert!(map
            .registers
            .iter()
            .any(|r| file.read(r.offset, 0).resp == RESP_OKAY));
        let mut bench = must(AxilBench::open(v, seed(3)));
        let txns = [
            AxilTxn {
                read: true,
                addr: past * 4,
                data: 0,
                strb: 0,
                delay: 0,
                w_delay: 0,
            },
            AxilTxn {
                read: false,
                addr: past * 4,
                data: 1,
                strb: 0xf,
                delay: 0,
                w_delay: 0,
            },
        ];
        must(bench.run(&txns, &[], None));
    }
}

/// One read and one write per cycle when nothing waits: N writes and N reads take N cycles plus
/// the two-cycle latency.
#[test]
fn full_rate_one_read_and_one_write_per_cycle() {
    let s = seed(0x7a);
    for (v, cfg) in configs::<AxilConfig>() {
        let mut bench = must(AxilBench::open(v, s));
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let n = 10_000;
        let mut txns = Vec::with_capacity(2 * n);
        for _ in 0..n {
            let mut w = random_txn(&mut rng, &cfg, TxnMix::FULL_SPEED);
            w.read = false;
            let mut r = random_txn(&mut rng, &cfg, TxnMix::FULL_SPEED);
            r.read = true;
            txns.push(w);
            txns.push(r);
        }
        let run = must(bench.run(&txns, &[], None));
        assert!(run.complete);
        eprintln!(
            "{v}: {} writes and {} reads in {} cycles ({:.4} transactions per cycle per channel)",
            n,
            n,
            run.cycles,
            n as f64 / run.cycles as f64
        );
        assert!(
            run.cycles <= n as u64 + 3,
            "{v}: {} cycles for {n} writes and {n} reads",
            run.cycles
        );
    }
}

/// The scoreboard can fail: after the model alone is told of a write the RTL never saw, the next
/// read of that register is a mismatch naming the transaction.
#[test]
fn a_model_that_disagrees_is_caught() {
    for (v, cfg) in configs::<AxilConfig>() {
        let mut bench = must(AxilBench::open(v, seed(5)));
        let map = cfg.map();
        let r = map
            .registers
            .iter()
            .find(|r| r.access == cube5_model::regmap::Access::Rw && r.reset.is_some())
            .unwrap_or_else(|| panic!("{v}: the map has an RW register with a reset value"));
        let reset = r.reset.unwrap_or(0) as u32;
        let bit = map.mask[r.offset as usize].trailing_zeros();
        bench.model_mut().edge(
            Some(BusWrite {
                offset: r.offset,
                data: reset ^ 1 << bit,
                strb: 0xf,
            }),
            &|_| 0,
        );
        let txn = AxilTxn {
            read: true,
            addr: r.offset * 4,
            data: 0,
            strb: 0,
            delay: 0,
            w_delay: 0,
        };
        let e = bench
            .run(&[txn], &[], None)
            .expect_err("the disagreement is found");
        let m = e
            .mismatch()
            .unwrap_or_else(|| panic!("{v}: not a mismatch: {e}"));
        assert_eq!(m.item, 0, "{v}: {m}");
        assert!(m.to_string().contains("seed"), "{m}");
    }
}

/// The host driver (cube5_model::accel_host) on the accelerator's map in the RTL: frame
/// registers, base addresses and a table load written and read back, the done interrupt waited
/// for and cleared (the co-simulation top's hardware side sets IrqStatus bits at random), the
/// counters read; every access is checked against the model on the way.
#[test]
fn the_host_driver_runs_on_the_rtl() {
    for (v, cfg) in configs::<AxilConfig>() {
        if cfg.map != MAP_ACCEL {
            continue;
        }
        let bench = must(AxilBench::open(v, seed(0x405)));
        let mut host = AccelHost::new(bench, 0);
        let f = FrameRegs::EXAMPLE;
        host.write_frame(&f).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(host.read_frame().unwrap_or_else(|e| panic!("{e}")), f);
        host.set_bases(0x1_2345_6780, 0xffff_ffff_0000_0040)
            .unwrap_or_else(|e| panic!("{e}"));
        host.load_table(TABLE_CLASS, 3, &[7, 8, 9])
            .unwrap_or_else(|e| panic!("{e}"));
        host.enable_irq(true, false)
            .unwrap_or_else(|e| panic!("{e}"));
        host.start().unwrap_or_else(|e| panic!("{e}"));
        // The stimulus sets IrqStatus.done sooner or later; an error bit may come first.
        match host.wait_done(10_000) {
            Ok(_) | Err(HostError::Frame(_)) => {}
            Err(e) => panic!("{v}: {e}"),
        }
        host.counters().unwrap_or_else(|e| panic!("{e}"));
        let bench = host.into_bus();
        assert!(bench.cycle() > 40, "{v}");
    }
}

#[test]
fn gate_level_smoke() {
    let s = seed(0x9a7e);
    for (v, _cfg) in gate_configs::<AxilConfig>() {
        let mut bench = must(AxilBench::open(v, s));
        let n = random_run(&mut bench, s, 20_000, TxnMix::RANDOM, 0.3, Some(1));
        assert!(n > 1000, "{v}: {n}");
    }
}
