//! The accelerator top `cube5_accel` (docs/accel.md): its configuration, i.e. how the top's
//! parameters split into the configurations of the units inside it. What the top computes is the
//! frame model's image (`cube5_frame` with `Source = 1`, fed by `cube5_vol_fetch` and
//! `cube5_section_buf`); this module is the one place that maps the top's parameters onto them.

use crate::unit::UnitConfig;
use crate::units::cube5_accel_ctrl::AccelCtrlConfig;
use crate::units::cube5_frame::{FrameConfig, UNIT_WIDTH_PARAMS};
use crate::units::cube5_vol_fetch::VolFetchConfig;
use crate::{ModelError, Result};

/// The top's parameters that it passes through to the frame besides the units' widths
/// ([`UNIT_WIDTH_PARAMS`]); the frame also gets `Source = 1`.
pub const FRAME_PARAMS: &[&str] = &["P", "MaxDim", "BlockDim"];

/// The top's parameters that it passes through to the volume fetch (the top's `Outstanding` is
/// the fetch's read bursts in flight).
pub const FETCH_PARAMS: &[&str] = &[
    "AddrW",
    "DataW",
    "P",
    "VoxelW",
    "MaxDim",
    "BlockDim",
    "MaxBurst",
    "Outstanding",
];

/// The top's own parameters, with the RTL's defaults: the section width (anchors), the image
/// writer's bursts in flight and the AXI ID width.
const OWN_PARAMS: &[(&str, i64)] = &[
    ("Section", 16),
    ("WrOutstanding", 4),
    ("IdW", 4),
    ("Window", 0),
    ("WinOutstanding", 16),
    ("WinWDepth", 8),
    ("WinDescDepth", 32),
    ("FetchHold", 0),
    ("WinZeroDepth", 0),
    ("WinRing", 0),
    ("WinRingBurst", 16),
    ("WinFinBurst", 0),
];

/// The defaults of the parameters the top passes on, where the top's default differs from (or
/// must not depend on) the unit's: the RTL's values (`rtl/cube5/cube5_accel.sv`).
const PASSED_DEFAULTS: &[(&str, i64)] = &[
    ("P", 4),
    ("MaxDim", 64),
    ("VoxelW", 12),
    ("BlockDim", 8),
    ("AddrW", 32),
    ("DataW", 64),
    ("MaxBurst", 16),
    ("Outstanding", 8),
    ("WeightW", 8),
    ("FracW", 4),
    ("ClassIdxW", 12),
    ("MagIdxW", 4),
    ("MagShift", 10),
    ("ColorW", 8),
    ("AlphaW", 12),
    ("RmLog2", 3),
    ("RmFracW", 4),
    ("DiffW", 9),
    ("SpecW", 8),
    ("ExtraW", 4),
    ("AccW", 20),
    ("ZW", 12),
];

/// P-groups per fetch item (the section buffer's `ItemGroups`) at `P` pipelines and a `DataW`-bit
/// bus: 2 where a beat holds two (and `P <= 4`), else 1.
pub fn item_groups(p: i64, data_w: i64) -> u32 {
    if data_w >= 32 * p && p <= 4 {
        2
    } else {
        1
    }
}

/// One configuration of `cube5_accel`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AccelConfig {
    /// The frame inside (`Source = 1`): its image is the top's.
    pub frame: FrameConfig,
    /// The volume fetch inside: its `P` is the item's voxels, `item_groups(P, DataW)` P-groups.
    pub fetch: VolFetchConfig,
    /// Anchors per section (`Section`).
    pub section: u32,
    /// Image write bursts in flight (`WrOutstanding`).
    pub wr_outstanding: u32,
    /// AXI ID width (`IdW`).
    pub id_w: u32,
    /// The frame's compositing window (`Window = 1`): parks and restores over the port, final
    /// pixels written during the sweep (docs/accel.md, *The compositing window in the top*).
    pub window: bool,
    /// With the window: its write bursts in flight, and its restore reads in flight.
    pub win_outstanding: u32,
    /// With the window: the depth of its AW and W FIFOs (`WinWDepth`).
    pub win_w_depth: u32,
    /// With the window: the fetch's read bursts kept in flight while window write beats wait
    /// (`FetchHold`; 0 stops it). Timing only: the image is the same.
    pub fetch_hold: u32,
    /// With the window: the zero-park bit FIFO's depth (`WinZeroDepth`; 0: `MaxDim^2`).
    /// Timing only.
    pub win_zero_depth: u32,
    /// With the window: the parks as a packed ring in park order, written and read in bursts of
    /// up to `win_ring_burst` beats (`WinRing`, `WinRingBurst`; docs/numerics/compos_window.md,
    /// *The ring in park order*). Timing and scratch layout only: the image is the same.
    pub win_ring: bool,
    pub win_ring_burst: u32,
    /// With the window: the final pixels' consecutive beats as bursts of up to this many beats
    /// (`WinFinBurst`; 0: single-beat bursts; docs/numerics/compos_window.md, *Final pixels in
    /// bursts*). Timing only: the image is the same.
    pub win_fin_burst: u32,
}

