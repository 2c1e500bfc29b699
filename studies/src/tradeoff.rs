//! The speed/accuracy trade, measured (`cube5 tradeoff`; results in `docs/tradeoffs.md`).
//!
//! Each sweep varies one knob of the pipeline model ([`Quality`], the early-termination threshold,
//! the interpolation scheme, the gradient scheme) and reports its cost (samples; synthesized cells
//! where the knob is a width) against its error versus the f64 image-order reference
//! ([`render_reference`]): PSNR, maximum absolute error, and cube3-paper §6.1's relative Euclidean
//! RGB error. Two sweeps reproduce cube3-paper §6: sheared against full tri-linear interpolation
//! over view angles (§6.1, Figure 13) and the 6-, 10- and 26-neighbourhood gradients' angular error
//! on a voxelized sphere (§6.2, Figure 15), the latter through the `cube5_gradient` model.
//!
//! The data come out as [`Table`]s and [`Figure`]s; the command line writes them as Markdown, CSV
//! and PNG.

use cube5_model::er_perspective::{render_er, render_er_f64, ErMerge, ErScheme};
use cube5_model::error::{ModelError, Result};
use cube5_model::phantom::{sphere_phantom, SphereGeometry};
use cube5_model::render::{
    image_error, render_pipeline, render_reference, CompositeMode, GradientScheme, ImageError,
    Interpolation, Projection, Quality, RenderParams, SliceSetup, View, STEP_W,
};
use cube5_model::slab_perspective::{render_slabs, SlabSpacing, Slabs};
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_frame::FrameConfig;
use cube5_model::units::cube5_gradient::{block_index, Gradient, GradientConfig, GradientIn};
use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_model::volume::Volume;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// cube3-paper §6.1: the largest relative Euclidean error of sheared tri-linear interpolation
/// against image-order ray casting (VolRen), percent.
pub const PAPER_VS_IMAGE_ORDER: f64 = 1.3;
/// cube3-paper §6.1: the same against the exact 8-neighbourhood at the same positions (True3D).
pub const PAPER_VS_TRUE3D: f64 = 0.3;

// =================================================================================================
// Tables, figures, synthesis results
// =================================================================================================

/// A result table.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// File stem (`tradeoff-widths`).
    pub name: String,
    pub title: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    fn new(name: &str, title: &str, columns: &[&str]) -> Self {
        Self {
            name: name.into(),
            title: title.into(),
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    pub fn to_markdown(&self) -> String {
        let mut s = format!("| {} |\n|", self.columns.join(" | "));
        for (i, _) in self.columns.iter().enumerate() {
            s.push_str(if i == 0 { "---|" } else { "---:|" });
        }
        s.push('\n');
        for r in &self.rows {
            s.push_str(&format!("| {} |\n", r.join(" | ")));
        }
        s
    }

    pub fn to_csv(&self) -> String {
        let quote = |c: &str| {
            if c.contains(',') || c.contains('"') {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.to_string()
            }
        };
        let mut s = self
            .columns
            .iter()
            .map(|c| quote(c))
            .collect::<Vec<_>>()
            .join(",");
        s.push('\n');
        for r in &self.rows {
            s.push_str(&r.iter().map(|c| quote(c)).collect::<Vec<_>>().join(","));
            s.push('\n');
        }
        s
    }
}

/// One curve of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// A line plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// File stem (`tradeoff-interpolation`).
    pub name: String,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Horizontal reference lines (value, label), e.g. the paper's bounds.
    pub marks: Vec<(f64, String)>,
    /// Plot x on a log2 axis.
    pub log_x: bool,
}

/// One synthesized configuration of an RTL top: its parameters and `target/synth/area.md` row.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthRow {
    pub top: String,
    pub config: String,
    pub params: BTreeMap<String, u32>,
    /// Columns of area.md by header name (`generic cells`, `ECP5 LUT4`, ...).
    pub figures: BTreeMap<String, String>,
}

/// Synthesis results, joined with the verified configurations (`rtl/**/*.variants`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Synth {
    pub rows: Vec<SynthRow>,
}

impl Synth {
    /// Joins `area_md` (the table `scripts/synth.sh` writes) with `variants`: `(top, text of
    /// top.variants)`. Rows of area.md without a variant line, and variants never synthesized,
    /// are dropped.
    pub fn parse(area_md: &str, variants: &[(String, String)]) -> Self {
        let mut params: BTreeMap<(String, String), BTreeMap<String, u32>> = BTreeMap::new();
        for (top, text) in variants {
            for line in text.lines() {
                let line = line.split('#').next().unwrap_or("").trim();
                let mut words = line.split_whitespace();
                let Some(name) = words.next() else { continue };
                let p: BTreeMap<String, u32> = words
                    .filter_map(|w| w.split_once('='))
                    .filter_map(|(k, v)| Some((k.to_string(), v.parse().ok()?)))
                    .collect();
                params.insert((top.clone(), name.to_string()), p);
            }
        }
        let mut header: Vec<String> = Vec::new();
        let mut rows = Vec::new();
        for line in area_md.lines() {
            let cells: Vec<String> = line
                .trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect();
            if cells.len() < 3 || cells[0].starts_with('-') {
                continue;
            }
            if cells[0] == "top" {
                header = cells;
                continue;
            }
            if header.is_empty() {
                continue;
            }
            let key = (cells[0].clone(), cells[1].clone());
            if let Some(p) = params.get(&key) {
                rows.push(SynthRow {
                    top: key.0,
                    config: key.1,
                    params: p.clone(),
                    figures: header
                        .iter()
                        .cloned()
                        .zip(cells.iter().cloned())
                        .skip(2)
                        .collect(),
                });
            }
        }
        Self { rows }
    }

