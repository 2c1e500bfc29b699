//! Driving `cube5_er` (the ER-Perspective sweep, docs/numerics/er_perspective.md, "The RTL:
//! cube5_er") with the host's items of an [`ErJob`] and comparing its base plane with the
//! contract's model, [`ErJob::render`], coxel by coxel.

use crate::error::TbError;
use crate::rtl::{RtlStream, Traffic};
use crate::variants::{gate_variants_of, variants_of, Variant};
use cube5_model::er_perspective::{ErJob, ErRun};
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_compos::Coxel;
use cube5_model::units::cube5_er::{frame_items, volume_items, ErConfig, ErIn};

/// What one frame of the RTL gave.
#[derive(Debug, Clone)]
pub struct ErRtlRun {
    pub coxels: Vec<Coxel>,
    /// Clocks from the frame's `Clear` to its `Emit` (the sweep and the merges), from the RTL.
    pub sweep_cycles: u64,
    /// Clocks of the whole drive (set-up items, sweep, read-out) under its traffic.
    pub cycles: u64,
}

/// One `cube5_er` DUT and its configuration.
pub struct ErBench {
    pub dut: RtlStream<ErConfig>,
    pub cfg: ErConfig,
}

/// The built RTL configurations of cube5_er (the table's order).
pub fn er_variants() -> Vec<&'static Variant> {
    variants_of(ErConfig::TOP)
}

/// The built gate-level netlists of cube5_er.
pub fn er_gate_variants() -> Vec<&'static Variant> {
    gate_variants_of(ErConfig::TOP)
}

fn setup_err(v: &Variant, e: impl std::fmt::Display) -> TbError {
    TbError::Setup {
        variant: v.name.to_string(),
        what: e.to_string(),
    }
}

impl ErBench {
    pub fn new(variant: &'static Variant, seed: u32) -> Result<Self, TbError> {
        let cfg: ErConfig = variant.config().map_err(|e| setup_err(variant, e))?;
        Ok(Self {
            dut: RtlStream::new(variant, cfg, seed)?,
            cfg,
        })
    }

    pub fn variant(&self) -> &'static Variant {
        self.dut.variant()
    }

    /// Whether this configuration runs `job` (else the host's refusal).
    pub fn check(&self, job: &ErJob) -> Result<(), String> {
        cube5_model::units::cube5_er::check_job(&self.cfg, job).map_err(|e| e.to_string())
    }

    /// Loads the volume of `job` (full speed); returns the clocks taken.
    pub fn load(&mut self, job: &ErJob) -> Result<u64, TbError> {
        let v = self.variant();
        let items = volume_items(&self.cfg, job).map_err(|e| setup_err(v, e))?;
        let n = items.len() as u64;
        let d = self
            .dut
            .drive(&items, &Traffic::full_speed(), 0, 4 * n + 100)?;
        if d.stats.consumed != n {
            return Err(TbError::Setup {
                variant: v.name.to_string(),
                what: format!("the volume load took {} of {n} items", d.stats.consumed),
            });
        }
        Ok(d.stats.cycles)
    }

    /// The frame's items (after its volume).
    pub fn items(&self, job: &ErJob) -> Result<Vec<ErIn>, TbError> {
        frame_items(&self.cfg, job).map_err(|e| setup_err(self.variant(), e))
    }

    /// A budget of clocks for `job`'s frame: eight per sample, ten per merged coxel, and the
    /// read-out, under traffic that may idle and stall most clocks.
    pub fn budget(job: &ErJob, items: usize) -> u64 {
        let layout = job.setup.layout();
        let samples: u64 = layout.samples_per_slice().iter().sum();
        let coxels: u64 = layout.extent.iter().map(|e| e.count()).sum();
        20 * (8 * samples + 12 * coxels + items as u64) + 100_000
    }

    /// Runs the frame of `job` (its volume loaded) under `traffic`.
    pub fn frame(&mut self, job: &ErJob, traffic: &Traffic) -> Result<ErRtlRun, TbError> {
        let items = self.items(job)?;
        let ext = job.setup.layout().extent[0];
        let n = ext.count();
        let d = self
            .dut
            .drive(&items, traffic, n, Self::budget(job, items.len()))?;
        if d.stats.protocol_errors != 0 {
            return Err(TbError::Protocol {
                variant: self.variant().name.to_string(),
                seed: 0,
                cycle: d.stats.first_protocol_error_cycle,
                what: "a stalled output dropped valid or changed".into(),
            });
        }
        if d.stats.produced != n || d.stats.consumed != items.len() as u64 {
            return Err(TbError::Deadlock {
                variant: self.variant().name.to_string(),
                seed: 0,
                cycle: d.stats.cycles,
                what: format!(
                    "{} of {} items taken, {} of {n} coxels out",
                    d.stats.consumed,
                    items.len(),
                    d.stats.produced
                ),
            });
        }
        Ok(ErRtlRun {
            sweep_cycles: d.outputs.first().map_or(0, |t| u64::from(t.value.cycles)),
            coxels: d.outputs.into_iter().map(|t| t.value.coxel).collect(),
            cycles: d.stats.cycles,
        })
    }
}

/// The first coxel where the RTL's base plane differs from the model's, named by its ray
/// `(m, n)` of region 0; `None` when they are equal bit for bit.
pub fn first_difference(got: &ErRtlRun, want: &ErRun) -> Option<String> {
    if got.coxels.len() != want.coxels.len() {
        return Some(format!(
            "{} coxels from the RTL, {} from the model",
            got.coxels.len(),
            want.coxels.len()
        ));
    }
    let w = want.extent.width().max(1);
    let k = (0..got.coxels.len()).find(|&k| got.coxels[k] != want.coxels[k])?;
    let (m, n) = (
        want.extent.m0 + (k % w) as i64,
        want.extent.n0 + (k / w) as i64,
    );
    let wrong = crate::harness::count_differing(&got.coxels, &want.coxels);
    Some(format!(
        "coxel {k} (ray ({m}, {n}) of region 0): RTL {:?}, model {:?} ({wrong} of {} coxels differ)",
        got.coxels[k],
        want.coxels[k],
        got.coxels.len()
    ))
}
