//! The pre-pass on the RTL: the three passes of `volume.prefilter` (x, then y, then z) streamed
//! through one `cube5_sepconv`, each pass's items made from the output of the pass before with
//! the contract's edge rule (docs/numerics/sepconv.md, *Over a volume: the 3-pass pre-filter*;
//! the model is `cube5_model::prefilter`). The caller compares the filtered volume with the
//! model's before the frame runs.

use crate::error::TbError;
use crate::rtl::{RtlStream, Traffic};
use crate::variants::{variants_of, Variant};
use cube5_model::prefilter::{pass_items, Prefilter, PASS_AXES, SEPCONV_LATENCY};
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_sepconv::{Sepconv, SepconvConfig};
use cube5_model::volume::Volume;

/// What the RTL pre-pass computed.
#[derive(Debug, Clone)]
pub struct RtlPrefilter {
    pub variant: &'static Variant,
    /// The filtered voxels (the last pass's outputs, in storage order).
    pub data: Vec<i64>,
    /// Cycles of each pass, from the first item offered to the last output taken.
    pub pass_cycles: [u64; 3],
}

impl RtlPrefilter {
    pub fn cycles(&self) -> u64 {
        self.pass_cycles.iter().sum()
    }
}

/// The built `cube5_sepconv` variant of configuration `cfg`, if any; else the error names the
/// `CUBE5_TOPS` entry that builds it.
pub fn sepconv_variant(cfg: &SepconvConfig) -> Result<&'static Variant, TbError> {
    let want = cfg.to_params();
    let same = |v: &&'static Variant| want.iter().all(|(k, val)| v.param(k) == Some(*val));
    let all: Vec<&'static Variant> = variants_of(SepconvConfig::TOP);
    match all.iter().copied().find(|v| same(v) && v.built) {
        Some(v) => Ok(v),
        None => {
            let kv: Vec<String> = want.iter().map(|(k, v)| format!("{k}={v}")).collect();
            Err(TbError::setup(
                SepconvConfig::TOP,
                format!(
                    "no build of {} with {} in this test bench (CUBE5_TOPS={}@{} builds it)",
                    SepconvConfig::TOP,
                    kv.join(" "),
                    SepconvConfig::TOP,
                    kv.join(":")
                ),
            ))
        }
    }
}

/// Streams the three passes of `kernel` over `vol` through the RTL (`seed`: the DUT's random
/// initial state), at full speed. `Ok(None)` for `Prefilter::None`.
pub fn run(vol: &Volume, kernel: Prefilter, seed: u32) -> Result<Option<RtlPrefilter>, TbError> {
    let (Some(cfg), Some(w)) = (kernel.sepconv_config(vol.bits), kernel.weight()) else {
        return Ok(None);
    };
    let variant = sepconv_variant(&cfg)?;
    let gold = Sepconv::new(cfg, w).map_err(|e| TbError::setup(variant.name, e))?;
    let mut dut: RtlStream<SepconvConfig> = RtlStream::new(variant, cfg, seed)?;
    for (addr, data) in gold.config_writes() {
        dut.write_config(addr, &data)?;
    }
    let mut data: Vec<i64> = vol.data.iter().map(|&v| i64::from(v)).collect();
    let mut pass_cycles = [0; 3];
    let n = data.len() as u64;
    for (axis, cycles) in pass_cycles.iter_mut().enumerate() {
        let items = pass_items(&data, vol.dims, axis);
        let start = dut.cycle();
        let driven = dut.drive(&items, &Traffic::full_speed(), n, 2 * n + 1000)?;
        if driven.stats.produced != n {
            return Err(TbError::Protocol {
                variant: variant.name.to_string(),
                seed: u64::from(seed),
                cycle: dut.cycle(),
                what: format!(
                    "pass along {}: {} of {n} outputs (latency {SEPCONV_LATENCY})",
                    PASS_AXES[axis], driven.stats.produced
                ),
            });
        }
        *cycles = dut.cycle() - start;
        data = driven.outputs.into_iter().map(|t| t.value).collect();
    }
    Ok(Some(RtlPrefilter {
        variant,
        data,
        pass_cycles,
    }))
}