    /// Adds the configurations of `variants` that area.md lacks but whose Yosys logs exist
    /// (`scripts/synth.sh` leaves `target/synth/<top>_<config>.{generic,ecp5}.log` and, for `fmax`
    /// configurations, `.pnr.log`; area.md holds only the tops of the last run). `read(name)`
    /// returns a log's text. The figures are counted as the script counts them.
    pub fn add_from_logs(
        &mut self,
        variants: &[(String, String)],
        read: impl Fn(&str) -> Option<String>,
    ) {
        for (top, text) in variants {
            for line in text.lines() {
                let line = line.split('#').next().unwrap_or("").trim();
                let mut words = line.split_whitespace();
                let Some(config) = words.next() else { continue };
                if self
                    .rows
                    .iter()
                    .any(|r| &r.top == top && r.config == config)
                {
                    continue;
                }
                let Some(generic) = read(&format!("{top}_{config}.generic.log")) else {
                    continue;
                };
                let Some(cells) = generic
                    .lines()
                    .filter_map(|l| l.trim().strip_prefix("Number of cells:"))
                    .filter_map(|v| v.trim().parse::<u64>().ok())
                    .next_back()
                else {
                    continue;
                };
                let mut figures = BTreeMap::new();
                figures.insert("generic cells".to_string(), cells.to_string());
                if let Some(ecp5) = read(&format!("{top}_{config}.ecp5.log")) {
                    // The script's awk: sum every stat line whose cell name starts so.
                    let count = |prefix: &str| {
                        ecp5.lines()
                            .filter_map(|l| {
                                let mut w = l.split_whitespace();
                                let (name, n) = (w.next()?, w.next()?);
                                if name.starts_with(prefix) {
                                    n.parse::<u64>().ok()
                                } else {
                                    None
                                }
                            })
                            .sum::<u64>()
                    };
                    figures.insert("ECP5 LUT4".into(), count("LUT4").to_string());
                    figures.insert("ECP5 MULT18".into(), count("MULT18X18D").to_string());
                }
                if let Some(pnr) = read(&format!("{top}_{config}.pnr.log")) {
                    if let Some(f) = pnr
                        .lines()
                        .rfind(|l| l.contains("Max frequency for clock"))
                        .and_then(|l| l.rsplit(": ").next())
                        .and_then(|v| v.split_whitespace().next())
                    {
                        figures.insert("ECP5 Fmax (MHz)".into(), f.to_string());
                    }
                }
                let params = line
                    .split_whitespace()
                    .filter_map(|w| w.split_once('='))
                    .filter_map(|(k, v)| Some((k.to_string(), v.parse().ok()?)))
                    .collect();
                self.rows.push(SynthRow {
                    top: top.clone(),
                    config: config.to_string(),
                    params,
                    figures,
                });
            }
        }
    }

    /// Fills an `n/a` ECP5 Fmax from the configuration's place-and-route log when one exists (a
    /// later `SYNTH_FMAX=0` run rewrites area.md without it but leaves the log).
    pub fn fmax_from_logs(&mut self, read: impl Fn(&str) -> Option<String>) {
        for r in &mut self.rows {
            let known = r
                .figures
                .get("ECP5 Fmax (MHz)")
                .is_some_and(|f| f.parse::<f64>().is_ok());
            if known {
                continue;
            }
            if let Some(f) = read(&format!("{}_{}.pnr.log", r.top, r.config)).and_then(|pnr| {
                pnr.lines()
                    .rfind(|l| l.contains("Max frequency for clock"))
                    .and_then(|l| l.rsplit(": ").next())
                    .and_then(|v| v.split_whitespace().next())
                    .map(str::to_string)
            }) {
                r.figures
                    .insert("ECP5 Fmax (MHz)".into(), format!("{f} (log)"));
            }
        }
    }

    /// The synthesized configuration of `top` whose parameters named in `bind` all match.
    pub fn find(&self, top: &str, bind: &[(&str, u32)]) -> Option<&SynthRow> {
        self.rows.iter().find(|r| {
            r.top == top
                && bind
                    .iter()
                    .all(|(k, v)| r.params.get(*k).is_none_or(|p| p == v))
                && bind.iter().any(|(k, _)| r.params.contains_key(*k))
        })
    }

    /// Cells of the units a quality setting uses, where a synthesized configuration matches.
    pub fn cells(&self, q: &Quality, voxel_bits: u32) -> String {
        let mut out = Vec::new();
        let units: [(&str, Vec<(&str, u32)>); 3] = [
            (
                "cube5_trilin",
                vec![
                    ("VoxelW", voxel_bits),
                    ("WeightW", q.weight_bits),
                    ("FracW", q.frac_bits),
                ],
            ),
            (
                "cube5_gradient",
                vec![
                    ("VoxelW", voxel_bits),
                    ("WeightW", q.weight_bits),
                    ("FracW", q.frac_bits),
                ],
            ),
            (
                "cube5_compos",
                vec![
                    ("ColorW", q.colour_bits),
                    ("AlphaW", q.alpha_bits),
                    ("AccW", q.acc_bits),
                ],
            ),
        ];
        for (top, bind) in units {
            if let Some(r) = self.find(top, &bind) {
                out.push(format!(
                    "{} {}: {}",
                    top.trim_start_matches("cube5_"),
                    r.config,
                    r.figures.get("generic cells").map_or("?", |s| s.as_str())
                ));
            }
        }
        if out.is_empty() {
            "-".into()
        } else {
            out.join("; ")
        }
    }
}

// =================================================================================================
// The sweep
// =================================================================================================

/// Progress reports of a long sweep (the command line shows bars).
pub trait Progress: Sync {
    fn start(&self, _name: &str, _total: u64) {}
    fn tick(&self) {}
    fn finish(&self) {}
}

/// No progress display.
pub struct Quiet;
impl Progress for Quiet {}

