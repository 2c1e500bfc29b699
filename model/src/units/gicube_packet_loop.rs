//! The GI-Cube ray packet (patent [349]): 32 bytes, written from `docs/numerics/gicube_packet.md`.
//! Also the golden model of the round-trip top `gicube_packet_loop`, which proves that the SV
//! struct `gicube_pkg::ray_packet_t` lays the fields out as this module does.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;

/// Bits in a packet.
pub const PACKET_BITS: u32 = 256;
/// 32-bit words in a packet.
pub const PACKET_WORDS: usize = 8;

/// One field of the layout: name, LSB, width (the table of the contract page, in order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub lsb: u32,
    pub width: u32,
}

const fn f(name: &'static str, lsb: u32, width: u32) -> Field {
    Field { name, lsb, width }
}

/// The layout, LSB first. Every bit of the 256 belongs to exactly one field.
pub const LAYOUT: [Field; 19] = [
    f("u", 0, 12),
    f("v", 12, 12),
    f("start_x", 24, 20),
    f("start_y", 44, 20),
    f("start_z", 64, 20),
    f("dir_x", 84, 16),
    f("dir_y", 100, 16),
    f("dir_z", 116, 16),
    f("red", 132, 12),
    f("green", 144, 12),
    f("blue", 156, 12),
    f("opacity", 168, 12),
    f("contribution", 180, 12),
    f("interaction", 192, 16),
    f("lifetime", 208, 8),
    f("generation", 216, 8),
    f("type", 224, 2),
    f("flags", 226, 6),
    f("reserved", 232, 24),
];

/// Fraction bits of the position fields, `U(12.8)`.
pub const POS_FRAC_W: u32 = 8;
/// Width of one position coordinate.
pub const POS_W: u32 = 20;
/// Fraction bits of a direction component, `S(2.14)`.
pub const DIR_FRAC_W: u32 = 14;
/// Fraction bits of colour, opacity and contribution, `U(0.12)`.
pub const COLOR_FRAC_W: u32 = 12;
/// Fraction bits of the interaction value, `U(0.16)`.
pub const INTERACTION_FRAC_W: u32 = 16;

/// Flag bits (the `flags` field).
pub mod flag {
    /// The ray carries irradiance to deposit in the volume ([382]).
    pub const IRRADIANCE: u8 = 1 << 0;
    /// Early ray termination ([357]).
    pub const TERMINATED: u8 = 1 << 1;
    /// Returned to the host because its queue was full ([372]).
    pub const OVERFLOW: u8 = 1 << 2;
}

/// The 2-bit `type` field. The reserved codes are carried unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RayType {
    Rendering = 0,
    Lighting = 1,
    Reserved2 = 2,
    Reserved3 = 3,
}

impl RayType {
    pub fn from_bits(bits: u64) -> Self {
        match bits & 3 {
            0 => Self::Rendering,
            1 => Self::Lighting,
            2 => Self::Reserved2,
            _ => Self::Reserved3,
        }
    }
}

/// One ray, every field as its raw integer (formats in the contract page).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RayPacket {
    /// Image column, `U(12.0)`.
    pub u: u16,
    /// Image row, `U(12.0)`.
    pub v: u16,
    /// Start (current sample) position, `U(12.8)` voxels each.
    pub start: [u32; 3],
    /// Direction, `S(2.14)` each.
    pub dir: [i16; 3],
    /// Red, green, blue, `U(0.12)` each.
    pub color: [u16; 3],
    /// `U(0.12)`.
    pub opacity: u16,
    /// `U(0.12)`.
    pub contribution: u16,
    /// `U(0.16)`.
    pub interaction: u16,
    pub lifetime: u8,
    pub generation: u8,
    pub ray_type: RayType,
    /// Six bits (see [`flag`]).
    pub flags: u8,
    /// 24 bits carried unchanged.
    pub reserved: u32,
}

impl Default for RayPacket {
    fn default() -> Self {
        Self {
            u: 0,
            v: 0,
            start: [0; 3],
            dir: [0; 3],
            color: [0; 3],
            opacity: 0,
            contribution: 0,
            interaction: 0,
            lifetime: 0,
            generation: 0,
            ray_type: RayType::Rendering,
            flags: 0,
            reserved: 0,
        }
    }
}

