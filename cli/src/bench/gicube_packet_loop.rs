//! Benchmark of the GI-Cube ray packet round trip (`gicube_packet_loop`): speed of the RTL and the
//! model, and the packet's quantization error.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_packet_loop::{
    random_packet, PacketLoop, PacketLoopConfig, RayPacket, RayReal,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = PacketLoopConfig::TOP;

pub fn run(n_items: usize) -> Result<()> {
    println!("The round-trip fixture (unpack into the SV struct, repack, per-field probe).\n");
    speed_table(
        |cfg: PacketLoopConfig| {
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let items: Vec<RayPacket> = (0..n_items).map(|_| random_packet(&mut rng)).collect();
            Ok((PacketLoop::new(cfg)?, items, vec![]))
        },
        Compare::No,
    )?;

    println!(
        "Quantization of real ray fields into the packet (round half up, `RayPacket::from_real`)"
    );
    println!(
        "against the f64 values, {n_items} random rays, in LSBs of each field; the bound is 0.5:\n"
    );
    println!("| field | format | max abs error (LSB) | RMS error (LSB) |");
    println!("|-------|--------|--------------------:|----------------:|");
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mut acc = [ErrorStats::default(); 4];
    for _ in 0..n_items {
        let r = RayReal::random(&mut rng);
        let back = RayPacket::from_real(&r)?.to_real();
        let mut add = |k: usize, got: f64, want: f64, frac: u32| {
            acc[k].add((got - want).abs() * f64::from(1u32 << frac));
        };
        for a in 0..3 {
            add(0, back.start[a], r.start[a], 8);
            add(1, back.dir[a], r.dir[a], 14);
            add(2, back.color[a], r.color[a], 12);
        }
        add(3, back.interaction, r.interaction, 16);
    }
    for (s, (field, format)) in acc.iter().zip([
        ("start x, y, z", "U(12.8)"),
        ("dir x, y, z", "S(2.14)"),
        ("red, green, blue", "U(0.12)"),
        ("interaction", "U(0.16)"),
    ]) {
        println!("| {field} | {format} | {:.4} | {:.4} |", s.max_abs, s.rms());
    }
    println!();
    Ok(())
}