/// What to sweep.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The scene's volume, transfer function, image and view, and the baseline quality.
    pub volume: Volume,
    pub tf: TransferFunction,
    pub params: RenderParams,
    pub quality: Quality,
    pub voxel_bits: Vec<u32>,
    pub weight_bits: Vec<u32>,
    pub colour_bits: Vec<u32>,
    pub alpha_bits: Vec<u32>,
    pub samples_per_slice: Vec<u32>,
    pub thresholds: Vec<f64>,
    /// §6.1: rotation angles about the vertical axis, degrees.
    pub angles: Vec<f64>,
    /// §6.1: the view's elevation (cube3 tilted the dataset 70 degrees: elevation 20).
    pub paper_elevation: f64,
    /// §6.1: the reference renderer's step.
    pub paper_step: f64,
    /// §6.2: edge of the voxelized sphere.
    pub sphere_size: usize,
    /// Slab perspective: the slab counts (the perspective view of `params`, fov 40 degrees).
    pub slab_counts: Vec<u32>,
    /// ER-perspective: the fields of view (degrees) and base rates (rays per voxel) swept.
    pub er_fovs: Vec<f64>,
    pub er_rates: Vec<u32>,
    pub synth: Option<Synth>,
}

impl Setup {
    /// The default sweep on `volume` (under two minutes on two cores at 64^3 and 128^2 pixels).
    pub fn new(
        volume: Volume,
        tf: TransferFunction,
        params: RenderParams,
        quality: Quality,
    ) -> Self {
        Self {
            volume,
            tf,
            params,
            quality,
            voxel_bits: vec![6, 7, 8, 10, 12],
            weight_bits: vec![2, 3, 4, 5, 6, 8, 10, 12],
            colour_bits: vec![4, 5, 6, 8, 10, 12],
            alpha_bits: vec![6, 8, 10, 12, 14],
            samples_per_slice: vec![1, 2, 3, 4],
            thresholds: vec![0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 0.999, 1.0],
            angles: (0..=18).map(|k| f64::from(k) * 5.0).collect(),
            paper_elevation: 20.0,
            paper_step: 0.5,
            sphere_size: 64,
            slab_counts: vec![1, 2, 4, 8, 16, 32, 64],
            er_fovs: vec![20.0, 40.0, 60.0, 90.0, 120.0],
            er_rates: vec![1, 2],
            synth: None,
        }
    }

    /// A tiny sweep for tests: a few settings of every knob, three angles.
    pub fn tiny(vol: Volume, tf: TransferFunction, params: RenderParams, quality: Quality) -> Self {
        Self {
            voxel_bits: vec![8, 12],
            weight_bits: vec![4, 8],
            colour_bits: vec![6, 8],
            alpha_bits: vec![8, 12],
            samples_per_slice: vec![1, 2],
            thresholds: vec![0.9, 1.0],
            angles: vec![0.0, 30.0, 45.0],
            sphere_size: 24,
            slab_counts: vec![2, 4],
            er_fovs: vec![40.0, 90.0],
            er_rates: vec![1],
            ..Self::new(vol, tf, params, quality)
        }
    }
}

/// Everything one sweep produced.
#[derive(Debug, Clone)]
pub struct Report {
    pub tables: Vec<Table>,
    pub figures: Vec<Figure>,
    /// §6.1: the largest relative Euclidean error over the angles, percent: sheared against the
    /// image-order reference, sheared against full tri-linear, and the angle of the first's peak;
    /// then the same three on the smoothed volume.
    pub paper_61: [f64; 6],
    /// §6.1 with the mean distance over the full scale instead: the largest sheared vs image order
    /// and sheared vs True3D, percent.
    pub paper_61_full_scale: [f64; 2],
    /// §6.2: mean angular error (degrees) per scheme (6, 10, 26) at 0 and 45 degrees and the
    /// largest over the angles: `[scheme][0 deg, 45 deg, max]`.
    pub paper_62: [[f64; 3]; 3],
    /// Whether the synthesis table was found.
    pub synth_found: bool,
}

/// ER-perspective (`er_perspective::render_er`, the frame's units at their default widths) over
/// the fields of view and base rates of `setup`, Bartlett and the dropped-ray what-if: error
/// against the f64 perspective reference and against its own f64 reference, samples per slice
/// against the `N^2 .. 4N^2` bound, time per frame.
fn er_sweep(
    setup: &Setup,
    persp: &RenderParams,
    progress: &dyn Progress,
) -> Result<(Table, Figure)> {
    let (vol, tf) = (&setup.volume, &setup.tf);
    let mut table = Table::new(
        "tradeoff-er",
        "ER-perspective: error against the f64 perspective reference, samples per slice, time",
        &[
            "fov (deg)",
            "rays/voxel",
            "merge",
            ERR_COLUMNS[0],
            ERR_COLUMNS[1],
            ERR_COLUMNS[2],
            "PSNR vs its f64 (dB)",
            "regions",
            "samples/slice min..max",
            "N^2",
            "time/frame (ms)",
        ],
    );
    let merges = [ErMerge::Bartlett, ErMerge::Centre];
    progress.start(
        "ER-perspective",
        (setup.er_fovs.len() * setup.er_rates.len() * merges.len()) as u64,
    );
    let mut series: Vec<Series> = Vec::new();
    for &fov in &setup.er_fovs {
        let params = RenderParams {
            fov,
            ..persp.clone()
        };
        let reference = render_reference(vol, tf, &params)?;
        for &rays_per_voxel in &setup.er_rates {
            for merge in merges {
                let scheme = ErScheme {
                    rays_per_voxel,
                    merge,
                };
                let t = std::time::Instant::now();
                let run = render_er(vol, tf, &params, &FrameConfig::DEFAULT, scheme)?;
                let ms = t.elapsed().as_secs_f64() * 1e3;
                let (ideal, _) = render_er_f64(vol, tf, &params, scheme)?;
                let e = image_error(&run.image, &reference);
                let own = image_error(&run.image, &ideal);
                let [a, m, r] = fmt_err(&e);
                let st = &run.stats;
                table.rows.push(vec![
                    format!("{fov}"),
                    rays_per_voxel.to_string(),
                    merge.name().into(),
                    a,
                    m,
                    r,
                    fmt_err(&own)[0].clone(),
                    st.regions.to_string(),
                    format!("{}..{}", st.min_per_slice(), st.max_per_slice()),
                    st.n2.to_string(),
                    format!("{ms:.0}"),
                ]);
                let name = format!("{rays_per_voxel} ray/voxel, {}", merge.name());
                let idx = match series.iter().position(|s| s.name == name) {
                    Some(i) => i,
                    None => {
                        series.push(Series {
                            name,
                            points: Vec::new(),
                        });
                        series.len() - 1
                    }
                };
                if e.psnr_db.is_finite() {
                    series[idx].points.push((fov, e.psnr_db));
                }
                progress.tick();
            }
        }
    }
    progress.finish();
    let figure = Figure {
        name: "tradeoff-er".into(),
        title: "ER-perspective: PSNR against the f64 perspective".into(),
        x_label: "field of view (degrees)".into(),
        y_label: "PSNR (dB)".into(),
        series,
        marks: Vec::new(),
        log_x: false,
    };
    Ok((table, figure))
}