impl RayPacket {
    /// The raw value of every field, in layout order (the direction as its 16-bit pattern).
    pub fn field_values(&self) -> [u64; 19] {
        let d = |x: i16| u64::from(x as u16);
        [
            u64::from(self.u),
            u64::from(self.v),
            u64::from(self.start[0]),
            u64::from(self.start[1]),
            u64::from(self.start[2]),
            d(self.dir[0]),
            d(self.dir[1]),
            d(self.dir[2]),
            u64::from(self.color[0]),
            u64::from(self.color[1]),
            u64::from(self.color[2]),
            u64::from(self.opacity),
            u64::from(self.contribution),
            u64::from(self.interaction),
            u64::from(self.lifetime),
            u64::from(self.generation),
            self.ray_type as u64,
            u64::from(self.flags),
            u64::from(self.reserved),
        ]
    }

    /// Builds a packet from raw field values in layout order; each must fit its width.
    pub fn from_field_values(v: &[u64; 19]) -> Result<Self> {
        for (field, &value) in LAYOUT.iter().zip(v) {
            if value >> field.width != 0 {
                return Err(ModelError::Config(format!(
                    "ray packet: field `{}` = {value:#x} does not fit in {} bits",
                    field.name, field.width
                )));
            }
        }
        Ok(Self {
            u: v[0] as u16,
            v: v[1] as u16,
            start: [v[2] as u32, v[3] as u32, v[4] as u32],
            dir: [v[5] as u16 as i16, v[6] as u16 as i16, v[7] as u16 as i16],
            color: [v[8] as u16, v[9] as u16, v[10] as u16],
            opacity: v[11] as u16,
            contribution: v[12] as u16,
            interaction: v[13] as u16,
            lifetime: v[14] as u8,
            generation: v[15] as u8,
            ray_type: RayType::from_bits(v[16]),
            flags: v[17] as u8,
            reserved: v[18] as u32,
        })
    }

    /// Refuses a packet with a field wider than its width, naming the field.
    pub fn validate(&self) -> Result<()> {
        Self::from_field_values(&self.field_values()).map(|_| ())
    }

    /// The 256 bits, LSB first, as eight 32-bit words.
    pub fn to_bits(&self) -> Result<[u32; PACKET_WORDS]> {
        self.validate()?;
        let mut w = BitWriter::new();
        for (field, value) in LAYOUT.iter().zip(self.field_values()) {
            w.put(value, field.width);
        }
        let words = w.finish(PACKET_BITS);
        let mut out = [0u32; PACKET_WORDS];
        out.copy_from_slice(&words);
        Ok(out)
    }

    /// Unpacks 256 bits (never fails: every bit pattern is a packet).
    pub fn from_bits(words: &[u32; PACKET_WORDS]) -> Self {
        let mut r = BitReader::new(words);
        let v: [u64; 19] = std::array::from_fn(|i| r.get(LAYOUT[i].width));
        Self::from_field_values(&v).expect("every field was read at its own width")
    }

    /// Field `k` of the layout (counted from 0) plus `k + 1`, modulo its width: the `probe` half
    /// of `gicube_packet_loop`. Fields of equal width get different increments, so a swap of two
    /// of them shows as well as a moved boundary.
    pub fn probed(&self) -> Self {
        let mut v = self.field_values();
        for (k, (value, field)) in v.iter_mut().zip(LAYOUT.iter()).enumerate() {
            *value = (*value + k as u64 + 1) & ((1u64 << field.width) - 1);
        }
        Self::from_field_values(&v).expect("masked to each width")
    }

    /// The real value of every fixed-point field (the f64 reading of the contract).
    pub fn to_real(&self) -> RayReal {
        let s = |raw: u32, frac: u32| f64::from(raw) / f64::from(1u32 << frac);
        RayReal {
            u: self.u,
            v: self.v,
            start: self.start.map(|x| s(x, POS_FRAC_W)),
            dir: self
                .dir
                .map(|d| f64::from(d) / f64::from(1u32 << DIR_FRAC_W)),
            color: self.color.map(|c| s(u32::from(c), COLOR_FRAC_W)),
            opacity: s(u32::from(self.opacity), COLOR_FRAC_W),
            contribution: s(u32::from(self.contribution), COLOR_FRAC_W),
            interaction: s(u32::from(self.interaction), INTERACTION_FRAC_W),
            lifetime: self.lifetime,
            generation: self.generation,
            ray_type: self.ray_type,
            flags: self.flags,
        }
    }

