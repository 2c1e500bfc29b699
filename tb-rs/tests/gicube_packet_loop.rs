//! Co-simulation of gicube_packet_loop against the golden model: the SV struct
//! `gicube_pkg::ray_packet_t` and the Rust `RayPacket` lay out the 32-byte ray identically
//! (docs/numerics/gicube_packet.md).

mod support;

use cube5_model::unit::StreamCodec;
use cube5_model::units::gicube_packet_loop::{
    directed_packets, random_packet, PacketLoop, PacketLoopConfig, PacketLoopOut, RayPacket,
    PACKET_WORDS,
};
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use support::{
    assert_one_item_per_clock, configs, directed_on_every_config, expect_mismatch,
    gate_smoke_then_directed, million_across_a_reset, random_items, seed, variant_with,
};

fn random_item(rng: &mut ChaCha8Rng) -> RayPacket {
    random_packet(rng)
}

#[test]
fn million_random_packets_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(PacketLoop::new, |_| random_item, 300, 3, 10);
}

#[test]
fn directed_extremes_every_field_wraps() {
    directed_on_every_config(
        PacketLoop::new,
        |_| directed_packets(),
        |n| StreamCheck::new(seed(301), 4 * n).with_traffic(0.3, 0.3),
    );
}

#[test]
fn one_packet_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<PacketLoopConfig>() {
        let items = random_items(seed(302), 100_000, random_item);
        assert_one_item_per_clock(variant, cfg, &[], &items, cfg.latency());
    }
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(
        PacketLoop::new,
        |_| random_item,
        |_| directed_packets(),
        303,
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
        let err = expect_mismatch(
            check_stream(
                variant_with(PacketLoopConfig::S1),
                MutantCodec(mutant),
                &mut PacketLoop::new(PacketLoopConfig::S1).unwrap(),
                &mut gen,
                &check,
            ),
            "a layout that differs from the SV struct must be caught",
        );
        assert!(
            err.item < 4,
            "{mutant:?}: caught at once, not at item {}",
            err.item
        );
        // The plain round trip alone cannot see it: the repack half still agrees.
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut dut =
            RtlStream::new(variant_with(PacketLoopConfig::S1), MutantCodec(mutant), 1).unwrap();
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