fn fmt_err(e: &ImageError) -> [String; 3] {
    [
        if e.psnr_db.is_finite() {
            format!("{:.1}", e.psnr_db)
        } else {
            "inf".into()
        },
        format!("{:.1}", e.max_abs * 255.0),
        format!("{:.3}", e.rel_euclid),
    ]
}

const ERR_COLUMNS: [&str; 3] = ["PSNR (dB)", "max abs (/255)", "rel. Euclidean (%)"];

/// Runs every sweep of `setup`.
pub fn run(setup: &Setup, progress: &dyn Progress) -> Result<Report> {
    let vol = &setup.volume;
    let tf = &setup.tf;
    let base = RenderParams {
        early_termination: 1.0,
        ..setup.params.clone()
    };
    let q0 = setup.quality;
    let vb0 = q0.voxel_width(vol.bits);
    let mut tables = Vec::new();
    let mut figures = Vec::new();

    let reference = render_reference(vol, tf, &base)?;
    let precise = render_pipeline(vol, tf, &base, &Quality::precise())?;
    let synth = setup.synth.clone().unwrap_or_default();
    let cells_col = if setup.synth.is_some() {
        "synthesized cells (generic)"
    } else {
        "synthesized cells (run make synth)"
    };

    // ---- widths ---------------------------------------------------------------------------------
    let mut widths = Table::new(
        "tradeoff-widths",
        "Bit widths (one knob at a time; the others at the baseline)",
        &[
            "knob",
            "bits",
            "samples",
            ERR_COLUMNS[0],
            ERR_COLUMNS[1],
            ERR_COLUMNS[2],
            "PSNR vs precise pipeline (dB)",
            cells_col,
        ],
    );
    let mut width_series: Vec<Series> = Vec::new();
    type Knob = (&'static str, fn(&mut Quality, u32));
    let knobs: [(Knob, &Vec<u32>); 4] = [
        (("voxel", |q, b| q.voxel_bits = Some(b)), &setup.voxel_bits),
        (("weight", |q, b| q.weight_bits = b), &setup.weight_bits),
        (("colour", |q, b| q.colour_bits = b), &setup.colour_bits),
        (("alpha", |q, b| q.alpha_bits = b), &setup.alpha_bits),
    ];
    let total: usize = knobs.iter().map(|(_, v)| v.len()).sum();
    progress.start("bit widths", total as u64);
    for ((name, set), values) in knobs {
        let mut pts = Vec::new();
        for &b in values {
            let mut q = q0;
            set(&mut q, b);
            let img = render_pipeline(vol, tf, &base, &q)?;
            let e = image_error(&img.image, &reference);
            let p = image_error(&img.image, &precise.image);
            let [a, m, r] = fmt_err(&e);
            widths.rows.push(vec![
                name.into(),
                b.to_string(),
                img.stats.samples.to_string(),
                a,
                m,
                r,
                fmt_err(&p)[0].clone(),
                synth.cells(&q, q.voxel_width(vol.bits)),
            ]);
            if p.psnr_db.is_finite() {
                pts.push((f64::from(b), p.psnr_db));
            }
            progress.tick();
        }
        width_series.push(Series {
            name: format!("{name} bits"),
            points: pts,
        });
    }
    progress.finish();
    tables.push(widths);
    figures.push(Figure {
        name: "tradeoff-widths".into(),
        title: "Bit widths: PSNR against the pipeline at precise widths".into(),
        x_label: "bits".into(),
        y_label: "PSNR (dB)".into(),
        series: width_series,
        marks: Vec::new(),
        log_x: false,
    });

    // ---- synthesized configurations -------------------------------------------------------------
    let mut configs = Table::new(
        "tradeoff-configs",
        "Verified interpolation/gradient configurations (VoxelW/WeightW/FracW): error and area",
        &[
            "config",
            "VoxelW/WeightW/FracW",
            ERR_COLUMNS[0],
            ERR_COLUMNS[1],
            ERR_COLUMNS[2],
            "trilin cells (generic / ECP5 LUT4 / MULT18)",
            "gradient cells (generic / ECP5 LUT4 / MULT18)",
            "trilin ECP5 Fmax (MHz)",
        ],
    );
    for (name, c) in [
        ("narrow", TrilinConfig::NARROW),
        ("default", TrilinConfig::DEFAULT),
        ("wide", TrilinConfig::WIDE),
    ] {
        let q = Quality {
            voxel_bits: Some(c.voxel_w),
            weight_bits: c.weight_w,
            frac_bits: c.frac_w,
            ..q0
        };
        let img = render_pipeline(vol, tf, &base, &q)?;
        let [a, m, r] = fmt_err(&image_error(&img.image, &reference));
        let bind = [
            ("VoxelW", c.voxel_w),
            ("WeightW", c.weight_w),
            ("FracW", c.frac_w),
        ];
        let cells = |top: &str| match synth.find(top, &bind) {
            Some(row) => format!(
                "{} / {} / {}",
                row.figures.get("generic cells").map_or("?", |s| s.as_str()),
                row.figures.get("ECP5 LUT4").map_or("?", |s| s.as_str()),
                row.figures.get("ECP5 MULT18").map_or("?", |s| s.as_str())
            ),
            None if setup.synth.is_some() => "not synthesized".into(),
            None => "run make synth".into(),
        };
        let fmax = synth
            .find("cube5_trilin", &bind)
            .and_then(|r| r.figures.get("ECP5 Fmax (MHz)").cloned())
            .unwrap_or_else(|| "-".into());
        configs.rows.push(vec![
            name.into(),
            format!("{}/{}/{}", c.voxel_w, c.weight_w, c.frac_w),
            a,
            m,
            r,
            cells("cube5_trilin"),
            cells("cube5_gradient"),
            fmax,
        ]);
    }
    tables.push(configs);

    // ---- sample rate and early termination ------------------------------------------------------
    let mut rate = Table::new(
        "tradeoff-sample-rate",
        "Samples per slice (sample rate along the ray)",
        &[
            "samples per slice",
            "samples",
            ERR_COLUMNS[0],
            ERR_COLUMNS[1],
            ERR_COLUMNS[2],
        ],
    );
    let mut rate_pts = Vec::new();
    progress.start("sample rate", setup.samples_per_slice.len() as u64);
    for &r in &setup.samples_per_slice {
        let q = Quality {
            samples_per_slice: r,
            ..q0
        };
        let img = render_pipeline(vol, tf, &base, &q)?;
        let e = image_error(&img.image, &reference);
        let [a, m, x] = fmt_err(&e);
        rate.rows
            .push(vec![r.to_string(), img.stats.samples.to_string(), a, m, x]);
        rate_pts.push((img.stats.samples as f64, e.rel_euclid));
        progress.tick();
    }
    progress.finish();
    tables.push(rate);

    let mut term = Table::new(
        "tradeoff-early-termination",
        "Early-termination threshold (composite)",
        &[
            "threshold",
            "samples",
            "samples composited",
            ERR_COLUMNS[0],
            ERR_COLUMNS[1],
            ERR_COLUMNS[2],
            "PSNR vs no termination (dB)",
        ],
    );
    let no_term = render_pipeline(vol, tf, &base, &q0)?;
    let mut term_pts = Vec::new();
    progress.start("early termination", setup.thresholds.len() as u64);
    for &t in &setup.thresholds {
        let params = RenderParams {
            early_termination: t,
            ..base.clone()
        };
        let img = render_pipeline(vol, tf, &params, &q0)?;
        let e = image_error(&img.image, &reference);
        let [a, m, x] = fmt_err(&e);
        term.rows.push(vec![
            t.to_string(),
            img.stats.samples.to_string(),
            img.stats.composited.to_string(),
            a,
            m,
            x,
            fmt_err(&image_error(&img.image, &no_term.image))[0].clone(),
        ]);
        term_pts.push((img.stats.samples as f64, e.rel_euclid));
        progress.tick();
    }
    progress.finish();
    tables.push(term);
    figures.push(Figure {
        name: "tradeoff-samples".into(),
        title: "Error vs samples: sample rate and early termination".into(),
        x_label: "samples (millions)".into(),
        y_label: "rel. Euclidean error (%)".into(),
        series: vec![
            Series {
                name: "samples per slice 1, 2, ...".into(),
                points: rate_pts.iter().map(|&(x, y)| (x / 1e6, y)).collect(),
            },
            Series {
                name: "early termination thresholds".into(),
                points: term_pts.iter().map(|&(x, y)| (x / 1e6, y)).collect(),
            },
        ],
        marks: Vec::new(),
        log_x: false,
    });

    // ---- §6.1 interpolation schemes over view angles ---------------------------------------------
    let paper_tf = TransferFunction::preset("cube3-bone")?;
    let smoothed = smooth(vol);
    let mut interp = Table::new(
        "tradeoff-interpolation",
        "cube3-paper §6.1: interpolation schemes over rotation angles (relative Euclidean error, %)",
        &[
            "angle (deg)",
            "bilinear-slice vs image order",
            "sheared vs image order",
            "trilinear vs image order",
            "sheared vs trilinear (True3D)",
            "sheared vs image order, mean over full scale",
            "sheared vs True3D, mean over full scale",
            "smoothed: sheared vs image order",
            "smoothed: sheared vs True3D",
            "sheared offset",
            "samples (sheared)",
        ],
    );
    let mut curves: Vec<Vec<(f64, f64)>> = vec![Vec::new(); 6];
    let mut full_scale = [0.0f64; 2];
    progress.start("interpolation over angles", setup.angles.len() as u64);
    for &angle in &setup.angles {
        let params = RenderParams {
            view: View {
                azimuth: angle,
                elevation: setup.paper_elevation,
            },
            direction: None,
            step: setup.paper_step,
            mode: CompositeMode::Composite,
            shading: true,
            ..base.clone()
        };
        let render = |v: &Volume, scheme| {
            let q = Quality {
                interpolation: scheme,
                gradient: GradientScheme::Ten,
                ..Quality::precise()
            };
            render_pipeline(v, &paper_tf, &params, &q)
        };
        let reference = render_reference(vol, &paper_tf, &params)?;
        let bilinear = render(vol, Interpolation::BilinearSlice)?;
        let sheared = render(vol, Interpolation::Sheared)?;
        let trilinear = render(vol, Interpolation::Trilinear)?;
        let s_reference = render_reference(&smoothed, &paper_tf, &params)?;
        let s_sheared = render(&smoothed, Interpolation::Sheared)?;
        let s_trilinear = render(&smoothed, Interpolation::Trilinear)?;
        let e_sheared = image_error(&sheared.image, &reference);
        let e_st_full = image_error(&sheared.image, &trilinear.image).full_scale_euclid;
        full_scale[0] = full_scale[0].max(e_sheared.full_scale_euclid);
        full_scale[1] = full_scale[1].max(e_st_full);
        let values = [
            image_error(&bilinear.image, &reference).rel_euclid,
            e_sheared.rel_euclid,
            image_error(&trilinear.image, &reference).rel_euclid,
            image_error(&sheared.image, &trilinear.image).rel_euclid,
            image_error(&s_sheared.image, &s_reference).rel_euclid,
            image_error(&s_sheared.image, &s_trilinear.image).rel_euclid,
        ];
        for (c, v) in curves.iter_mut().zip(values) {
            c.push((angle, v));
        }
        interp.rows.push(vec![
            format!("{angle}"),
            format!("{:.3}", values[0]),
            format!("{:.3}", values[1]),
            format!("{:.3}", values[2]),
            format!("{:.3}", values[3]),
            format!("{:.3}", e_sheared.full_scale_euclid),
            format!("{:.3}", e_st_full),
            format!("{:.3}", values[4]),
            format!("{:.3}", values[5]),
            format!("{}", sheared.stats.offset),
            sheared.stats.samples.to_string(),
        ]);
        progress.tick();
    }
    progress.finish();
    let peak = |c: &Vec<(f64, f64)>| {
        c.iter().copied().fold(
            (0.0, f64::NEG_INFINITY),
            |m, p| if p.1 > m.1 { p } else { m },
        )
    };
    let (p_raw, p_smooth) = (peak(&curves[1]), peak(&curves[4]));
    let largest = |c: &Vec<(f64, f64)>| c.iter().map(|p| p.1).fold(0.0, f64::max);
    let paper_61 = [
        p_raw.1,
        largest(&curves[3]),
        p_raw.0,
        p_smooth.1,
        largest(&curves[5]),
        p_smooth.0,
    ];
    tables.push(interp);
    let names = [
        "bilinear-slice vs image order",
        "sheared vs image order",
        "trilinear vs image order",
        "sheared vs trilinear (True3D)",
        "smoothed: sheared vs image order",
        "smoothed: sheared vs True3D",
    ];
    figures.push(Figure {
        name: "tradeoff-interpolation".into(),
        title: "cube3-paper 6.1: interpolation error over rotation angle".into(),
        x_label: "rotation angle (degrees)".into(),
        y_label: "rel. Euclidean error (%)".into(),
        series: names
            .iter()
            .zip(&curves)
            .map(|(n, c)| Series {
                name: n.to_string(),
                points: c.clone(),
            })
            .collect(),
        marks: vec![
            (
                PAPER_VS_IMAGE_ORDER,
                "paper: sheared vs VolRen < 1.3%".into(),
            ),
            (PAPER_VS_TRUE3D, "paper: sheared vs True3D < 0.3%".into()),
        ],
        log_x: false,
    });

    // ---- §6.2 gradient schemes on a voxelized sphere ---------------------------------------------
    let mut grad = Table::new(
        "tradeoff-gradient",
        "cube3-paper §6.2: mean angular error of the gradient on a voxelized sphere (degrees)",
        &[
            "angle (deg)",
            "6-nbhd",
            "10-nbhd",
            "26-nbhd",
            "6-nbhd (v12)",
            "10-nbhd (v12)",
            "26-nbhd (v12)",
            "surface points",
        ],
    );
    let gschemes = [
        GradientScheme::Six,
        GradientScheme::Ten,
        GradientScheme::TwentySix,
    ];
    let mut gcurves: Vec<Vec<(f64, f64)>> = vec![Vec::new(); 3];
    let sphere = sphere_phantom(setup.sphere_size, 12)?;
    let geometry = SphereGeometry::for_size(setup.sphere_size);
    progress.start("gradients over angles", setup.angles.len() as u64);
    for &angle in &setup.angles {
        let mut row = vec![format!("{angle}")];
        let mut points = 0;
        let mut fixed = Vec::new();
        for (si, &scheme) in gschemes.iter().enumerate() {
            let precise = sphere_gradient_error(&sphere, &geometry, angle, scheme, true)?;
            let v12 = sphere_gradient_error(&sphere, &geometry, angle, scheme, false)?;
            row.push(format!("{:.2}", precise.0));
            fixed.push(format!("{:.2}", v12.0));
            gcurves[si].push((angle, precise.0));
            points = precise.1;
        }
        row.extend(fixed);
        row.push(points.to_string());
        grad.rows.push(row);
        progress.tick();
    }
    progress.finish();
    tables.push(grad);
    let at = |c: &Vec<(f64, f64)>, a: f64| {
        c.iter()
            .find(|p| (p.0 - a).abs() < 1e-9)
            .map_or(f64::NAN, |p| p.1)
    };
    let paper_62 = std::array::from_fn(|s| {
        [
            at(&gcurves[s], 0.0),
            at(&gcurves[s], 45.0),
            gcurves[s].iter().map(|p| p.1).fold(0.0, f64::max),
        ]
    });
    figures.push(Figure {
        name: "tradeoff-gradient".into(),
        title: "cube3-paper 6.2: gradient angular error on a voxelized sphere".into(),
        x_label: "rotation angle (degrees)".into(),
        y_label: "mean angular error (degrees)".into(),
        series: ["6-neighbourhood", "10-neighbourhood", "26-neighbourhood"]
            .iter()
            .zip(&gcurves)
            .map(|(n, c)| Series {
                name: n.to_string(),
                points: c.clone(),
            })
            .collect(),
        marks: Vec::new(),
        log_x: false,
    });

    // ---- perspective by parallel slabs (what-if) -------------------------------------------------
    let persp = RenderParams {
        projection: Projection::Perspective,
        fov: 40.0,
        ..base.clone()
    };
    let persp_reference = render_reference(vol, tf, &persp)?;
    let mut slab_table = Table::new(
        "tradeoff-slabs",
        "Perspective by parallel slabs (what-if): error against the f64 perspective reference",
        &[
            "slabs",
            "spacing",
            ERR_COLUMNS[0],
            ERR_COLUMNS[1],
            ERR_COLUMNS[2],
        ],
    );
    let spacings = [SlabSpacing::Equal, SlabSpacing::Geometric];
    progress.start(
        "slab perspective",
        (spacings.len() * setup.slab_counts.len()) as u64,
    );
    let mut slab_series = Vec::new();
    for spacing in spacings {
        let mut pts = Vec::new();
        for &count in &setup.slab_counts {
            let img = render_slabs(vol, tf, &persp, Slabs { count, spacing })?;
            let e = image_error(&img, &persp_reference);
            let [a, m, r] = fmt_err(&e);
            slab_table
                .rows
                .push(vec![count.to_string(), spacing.name().into(), a, m, r]);
            if e.psnr_db.is_finite() {
                pts.push((f64::from(count), e.psnr_db));
            }
            progress.tick();
        }
        slab_series.push(Series {
            name: format!("{} slabs", spacing.name()),
            points: pts,
        });
    }
    progress.finish();
    tables.push(slab_table);
    figures.push(Figure {
        name: "tradeoff-slabs".into(),
        title: "Perspective by parallel slabs: PSNR against the f64 perspective".into(),
        x_label: "slabs".into(),
        y_label: "PSNR (dB)".into(),
        series: slab_series,
        marks: Vec::new(),
        log_x: true,
    });

    // ---- ER-perspective -----------------------------------------------------------------------
    let (er_table, er_figure) = er_sweep(setup, &persp, progress)?;
    tables.push(er_table);
    figures.push(er_figure);
    let _ = vb0;
    Ok(Report {
        tables,
        figures,
        paper_61,
        paper_61_full_scale: full_scale,
        paper_62,
        synth_found: setup.synth.is_some(),
    })
}

/// The volume filtered with `[1 2 1] / 4` along each axis (zero outside), rounded: a stand-in for
/// a CT scanner's point-spread function, which the hard-edged phantoms lack.
pub fn smooth(vol: &Volume) -> Volume {
    let [nx, ny, nz] = vol.dims;
    let mut cur: Vec<f64> = vol.data.iter().map(|&v| f64::from(v)).collect();
    let strides = [1, nx, nx * ny];
    for (axis, &stride) in strides.iter().enumerate() {
        let n = vol.dims[axis];
        let prev = cur.clone();
        cur.par_iter_mut().enumerate().for_each(|(i, out)| {
            let c = (i / stride) % n;
            let left = if c > 0 { prev[i - stride] } else { 0.0 };
            let right = if c + 1 < n { prev[i + stride] } else { 0.0 };
            *out = (left + 2.0 * prev[i] + right) / 4.0;
        });
    }
    let _ = nz;
    let data = cur.iter().map(|v| v.round() as u16).collect();
    Volume {
        dims: vol.dims,
        spacing: vol.spacing,
        bits: vol.bits,
        data,
    }
}

/// cube3-paper §6.2 at one rotation angle: rays of the slice-order frame (viewing along the
/// rotated x axis, samples at the sheared scheme's offset, exact 8-neighbourhood interpolation)
/// stop at the first sample above density 0.5; there the `cube5_gradient` model estimates the
/// gradient from the 3x3x3 block of ray samples, and the angle to the sphere's analytic normal is
/// averaged over all such surface points. `precise`: `U(16.8)` samples and the unit's f64
/// reference arithmetic; otherwise the default `v12` configuration, bit-accurate.
/// Returns (mean angle in degrees, number of surface points).
pub fn sphere_gradient_error(
    sphere: &Volume,
    g: &SphereGeometry,
    angle: f64,
    scheme: GradientScheme,
    precise: bool,
) -> Result<(f64, usize)> {
    let a = angle.to_radians();
    let dir = DVec3::new(a.cos(), a.sin(), 0.0);
    let setup = SliceSetup::new(sphere, dir)?;
    let (tc, gc) = if precise {
        (
            TrilinConfig::new(16, 12, 8)?,
            GradientConfig::new(16, 8, 12)?,
        )
    } else {
        (TrilinConfig::DEFAULT, GradientConfig::DEFAULT)
    };
    let trilin = Trilin::new(tc)?;
    let unit = Gradient::new(gc)?;
    let [ni, nj, nk] = setup.n;
    let [ai, aj, ak] = setup.axes;
    let (dx, dy) = (setup.dx(), setup.dy());
    let offset = setup.offset(Interpolation::Sheared, tc.weight_w);
    let shift = STEP_W - tc.weight_w;
    let gdx = (f64::from(setup.dx_raw) / f64::from(1u32 << shift)).round() as i32;
    let gdy = (f64::from(setup.dy_raw) / f64::from(1u32 << shift)).round() as i32;
    let scale = f64::from((1u32 << tc.voxel_w) - 1) / f64::from(sphere.max_value());
    let to_vol = |x: f64, y: f64, t: f64| {
        let mut p = [0.0; 3];
        p[ai] = x;
        p[aj] = y;
        p[ak] = if setup.k_reversed {
            (nk - 1) as f64 - t
        } else {
            t
        };
        p
    };
    let one = f64::from(1u32 << tc.weight_w);
    let weight = |f: f64| ((f * one).floor() as u32).min((1 << tc.weight_w) - 1);
    // Exact 8-neighbourhood sample of the ray through (ra, rb) at depth t, raw U(VoxelW.FracW).
    let sample = |ra: f64, rb: f64, t: f64| -> u32 {
        let (x, y) = (ra + t * dx, rb + t * dy);
        let base = [x.floor(), y.floor(), t.floor()];
        let f = [x - base[0], y - base[1], t - base[2]];
        let mut voxels = [0u32; 8];
        for (c, v) in voxels.iter_mut().enumerate() {
            let p = to_vol(
                base[0] + (c & 1) as f64,
                base[1] + ((c >> 1) & 1) as f64,
                base[2] + (c >> 2) as f64,
            );
            let raw = sphere.get(p[0] as i64, p[1] as i64, p[2] as i64);
            *v = (f64::from(raw) * scale).round() as u32;
        }
        trilin.sample(&TrilinIn {
            voxels,
            weights: f.map(weight),
            mode: TrilinMode::Lerp,
        })
    };
    let threshold = (0.5 * f64::from(tc.voxel_max()) * f64::from(1u32 << tc.frac_w)) as u32;
    let offsets = scheme.offsets(gdx, gdy);
    let results: Vec<f64> = (0..ni * nj)
        .into_par_iter()
        .filter_map(|idx| {
            let (ra, rb) = ((idx % ni) as f64, (idx / ni) as f64);
            let mut m = 0usize;
            loop {
                let t = m as f64 + offset;
                if t > (nk - 1) as f64 {
                    return None;
                }
                let s = sample(ra, rb, t);
                if s > threshold {
                    let mut block = [0u32; 27];
                    for &(di, dj, dk) in &offsets {
                        block[block_index(di, dj, dk)] =
                            sample(ra + f64::from(di), rb + f64::from(dj), t + f64::from(dk));
                    }
                    let item = GradientIn {
                        samples: block,
                        dx: gdx,
                        dy: gdy,
                        mode: scheme.mode(),
                    };
                    let gv = if precise {
                        unit.reference(&item).g
                    } else {
                        unit.components(&item).map(|v| v as f64)
                    };
                    let mut gw = DVec3::ZERO;
                    gw[ai] = gv[0];
                    gw[aj] = gv[1];
                    gw[ak] = if setup.k_reversed { -gv[2] } else { gv[2] };
                    if gw.length() < 1e-12 {
                        return Some(90.0);
                    }
                    let p = to_vol(ra + t * dx, rb + t * dy, t);
                    let n = DVec3::from_array(g.normal(p));
                    // The density falls outward: the outward normal is minus the gradient.
                    let c = (-gw.normalize()).dot(n).clamp(-1.0, 1.0);
                    return Some(c.acos().to_degrees());
                }
                m += 1;
            }
        })
        .collect();
    if results.is_empty() {
        return Err(ModelError::Volume(
            "sphere phantom: no ray met the surface".into(),
        ));
    }
    Ok((
        results.iter().sum::<f64>() / results.len() as f64,
        results.len(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use cube5_model::phantom::head_phantom;

    #[test]
    fn synth_table_joins_variants() {
        let area = "| top | config | generic cells | ECP5 LUT4 |\n|---|---|---:|---:|\n\
                    | cube5_trilin | v8 | 3716 | 54 |\n| cube5_trilin | v12 | 7194 | 66 |\n";
        let variants = vec![(
            "cube5_trilin".to_string(),
            "# c\nv8 gate VoxelW=8 WeightW=6 FracW=2\nv12 fmax VoxelW=12 WeightW=8 FracW=4\n"
                .to_string(),
        )];
        let s = Synth::parse(area, &variants);
        assert_eq!(s.rows.len(), 2);
        let r = s
            .find(
                "cube5_trilin",
                &[("VoxelW", 12), ("WeightW", 8), ("FracW", 4)],
            )
            .unwrap();
        assert_eq!(r.figures["generic cells"], "7194");
        assert!(s.find("cube5_trilin", &[("VoxelW", 10)]).is_none());
        assert!(s
            .cells(&Quality::default(), 12)
            .contains("trilin v12: 7194"));
    }

    #[test]
    fn gradient_schemes_on_the_sphere() {
        let n = 24;
        let sphere = sphere_phantom(n, 12).unwrap();
        let g = SphereGeometry::for_size(n);
        let e = |a, s| sphere_gradient_error(&sphere, &g, a, s, true).unwrap().0;
        // Axis aligned, the schemes see orthogonal neighbours: small error for all.
        for s in [
            GradientScheme::Six,
            GradientScheme::Ten,
            GradientScheme::TwentySix,
        ] {
            assert!(e(0.0, s) < 5.0, "{s:?}");
        }
        // At 30 degrees the slanted 6-neighbourhood is worse than the resampled 10-neighbourhood.
        assert!(e(30.0, GradientScheme::Six) > e(30.0, GradientScheme::Ten));
    }

    #[test]
    fn tiny_sweep_runs() {
        let vol = head_phantom(16, 12).unwrap();
        let params = RenderParams {
            width: 16,
            height: 16,
            ..RenderParams::default()
        };
        let mut setup = Setup::tiny(
            vol,
            TransferFunction::head_default(),
            params,
            Quality::default(),
        );
        setup.sphere_size = 16;
        let report = run(&setup, &Quiet).unwrap();
        assert_eq!(report.tables.len(), 8);
        assert_eq!(report.figures.len(), 6);
        let er = report
            .tables
            .iter()
            .find(|t| t.name == "tradeoff-er")
            .unwrap();
        assert_eq!(er.rows.len(), 4, "2 fields of view x 2 merges");
        let slabs = report
            .tables
            .iter()
            .find(|t| t.name == "tradeoff-slabs")
            .unwrap();
        assert_eq!(slabs.rows.len(), 4, "2 counts x 2 spacings");
        assert!(report.tables.iter().all(|t| !t.rows.is_empty()));
        // At exactly 45 degrees sheared and full tri-linear agree (the offset is zero).
        let interp = &report.tables[4];
        let row45 = interp.rows.iter().find(|r| r[0] == "45").unwrap();
        assert_eq!(row45[4], "0.000");
    }
}