    /// Quantizes real values: `sat(floor(x * 2^f + 1/2))` per field; NaN is an error.
    pub fn from_real(r: &RayReal) -> Result<Self> {
        let q = |name: &str, x: f64, frac: u32, lo: i64, hi: i64| -> Result<i64> {
            if x.is_nan() {
                return Err(ModelError::Config(format!("ray packet: `{name}` is NaN")));
            }
            let scaled = (x * (1u64 << frac) as f64 + 0.5).floor();
            Ok(scaled.clamp(lo as f64, hi as f64) as i64)
        };
        let pos_max = (1i64 << POS_W) - 1;
        let c_max = (1i64 << 12) - 1;
        let axes = ["x", "y", "z"];
        let mut start = [0u32; 3];
        let mut dir = [0i16; 3];
        for a in 0..3 {
            start[a] = q(
                &format!("start_{}", axes[a]),
                r.start[a],
                POS_FRAC_W,
                0,
                pos_max,
            )? as u32;
            dir[a] = q(
                &format!("dir_{}", axes[a]),
                r.dir[a],
                DIR_FRAC_W,
                i64::from(i16::MIN),
                i64::from(i16::MAX),
            )? as i16;
        }
        let names = ["red", "green", "blue"];
        let mut color = [0u16; 3];
        for c in 0..3 {
            color[c] = q(names[c], r.color[c], COLOR_FRAC_W, 0, c_max)? as u16;
        }
        let p = Self {
            u: r.u,
            v: r.v,
            start,
            dir,
            color,
            opacity: q("opacity", r.opacity, COLOR_FRAC_W, 0, c_max)? as u16,
            contribution: q("contribution", r.contribution, COLOR_FRAC_W, 0, c_max)? as u16,
            interaction: q("interaction", r.interaction, INTERACTION_FRAC_W, 0, 0xffff)? as u16,
            lifetime: r.lifetime,
            generation: r.generation,
            ray_type: r.ray_type,
            flags: r.flags,
            reserved: 0,
        };
        p.validate()?;
        Ok(p)
    }
}

/// A ray with real-valued fields (voxel units, unit-less colours), the f64 side of the packet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayReal {
    pub u: u16,
    pub v: u16,
    pub start: [f64; 3],
    pub dir: [f64; 3],
    pub color: [f64; 3],
    pub opacity: f64,
    pub contribution: f64,
    pub interaction: f64,
    pub lifetime: u8,
    pub generation: u8,
    pub ray_type: RayType,
    pub flags: u8,
}

impl RayReal {
    /// A random rendering ray inside the packet's ranges (the quantization stimulus): pixel,
    /// start, direction, colour, opacity, contribution, interaction, lifetime and generation drawn
    /// in that order; type `Rendering`, no flags.
    pub fn random<R: rand::Rng + ?Sized>(rng: &mut R) -> Self {
        RayReal {
            u: rng.random_range(0..4096),
            v: rng.random_range(0..4096),
            start: std::array::from_fn(|_| rng.random_range(0.0..4095.99)),
            dir: std::array::from_fn(|_| rng.random_range(-1.0..=1.0)),
            color: std::array::from_fn(|_| rng.random_range(0.0..0.9998)),
            opacity: rng.random_range(0.0..0.9998),
            contribution: rng.random_range(0.0..0.9998),
            interaction: rng.random_range(0.0..0.99999),
            lifetime: rng.random(),
            generation: rng.random(),
            ray_type: RayType::Rendering,
            flags: 0,
        }
    }
}

/// `gicube_packet_loop` configuration: register stages between input and output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PacketLoopConfig {
    pub stages: u32,
}

impl PacketLoopConfig {
    pub const S1: Self = Self { stages: 1 };
    pub const S2: Self = Self { stages: 2 };

    pub fn validate(&self) -> Result<()> {
        if !(1..=2).contains(&self.stages) {
            return Err(ModelError::Config(format!(
                "packet loop: Stages {} outside 1..=2",
                self.stages
            )));
        }
        Ok(())
    }

    /// Latency in cycles.
    pub fn latency(&self) -> u64 {
        u64::from(self.stages)
    }
}

/// One output of `gicube_packet_loop`: the plain round trip and the field-wise increment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PacketLoopOut {
    pub repack: RayPacket,
    pub probe: RayPacket,
}

