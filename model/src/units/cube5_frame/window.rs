//! The compositing window (`docs/numerics/compos_window.md`; issue 12, the accelerator): the frame
//! swept in sections (`sections`) with only the coxels of the active rays on chip. In section
//! `[A0, A0 + ns)` at slice `s` the samples land in base-plane pixels
//! `R in [A0 + offx(s), A0 + ns + offx(s))`, `Q in [offy(s), offy(s) + nj)`
//! (`offx(s) = max sx - sx(s)`, likewise `y`): the *active* pixels. A pixel that stops being
//! active leaves the window: *parked* (its exact partial coxel to DRAM) when a later slice or
//! section will take a sample into it again, *final* (it goes out as an image pixel) when not. A
//! pixel that becomes active enters the window: *restored* (its parked coxel read back) or *fresh*
//! (the initial coxel, no read) when nothing reached it yet. Coxels move, never change, so with
//! the sections in sweep order ([`section_order`]) the image is the whole-plane frame's, bit for
//! bit, for every section width; [`render_window`] renders that way and counts the traffic.

use super::sections::{section_beats, Section, SectionVoxels};
use super::{BasePlane, FrameParams, FrameUnits};
use crate::error::{ModelError, Result};
use crate::units::cube5_compos::Coxel;
use crate::volume::Volume;

/// What moved between the window and DRAM in one frame, in coxels (pixels).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WindowTraffic {
    /// Partial coxels written to DRAM on leaving the window (a later sample will need them).
    pub parked: u64,
    /// Partial coxels read back on entering the window (every parked one, exactly once).
    pub restored: u64,
    /// Coxels that entered the window for the first time (the initial coxel: no read).
    pub fresh: u64,
    /// Pixels that left the window final, during the sweep or at a section's end.
    pub final_out: u64,
    /// Pixels no sample reaches (the initial coxel; written with the image).
    pub untouched: u64,
    /// Most coxels on chip at once: the active pixels of two consecutive slices of a section
    /// (the leaving ones wait for their last write-back while the entering ones are read).
    pub max_window: usize,
    /// Most coxels leaving the window at one slice change inside a section (a column and a row).
    pub max_moves: usize,
    /// Pixels final (out of the window for good) at the end of each section, cumulative, in the
    /// sweep's order.
    pub final_after: Vec<u64>,
    /// Pixels still in the window when the last section's sweep ends: the only ones whose
    /// read-out cannot overlap the sweep (at most `ns nj`).
    pub left_at_end: u64,
    /// The three streams of the window, in the order the RTL (`cube5_frame` `Window = 1`)
    /// emits them (docs/numerics/compos_window.md, *Order of the streams*).
    pub streams: WindowStreams,
}

/// A pixel `(R, Q)` and its coxel, as it leaves the window.
pub type PixelCoxel = (usize, usize, Coxel);

/// What crosses the window's edge, in order: within a step the pixels in row-major order of
/// their base-plane position (`Q` outer, `R` inner), the steps in sweep order. The leaving
/// pixels of a step follow the step's samples (their last write-back), the restores of a step
/// are requested before it (its first samples take them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WindowStreams {
    /// Parked coxels (partial: a later step samples the pixel again).
    pub parked: Vec<PixelCoxel>,
    /// Final pixels (no later sample), the image's pixels but the untouched ones.
    pub finals: Vec<PixelCoxel>,
    /// Restore requests `(R, Q)`: the coxel parked for that pixel comes back, in this order.
    pub restores: Vec<(usize, usize)>,
}

/// The active pixels of section `sec` at slice `s`: columns, rows.
fn active(
    params: &FrameParams,
    sec: &Section,
    s: usize,
) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
    let (r0, q0) = params.pixel_of(&params.slice(s), sec.a0, 0);
    (r0..r0 + sec.ns, q0..q0 + params.nj)
}

/// Every active pixel of `sec` at slice `s`, as the index `Q W + R`.
fn active_pixels(params: &FrameParams, w: usize, sec: &Section, s: usize) -> Vec<usize> {
    let (rs, qs) = active(params, sec, s);
    qs.flat_map(|q| rs.clone().map(move |r| q * w + r))
        .collect()
}