/// Bytes per base-plane pixel in memory (the top's `PixelBytes`: R, G, B, A codes).
pub const PIXEL_BYTES: u32 = 4;

/// The window's AXI IDs (cube5_accel_win): parks and restores, final pixels (the fetch and the
/// image's clear use 0).
pub const ID_PARK: u32 = 1;
pub const ID_FINAL: u32 = 2;

impl AccelConfig {
    /// The control core inside (cube5_accel.sv: its parameters from the top's), whose plan gives
    /// the image's rows in memory.
    pub fn ctrl(&self) -> AccelCtrlConfig {
        AccelCtrlConfig {
            p: self.frame.p as u32,
            max_dim: self.fetch.max_dim,
            block_dim: self.fetch.block_dim,
            section: self.section,
            addr_w: self.fetch.addr_w,
            data_w: self.fetch.data_w,
            pixel_bytes: PIXEL_BYTES,
            len_w: 16,
            window: u32::from(self.window),
        }
    }
}

impl AccelConfig {
    /// `Cx`: bytes of a parked coxel's slot in the scratch area (`Window = 1`): the stored coxel
    /// (`4 (AccW + 1) + 1` bits) rounded up to a power-of-two byte count, at least a bus beat.
    pub fn park_slot_bytes(&self) -> u64 {
        let store_bits = 4 * (u64::from(self.frame.compos.acc_w) + 1) + 1;
        store_bits
            .div_ceil(8)
            .next_power_of_two()
            .max(u64::from(self.fetch.data_w / 8))
    }

    /// The bursts the top may have in flight on its port, reads or writes, whichever is more
    /// (the fetch's `Outstanding` or the writer's `WrOutstanding`, plus the window's).
    pub fn port_outstanding(&self) -> u32 {
        let win = if self.window { self.win_outstanding } else { 0 };
        (self.fetch.outstanding + win).max(self.wr_outstanding + win)
    }
}

impl UnitConfig for AccelConfig {
    const TOP: &'static str = "cube5_accel";