/// The golden model of `gicube_packet_loop`.
#[derive(Debug, Clone)]
pub struct PacketLoop {
    cfg: PacketLoopConfig,
}

impl PacketLoop {
    pub fn new(cfg: PacketLoopConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self { cfg })
    }

    pub fn config(&self) -> PacketLoopConfig {
        self.cfg
    }
}

crate::item_by_item!(PacketLoop, RayPacket => PacketLoopOut, |_unit, p| PacketLoopOut {
    repack: *p,
    probe: p.probed(),
});

impl StreamCodec for PacketLoopConfig {
    type In = RayPacket;
    type Out = PacketLoopOut;

    fn in_width(&self) -> u32 {
        PACKET_BITS
    }

    fn out_width(&self) -> u32 {
        2 * PACKET_BITS
    }

    /// Test-bench side: packets come from generators that keep every field in range.
    fn pack_in(&self, item: &RayPacket) -> Vec<u32> {
        item.to_bits()
            .unwrap_or_else(|e| panic!("test bench built a bad packet: {e}"))
            .to_vec()
    }

    fn unpack_out(&self, words: &[u32]) -> PacketLoopOut {
        let half = |k: usize| -> [u32; PACKET_WORDS] {
            std::array::from_fn(|i| words.get(k * PACKET_WORDS + i).copied().unwrap_or(0))
        };
        PacketLoopOut {
            repack: RayPacket::from_bits(&half(0)),
            probe: RayPacket::from_bits(&half(1)),
        }
    }
}

/// A random packet from raw bits (every 256-bit pattern is a packet).
pub fn random_packet(rng: &mut impl rand::Rng) -> RayPacket {
    let words: [u32; PACKET_WORDS] = std::array::from_fn(|_| rng.random());
    RayPacket::from_bits(&words)
}

/// Directed packets: all zeros, all ones (every field wraps in the probe), and each field in turn
/// at all-ones, at its MSB alone and at 1, among zeros and among ones.
pub fn directed_packets() -> Vec<RayPacket> {
    let mut out = vec![
        RayPacket::from_bits(&[0; PACKET_WORDS]),
        RayPacket::from_bits(&[u32::MAX; PACKET_WORDS]),
    ];
    for (i, field) in LAYOUT.iter().enumerate() {
        let ones = (1u64 << field.width) - 1;
        for value in [ones, 1u64 << (field.width - 1), 1] {
            let mut v = [0u64; 19];
            v[i] = value;
            out.push(RayPacket::from_field_values(&v).expect("fits"));
            let mut v = RayPacket::from_bits(&[u32::MAX; PACKET_WORDS]).field_values();
            v[i] = ones ^ value;
            out.push(RayPacket::from_field_values(&v).expect("fits"));
        }
    }
    out
}

// The RTL parameters of this unit (the RTL defaults are the model's `S1`).
crate::unit_config!(PacketLoopConfig, "gicube_packet_loop", S1, {
    "Stages" => stages,
});

#[cfg(test)]
mod tests {
    use super::*;
    use crate::unit::StreamUnit;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn layout_covers_256_bits_exactly_once() {
        let mut next = 0;
        for field in LAYOUT {
            assert_eq!(field.lsb, next, "field `{}` does not follow on", field.name);
            next += field.width;
        }
        assert_eq!(next, PACKET_BITS);
        assert_eq!(PACKET_BITS / 8, 32, "32 bytes, [349]");
    }

