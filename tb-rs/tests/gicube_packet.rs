//! Co-simulation of gicube_packet_loop against the golden model: the SV struct
//! `gicube_pkg::ray_packet_t` and the Rust `RayPacket` lay out the 32-byte ray identically
//! (docs/numerics/gicube_packet.md).

mod support;

use cube5_model::gicube::packet::{
    directed_packets, random_packet, PacketLoop, PacketLoopConfig, PacketLoopOut, RayPacket,
    PACKET_WORDS,
};
use cube5_model::unit::StreamCodec;
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use support::{must_match, seed, MILLION};

const CONFIGS: [(&str, PacketLoopConfig); 2] = [
    ("gicube_packet_loop_s1", PacketLoopConfig::S1),
    ("gicube_packet_loop_s2", PacketLoopConfig::S2),
];

fn random_item(rng: &mut ChaCha8Rng) -> RayPacket {
    random_packet(rng)
}

#[test]
fn million_random_packets_per_config_with_idle_backpressure_and_reset() {
    for (i, (variant, cfg)) in CONFIGS.iter().enumerate() {
        let check = StreamCheck::new(seed(300 + i as u64), MILLION)
            .with_traffic(0.2, 0.3)
            .with_reset_in_batch(3);
        let r = must_match(
            variant,
            *cfg,
            &mut PacketLoop::new(*cfg).unwrap(),
            &mut random_item,
            &check,
        );
        assert_eq!(r.resets, 1);
        assert!(r.compared as usize >= MILLION - 10);
    }
}

#[test]
fn directed_extremes_every_field_wraps() {
    for (variant, cfg) in CONFIGS {
        let items = directed_packets();
        let n = items.len();
        let mut it = items.into_iter().cycle();
        let check = StreamCheck::new(seed(301), 4 * n).with_traffic(0.3, 0.3);
        must_match(
            variant,
            cfg,
            &mut PacketLoop::new(cfg).unwrap(),
            &mut |_| it.next().unwrap(),
            &check,
        );
    }
}

#[test]
fn one_packet_per_cycle_when_never_stalled() {
    for (variant, cfg) in CONFIGS {
        let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed(302));
        let items: Vec<RayPacket> = (0..100_000).map(|_| random_packet(&mut rng)).collect();
        let n = items.len() as u64;
        let driven = dut
            .drive(&items, &Traffic::full_speed(), n, 10 * n)
            .unwrap();
        assert_eq!(driven.stats.consumed, n);
        assert_eq!(
            driven.stats.cycles,
            n + cfg.latency(),
            "{variant}: one packet per clock plus the pipeline fill"
        );
        let first = driven.outputs.first().unwrap().cycle;
        let last = driven.outputs.last().unwrap().cycle;
        assert_eq!(last - first + 1, n, "{variant}: outputs leave back to back");
    }
}

#[test]
fn gate_level_netlist_smoke() {
    let cfg = PacketLoopConfig::S1;
    let check = StreamCheck::new(seed(303), 30_000)
        .with_traffic(0.2, 0.2)
        .with_batch(10_000)
        .with_reset_in_batch(1);
    must_match(
        "gicube_packet_loop_s1_gate",
        cfg,
        &mut PacketLoop::new(cfg).unwrap(),
        &mut random_item,
        &check,
    );
    let items = directed_packets();
    let n = items.len();
    let mut it = items.into_iter().cycle();
    must_match(
        "gicube_packet_loop_s1_gate",
        cfg,
        &mut PacketLoop::new(cfg).unwrap(),
        &mut |_| it.next().unwrap(),
        &StreamCheck::new(seed(304), n).with_traffic(0.3, 0.3),
    );
}

/// A Rust layout that differs from the contract: `dir_x` and `dir_y` swapped (equal widths), or the
/// `u`/`v` boundary moved one bit up (`u` 13 bits, `v` 11 bits).
#[derive(Debug, Clone, Copy)]
enum Mutant {
    SwapDirXY,
    MoveUvBoundary,
}

#[derive(Debug, Clone, Copy)]
struct MutantCodec(Mutant);

impl MutantCodec {
    fn pack_words(self, p: &RayPacket) -> [u32; PACKET_WORDS] {
        match self.0 {
            Mutant::SwapDirXY => {
                let mut q = *p;
                q.dir.swap(0, 1);
                q.to_bits().unwrap()
            }
            Mutant::MoveUvBoundary => {
                let mut w = p.to_bits().unwrap();
                let uv = u32::from(p.u) | u32::from(p.v) << 13; // u 13 bits, v 11 bits
                w[0] = (w[0] & !0xff_ffff) | (uv & 0xff_ffff);
                w
            }
        }
    }

    fn unpack_words(self, w: &[u32; PACKET_WORDS]) -> RayPacket {
        let mut p = RayPacket::from_bits(w);
        match self.0 {
            Mutant::SwapDirXY => p.dir.swap(0, 1),
            Mutant::MoveUvBoundary => {
                p.u = (w[0] & 0x1fff) as u16 & 0xfff;
                p.v = ((w[0] >> 13) & 0x7ff) as u16;
            }
        }
        p
    }
}

impl StreamCodec for MutantCodec {
    type In = RayPacket;
    type Out = PacketLoopOut;

    fn in_width(&self) -> u32 {
        PacketLoopConfig::S1.in_width()
    }
    fn out_width(&self) -> u32 {
        PacketLoopConfig::S1.out_width()
    }
    fn pack_in(&self, item: &RayPacket) -> Vec<u32> {
        self.pack_words(item).to_vec()
    }
    fn unpack_out(&self, words: &[u32]) -> PacketLoopOut {
        let half = |k: usize| -> [u32; PACKET_WORDS] {
            std::array::from_fn(|i| words[k * PACKET_WORDS + i])
        };
        PacketLoopOut {
            repack: self.unpack_words(&half(0)),
            probe: self.unpack_words(&half(1)),
        }
    }
}

#[test]
fn a_rust_layout_with_swapped_or_moved_fields_is_caught_by_the_probe() {
    for mutant in [Mutant::SwapDirXY, Mutant::MoveUvBoundary] {
        // Packets with u < 2048 and v < 2048 fit both layouts.
        let mut gen = |rng: &mut ChaCha8Rng| {
            let mut p = random_packet(rng);
            p.u &= 0x7ff;
            p.v &= 0x7ff;
            p
        };
        let mut check = StreamCheck::new(seed(305), 2_000).with_traffic(0.1, 0.1);
        check.waveform_on_mismatch = false;
        let err = check_stream(
            "gicube_packet_loop_s1",
            MutantCodec(mutant),
            &mut PacketLoop::new(PacketLoopConfig::S1).unwrap(),
            &mut gen,
            &check,
        )
        .expect_err("a layout that differs from the SV struct must be caught");
        assert!(
            err.item < 4,
            "{mutant:?}: caught at once, not at item {}",
            err.item
        );
        // The plain round trip alone cannot see it: the repack half still agrees.
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut dut = RtlStream::new("gicube_packet_loop_s1", MutantCodec(mutant), 1).unwrap();
        let items: Vec<RayPacket> = (0..1000).map(|_| gen(&mut rng)).collect();
        let out = dut
            .drive(&items, &Traffic::full_speed(), 1000, 10_000)
            .unwrap();
        for (p, o) in items.iter().zip(&out.outputs) {
            assert_eq!(
                o.value.repack, *p,
                "{mutant:?}: the repack half round-trips"
            );
        }
        assert!(
            items
                .iter()
                .zip(&out.outputs)
                .any(|(p, o)| o.value.probe != p.probed()),
            "{mutant:?}: the probe half differs"
        );
    }
}