    fn from_params(params: &[(&str, i64)]) -> Result<Self> {
        let mut all: Vec<(&'static str, i64)> = PASSED_DEFAULTS
            .iter()
            .chain(OWN_PARAMS.iter())
            .copied()
            .collect();
        for &(name, value) in params {
            let Some(slot) = all.iter_mut().find(|(n, _)| *n == name) else {
                let known: Vec<&str> = all.iter().map(|(n, _)| *n).collect();
                return Err(ModelError::Config(format!(
                    "cube5_accel: unknown parameter {name} (known: {})",
                    known.join(", ")
                )));
            };
            slot.1 = value;
        }
        let get = |n: &str| all.iter().find(|(k, _)| *k == n).map_or(0, |&(_, v)| v);
        let pick = |names: &[&'static str]| -> Vec<(&'static str, i64)> {
            names.iter().map(|&n| (n, get(n))).collect()
        };
        let mut fp = pick(FRAME_PARAMS);
        fp.extend(pick(UNIT_WIDTH_PARAMS));
        fp.push(("Source", 1));
        // The frame's slice FIFOs hold one section (cube5_accel.sv: `.MaxSection(Section)`), and
        // its read-out gives P pixels of a row per item (`.OutLanes(P)`).
        fp.push(("MaxSection", get("Section")));
        // With the compositing window (`Window = 1`) the frame has no read-out: one lane.
        fp.push(("OutLanes", if get("Window") == 1 { 1 } else { get("P") }));
        fp.push(("Window", get("Window")));
        fp.push(("WinDescDepth", get("WinDescDepth")));
        let own = |n: &str| {
            u32::try_from(get(n)).map_err(|_| {
                ModelError::Config(format!("cube5_accel: {n} = {} is out of range", get(n)))
            })
        };
        // The fetch's items are the section buffer's: two P-groups where a bus beat holds them
        // (`ItemGroups` = 2, docs/numerics/section_buf.md), else one.
        let mut fetch_params = pick(FETCH_PARAMS);
        let groups = item_groups(get("P"), get("DataW"));
        for (n, v) in &mut fetch_params {
            if *n == "P" {
                *v *= i64::from(groups);
            }
        }
        let c = Self {
            frame: FrameConfig::from_params(&fp)?,
            fetch: VolFetchConfig::from_params(&fetch_params)?,
            section: own("Section")?,
            wr_outstanding: own("WrOutstanding")?,
            id_w: own("IdW")?,
            window: own("Window")? == 1,
            win_outstanding: own("WinOutstanding")?,
            win_w_depth: own("WinWDepth")?,
            fetch_hold: own("FetchHold")?,
            win_zero_depth: own("WinZeroDepth")?,
            win_ring: own("WinRing")? == 1,
            win_ring_burst: own("WinRingBurst")?,
            win_fin_burst: own("WinFinBurst")?,
        };
        let pow2 = |v: u32| v.is_power_of_two();
        if own("WinRing")? > 1
            || !pow2(c.win_ring_burst)
            || !(2..=256).contains(&c.win_ring_burst)
            || (c.win_zero_depth != 0 && (!pow2(c.win_zero_depth) || c.win_zero_depth < 2))
            || (c.win_fin_burst != 0
                && (!pow2(c.win_fin_burst) || !(2..=256).contains(&c.win_fin_burst)))
        {
            return Err(ModelError::Config(format!(
                "cube5_accel: WinRing must be 0 or 1, WinRingBurst = {} a power of two from 2 to \
                 256, WinZeroDepth = {} 0 or a power of two of at least 2, WinFinBurst = {} 0 or \
                 a power of two from 2 to 256",
                c.win_ring_burst, c.win_zero_depth, c.win_fin_burst
            )));
        }
        if !c.win_w_depth.is_power_of_two() || c.win_w_depth < 2 {
            return Err(ModelError::Config(format!(
                "cube5_accel: WinWDepth = {} must be a power of two of at least 2",
                c.win_w_depth
            )));
        }
        if own("Window")? > 1 || (c.window && c.id_w < 2) {
            return Err(ModelError::Config(
                "cube5_accel: Window must be 0 or 1, and Window = 1 needs IdW >= 2".into(),
            ));
        }
        if c.section < 2 * get("P") as u32 {
            return Err(ModelError::Config(format!(
                "cube5_accel: Section = {} must be at least 2 P = {}",
                c.section,
                2 * get("P")
            )));
        }
        Ok(c)
    }

    fn to_params(&self) -> Vec<(&'static str, i64)> {
        let frame = self.frame.to_params();
        let fetch = self.fetch.to_params();
        let from = |list: &[(&'static str, i64)], n: &str| {
            list.iter().find(|(k, _)| *k == n).map(|&(_, v)| v)
        };
        let mut out: Vec<(&'static str, i64)> = Vec::new();
        for &n in FRAME_PARAMS
            .iter()
            .chain(UNIT_WIDTH_PARAMS)
            .chain(FETCH_PARAMS)
        {
            if out.iter().any(|(k, _)| *k == n) {
                continue;
            }
            let v = from(&frame, n).or_else(|| from(&fetch, n)).unwrap_or(0);
            out.push((n, v));
        }
        out.extend([
            ("Section", i64::from(self.section)),
            ("WrOutstanding", i64::from(self.wr_outstanding)),
            ("IdW", i64::from(self.id_w)),
            ("Window", i64::from(self.window)),
            ("WinOutstanding", i64::from(self.win_outstanding)),
            ("WinWDepth", i64::from(self.win_w_depth)),
            ("WinDescDepth", i64::from(self.frame.win_desc_depth)),
            ("FetchHold", i64::from(self.fetch_hold)),
            ("WinZeroDepth", i64::from(self.win_zero_depth)),
            ("WinRing", i64::from(self.win_ring)),
            ("WinRingBurst", i64::from(self.win_ring_burst)),
            ("WinFinBurst", i64::from(self.win_fin_burst)),
        ]);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_round_trip_and_bad_parameters_are_refused() {
        let c = AccelConfig::from_params(&[]).unwrap();
        let back = AccelConfig::from_params(&c.to_params()).unwrap();
        assert_eq!(c, back);
        assert!(AccelConfig::from_params(&[("Bogus", 1)]).is_err());
        assert!(AccelConfig::from_params(&[("Section", 4), ("P", 4)]).is_err());
    }
}