    #[test]
    fn bits_round_trip_both_ways() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..100_000 {
            let words: [u32; PACKET_WORDS] = std::array::from_fn(|_| rand::Rng::random(&mut rng));
            let p = RayPacket::from_bits(&words);
            assert_eq!(p.to_bits().unwrap(), words);
            assert_eq!(RayPacket::from_bits(&p.to_bits().unwrap()), p);
        }
        for p in directed_packets() {
            assert_eq!(RayPacket::from_bits(&p.to_bits().unwrap()), p);
        }
    }

    #[test]
    fn fields_land_where_the_table_says() {
        let p = RayPacket {
            u: 0xabc,
            start: [1 << 19, 0, 0],
            dir: [-1, 0, 0],
            flags: flag::IRRADIANCE | flag::OVERFLOW,
            reserved: 0x80_0001,
            ..Default::default()
        };
        let w = p.to_bits().unwrap();
        let bit = |b: u32| (w[(b / 32) as usize] >> (b % 32)) & 1;
        assert_eq!(w[0] & 0xfff, 0xabc);
        assert_eq!(bit(43), 1, "start_x MSB is bit 43");
        for b in 84..=99 {
            assert_eq!(bit(b), 1, "dir_x = -1 sets bits 84..=99");
        }
        assert_eq!((bit(226), bit(227), bit(228)), (1, 0, 1));
        assert_eq!((bit(232), bit(255)), (1, 1));
        assert_eq!(w[7] >> 24, 0x80);
    }

    #[test]
    fn out_of_range_field_is_an_error_naming_it() {
        let p = RayPacket {
            u: 4096,
            ..Default::default()
        };
        let e = p.to_bits().unwrap_err().to_string();
        assert!(e.contains("`u`"), "{e}");
        let p = RayPacket {
            flags: 0x40,
            ..Default::default()
        };
        assert!(p.validate().unwrap_err().to_string().contains("flags"));
    }

    #[test]
    fn probe_wraps_each_field_alone() {
        let ones = RayPacket::from_bits(&[u32::MAX; PACKET_WORDS]);
        let p = ones.probed();
        assert_eq!((p.u, p.v), (0, 1), "all-ones plus 1 and plus 2");
        assert_eq!(p.reserved, 18, "the last field, k = 18, gets + 19");
        let p = RayPacket::default().probed();
        assert_eq!((p.u, p.v), (1, 2));
        assert_eq!(p.start, [3, 4, 5]);
        assert_eq!(p.dir, [6, 7, 8]);
        assert_eq!(p.ray_type, RayType::Lighting, "17 mod 4");
        assert_eq!(p.flags, 18);
        let d = RayPacket {
            dir: [i16::MAX - 5, -7, -9],
            ..Default::default()
        }
        .probed();
        assert_eq!(d.dir, [i16::MIN, 0, -1]);
    }

    #[test]
    fn quantization_is_within_half_an_lsb() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        use rand::Rng;
        for _ in 0..100_000 {
            let mut r = RayReal::random(&mut rng);
            r.ray_type = RayType::from_bits(rng.random_range(0..4));
            r.flags = rng.random_range(0..64);
            let p = RayPacket::from_real(&r).unwrap();
            let back = p.to_real();
            for a in 0..3 {
                assert!((back.start[a] - r.start[a]).abs() <= 0.5 / 256.0 + 1e-12);
                assert!((back.dir[a] - r.dir[a]).abs() <= 0.5 / 16384.0 + 1e-12);
                assert!((back.color[a] - r.color[a]).abs() <= 0.5 / 4096.0 + 1e-12);
            }
            assert!((back.interaction - r.interaction).abs() <= 0.5 / 65536.0 + 1e-12);
            assert_eq!(
                RayPacket::from_real(&back).unwrap(),
                p,
                "exact values are fixed points"
            );
        }
    }

    #[test]
    fn quantization_extremes_saturate_and_nan_is_refused() {
        let base = RayPacket::default().to_real();
        let p = RayPacket::from_real(&RayReal {
            start: [-3.0, 5000.0, 4095.999],
            dir: [1.0, -1.0, 2.5],
            color: [1.0, -0.1, 0.99999],
            ..base
        })
        .unwrap();
        assert_eq!(p.start, [0, (1 << 20) - 1, (1 << 20) - 1]);
        assert_eq!(p.dir, [1 << 14, -(1 << 14), i16::MAX]);
        assert_eq!(p.color, [4095, 0, 4095]);
        let nan = RayReal {
            opacity: f64::NAN,
            ..base
        };
        assert!(RayPacket::from_real(&nan)
            .unwrap_err()
            .to_string()
            .contains("opacity"));
    }

    #[test]
    fn loop_model_and_codec() {
        assert!(PacketLoopConfig { stages: 0 }.validate().is_err());
        assert!(PacketLoopConfig { stages: 3 }.validate().is_err());
        let cfg = PacketLoopConfig::S1;
        let mut m = PacketLoop::new(cfg).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let items: Vec<RayPacket> = (0..1000).map(|_| random_packet(&mut rng)).collect();
        let outs = m.run(&items);
        for (p, o) in items.iter().zip(&outs) {
            let mut words = cfg.pack_in(&o.repack);
            words.extend(cfg.pack_in(&o.probe));
            assert_eq!(cfg.unpack_out(&words), *o);
            assert_eq!(o.repack, *p);
        }
    }
}