/// The base plane rendered section by section in `order` through a compositing window: only the
/// active pixels' coxels on chip, the rest parked in DRAM (exact partial coxels) or out as final
/// pixels; each section from its own beats. With [`super::sections::section_order`]'s order it
/// is the frame's image for every section width. Refused: an order that leaves a parked coxel
/// never restored (impossible in sweep order).
pub fn render_window(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
    order: &[Section],
    p: usize,
) -> Result<(BasePlane, WindowTraffic)> {
    let (w, h) = params.base_plane_size();
    let nk = params.nk;
    let empty = units.initial_coxel();
    // The last step (section n, slice s: n nk + s) that takes a sample into each pixel.
    let mut last = vec![None::<usize>; w * h];
    for (n, sec) in order.iter().enumerate() {
        for s in 0..nk {
            for i in active_pixels(params, w, sec, s) {
                last[i] = Some(n * nk + s);
            }
        }
    }
    let mut t = WindowTraffic {
        untouched: last.iter().filter(|l| l.is_none()).count() as u64,
        ..WindowTraffic::default()
    };
    let mut dram: Vec<Option<Coxel>> = vec![None; w * h];
    let mut image: Vec<Option<Coxel>> = vec![None; w * h];
    let mut chip: Vec<Option<Coxel>> = vec![None; w * h];
    let mut on: Vec<usize> = Vec::new();
    let mut now_mark = vec![false; w * h];
    // A coxel leaving after step `step`: final when that was its last, else parked.
    let leave = |i: usize,
                 step: usize,
                 chip: &mut [Option<Coxel>],
                 dram: &mut [Option<Coxel>],
                 image: &mut [Option<Coxel>],
                 t: &mut WindowTraffic| {
        let c = chip[i].take();
        let (r, q) = (i % w, i / w);
        if last[i] == Some(step) {
            if let Some(x) = c {
                t.streams.finals.push((r, q, x));
            }
            image[i] = c;
            t.final_out += 1;
        } else {
            if let Some(x) = c {
                t.streams.parked.push((r, q, x));
            }
            dram[i] = c;
            t.parked += 1;
        }
    };
    for (n, sec) in order.iter().enumerate() {
        let data = SectionVoxels::from_beats(params, *sec, &section_beats(params, vol, *sec, p))?;
        let mut prev: Vec<usize> = Vec::new();
        for s in 0..nk {
            let now = active_pixels(params, w, sec, s);
            for &i in &now {
                now_mark[i] = true;
            }
            let entering = now.iter().filter(|&&i| chip[i].is_none()).count();
            t.max_window = t.max_window.max(on.len() + entering);
            if s > 0 {
                // The previous step's pixels in row-major order: those not active now leave.
                let before = on.len();
                for &i in &prev {
                    if !now_mark[i] {
                        leave(i, n * nk + s - 1, &mut chip, &mut dram, &mut image, &mut t);
                    }
                }
                on.retain(|&i| now_mark[i]);
                t.max_moves = t.max_moves.max(before - on.len());
            }
            for &i in &now {
                now_mark[i] = false;
                if chip[i].is_none() {
                    chip[i] = Some(match dram[i].take() {
                        Some(c) => {
                            t.restored += 1;
                            t.streams.restores.push((i % w, i / w));
                            c
                        }
                        None => {
                            t.fresh += 1;
                            empty
                        }
                    });
                    on.push(i);
                }
            }
            prev = now;
            let c = params.slice(s);
            for b in 0..params.nj {
                for a in sec.a0..sec.a0 + sec.ns {
                    let smp = data.shaded(params, units, &c, a, b);
                    let (r, q) = params.pixel_of(&c, a, b);
                    let i = q * w + r;
                    let cox = chip[i].as_ref().ok_or_else(|| {
                        ModelError::Config(format!(
                            "compositing window: pixel ({r}, {q}) not on chip"
                        ))
                    })?;
                    chip[i] = Some(units.compos.step(cox, &smp));
                }
            }
        }
        // The section's end: every coxel leaves the window.
        t.left_at_end = on.len() as u64;
        on.clear();
        for i in std::mem::take(&mut prev) {
            leave(i, n * nk + nk - 1, &mut chip, &mut dram, &mut image, &mut t);
        }
        t.final_after.push(t.final_out);
    }
    if dram.iter().any(Option::is_some) {
        return Err(ModelError::Config(
            "compositing window: a parked coxel was never restored (sections out of sweep order)"
                .into(),
        ));
    }
    Ok((
        BasePlane {
            width: w,
            height: h,
            coxels: image.into_iter().map(|c| c.unwrap_or(empty)).collect(),
        },
        t,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::TransferFunction;
    use crate::units::cube5_frame::sections::section_order;
    use crate::units::cube5_frame::{frame_phong, render_base_plane, FrameMode, FrameSetup};
    use glam::DVec3;

    fn units(setup: &FrameSetup, mode: FrameMode) -> FrameUnits {
        let tf = TransferFunction::head_default();
        FrameUnits::new(mode, setup, &tf, &frame_phong(&setup.params, &[])).unwrap()
    }

    /// The window's image is the whole-plane frame's, bit for bit, for every section width (P to
    /// the whole face, a narrower last section), MIP and composite, the six faces, 45 degrees
    /// both ways and obliques with DX > 0 and DX < 0; every parked coxel comes back exactly once;
    /// on chip at most (ns + 1)(nj + 1) coxels, at most a column and a row (nj + ns) leave per
    /// slice; every pixel leaves final exactly once.
    #[test]
    fn the_window_changes_no_bit_and_parks_what_it_restores() {
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        let mut parked_any = false;
        for v in super::super::sections::test_views() {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
            let params = setup.params;
            for mode in [FrameMode::Mip, FrameMode::Composite, FrameMode::Minip] {
                let u = units(&setup, mode);
                let want = render_base_plane(&params, &vol, &u);
                for s in [4, 8, 16, params.ni] {
                    let order = section_order(&params, s, 4).unwrap();
                    let (got, t) = render_window(&params, &vol, &u, &order, 4).unwrap();
                    assert!(
                        got == want,
                        "{mode:?} view {v:?} S = {s}: the image changed"
                    );
                    assert_eq!(t.parked, t.restored, "view {v:?} S = {s}");
                    let st = &t.streams;
                    assert_eq!(st.parked.len() as u64, t.parked);
                    assert_eq!(st.finals.len() as u64, t.final_out);
                    // Restores come back in the order they were parked (a FIFO in DRAM would do).
                    let parked: Vec<(usize, usize)> =
                        st.parked.iter().map(|&(r, q, _)| (r, q)).collect();
                    assert_eq!(parked, st.restores, "view {v:?} S = {s}: restore order");
                    assert_eq!(
                        t.final_out + t.untouched,
                        (want.width * want.height) as u64,
                        "view {v:?} S = {s}: every pixel out once"
                    );
                    assert!(
                        t.max_window <= (s + 1) * (params.nj + 1),
                        "view {v:?} S = {s}: {} coxels on chip",
                        t.max_window
                    );
                    assert!(
                        t.max_moves <= s + params.nj,
                        "view {v:?} S = {s}: {} coxels left at once",
                        t.max_moves
                    );
                    assert!(t.left_at_end <= (order[order.len() - 1].ns * params.nj) as u64);
                    if params.dx == 0 && s < params.ni {
                        // No ray crosses a section boundary along i.
                        assert_eq!(t.parked, 0, "view {v:?} S = {s}");
                    }
                    parked_any |= t.parked > 0;
                }
            }
        }
        assert!(parked_any, "no view parked a coxel");
    }

    /// Out of sweep order the window would need a parked coxel before it is written: refused or
    /// a different image, never silently the same traffic.
    #[test]
    fn against_the_sweep_the_window_cannot_keep_the_order() {
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::new(0.6, 0.2, 1.0), 4).unwrap();
        let u = units(&setup, FrameMode::Composite);
        let want = render_base_plane(&setup.params, &vol, &u);
        let mut order = section_order(&setup.params, 8, 4).unwrap();
        order.reverse();
        match render_window(&setup.params, &vol, &u, &order, 4) {
            Ok((got, _)) => assert!(got != want, "the wrong order left the image unchanged"),
            Err(e) => assert!(e.to_string().contains("never restored"), "{e}"),
        }
    }

    /// The figures of docs/numerics/compos_window.md: 64^3 head, P = 4, S = 32 and 64, a face,
    /// 45 degrees and an oblique.
    #[test]
    #[ignore = "figures for the docs (64^3 frames in the model, a few seconds in release)"]
    fn window_traffic_figures() {
        let vol = crate::phantom::head_phantom(64, 12).unwrap();
        for v in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.37, 0.81, -1.0],
        ] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
            let params = setup.params;
            let u = units(&setup, FrameMode::Composite);
            for s in [16, 32, 64] {
                let order = section_order(&params, s, 4).unwrap();
                let (_, t) = render_window(&params, &vol, &u, &order, 4).unwrap();
                let (w, h) = params.base_plane_size();
                eprintln!(
                    "FIG view {v:?} S = {s}: W x H {w} x {h}, samples {}, parked {} ({:.4} per sample), fresh {}, final {} (before the last section {}, in the window at the end {}), untouched {}, window max {} coxels, moves max {}",
                    params.samples(),
                    t.parked,
                    t.parked as f64 / params.samples() as f64,
                    t.fresh,
                    t.final_out,
                    t.final_after.iter().rev().nth(1).copied().unwrap_or(0),
                    t.left_at_end,
                    t.untouched,
                    t.max_window,
                    t.max_moves
                );
            }
        }
    }
}
