//! The frame swept in sections (`docs/numerics/frame.md`, "Sections"; issue 12, the accelerator):
//! the face is cut along `i` into sections of `S` anchors, each section is swept through all its
//! slices before the next one starts, and the compositing buffer keeps the whole base plane. Left
//! to right when `DX >= 0`, right to left when `DX < 0`, every ray still takes its samples in slice
//! order, so the image is the frame's, bit for bit.
//!
//! A section sees only its beams and, beside each row's first and last beat, the edge voxels `lo`
//! (column `A0 - 1`), `hi0`, `hi1` (`A0 + ns`, `A0 + ns + 1`): [`section_beats`] is that stream
//! (the order `cube5_section_buf` delivers), and [`render_sections`] renders from those beats
//! alone, the samples and gradients at a section's edges included.

use super::{volume_voxels, BasePlane, FrameParams, FrameUnits, SliceConst};
use crate::error::{ModelError, Result};
use crate::units::cube5_section_buf::Beam;
use crate::volume::Volume;

/// One section: anchors `a0 .. a0 + ns` along `i`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Section {
    pub a0: usize,
    pub ns: usize,
}

/// The sections of width `width` of a face, in the order that keeps every ray's samples in slice
/// order: left to right for `DX >= 0`, right to left for `DX < 0`. The last section (in `i`) is
/// narrower when `width` does not divide `ni`. Refused: `width` 0 or not a multiple of `p`.
pub fn section_order(params: &FrameParams, width: usize, p: usize) -> Result<Vec<Section>> {
    if width == 0 || p == 0 || !width.is_multiple_of(p) {
        return Err(ModelError::Config(format!(
            "frame sections: width {width} must be a positive multiple of P = {p}"
        )));
    }
    let mut v: Vec<Section> = (0..params.ni)
        .step_by(width)
        .map(|a0| Section {
            a0,
            ns: width.min(params.ni - a0),
        })
        .collect();
    if params.dx < 0 {
        v.reverse();
    }
    Ok(v)
}

/// The beats of one section in the frame's order (slice `s`, row `b`, beat `m`): `P` voxels at
/// `i = a0 + P m ..`, `lo` (voxel `a0 - 1`) on a row's first beat, `hi0`, `hi1` (voxels
/// `a0 + ns`, `a0 + ns + 1`) on its last, each zero outside `0 .. ni` and on the other beats, and
/// the marks of `cube5_section_buf`'s beams.
pub fn section_beats(params: &FrameParams, vol: &Volume, sec: Section, p: usize) -> Vec<Beam> {
    let nbr = sec.ns / p;
    let mut out = Vec::with_capacity(params.nk * params.nj * nbr);
    let voxel = volume_voxels(params, vol);
    for s in 0..params.nk {
        for b in 0..params.nj {
            for m in 0..nbr {
                let (first, last) = (m == 0, m + 1 == nbr);
                // Zero outside the face.
                let at = |i: i64| if i < 0 { 0 } else { voxel(s, i as usize, b) };
                let a = (sec.a0 + p * m) as i64;
                let e = (sec.a0 + sec.ns) as i64;
                out.push(Beam {
                    lanes: (0..p as i64).map(|l| at(a + l)).collect(),
                    lo: if first { at(sec.a0 as i64 - 1) } else { 0 },
                    hi0: if last { at(e) } else { 0 },
                    hi1: if last { at(e + 1) } else { 0 },
                    row_first: first,
                    row_last: last,
                    slice_last: last && b + 1 == params.nj,
                    last: last && b + 1 == params.nj && s + 1 == params.nk,
                    error: false,
                });
            }
        }
    }
    out
}

/// What a section's sweep knows: its beats' voxels, columns `a0 - 1 ..= a0 + ns + 1` of every row
/// of every slice (from the beats alone; zero where the stream carries nothing).
#[derive(Debug, Clone)]
pub struct SectionVoxels {
    pub sec: Section,
    nj: usize,
    /// `(s nj + b) (ns + 3) + (i - a0 + 1)`.
    cols: Vec<u32>,
}

impl SectionVoxels {
    /// Gathers a section's voxels from its beats (`nk nj ns / P` of them, in the frame's order).
    pub fn from_beats(params: &FrameParams, sec: Section, beats: &[Beam]) -> Result<Self> {
        let w = sec.ns + 3;
        let p = beats.first().map_or(1, |b| b.lanes.len()).max(1);
        let nbr = sec.ns / p;
        if nbr == 0 || beats.len() != params.nk * params.nj * nbr {
            return Err(ModelError::Config(format!(
                "frame sections: {} beats for a section of {} anchors, {} rows, {} slices",
                beats.len(),
                sec.ns,
                params.nj,
                params.nk
            )));
        }
        let mut cols = vec![0u32; params.nk * params.nj * w];
        for (t, beat) in beats.iter().enumerate() {
            let (row, m) = (t / nbr, t % nbr);
            let base = row * w;
            for (l, &v) in beat.lanes.iter().enumerate() {
                cols[base + 1 + p * m + l] = v;
            }
            if m == 0 {
                cols[base] = beat.lo;
            }
            if m + 1 == nbr {
                cols[base + 1 + sec.ns] = beat.hi0;
                cols[base + 2 + sec.ns] = beat.hi1;
            }
        }
        Ok(Self {
            sec,
            nj: params.nj,
            cols,
        })
    }

    /// Voxel `(i, j)` of slice `s`: `i` in `a0 - 1 ..= a0 + ns + 1`; rows past the face read 0.
    fn voxel(&self, s: usize, i: i64, j: usize) -> u32 {
        let (a0, w) = (self.sec.a0 as i64, self.sec.ns + 3);
        debug_assert!(i >= a0 - 1 && i <= a0 + self.sec.ns as i64 + 1);
        if j >= self.nj {
            return 0;
        }
        self.cols[(s * self.nj + j) * w + (i - a0 + 1) as usize]
    }

    /// This section's voxels as [`super::sample_at`] reads them: `(t, i, j)` is voxel `(i, j)` of
    /// slice `t`, `i` in `a0 - 1 ..= a0 + ns + 1` (the anchors `a0 - 1 ..= a0 + ns`).
    pub fn voxels(&self) -> impl Fn(usize, usize, usize) -> u32 + '_ {
        |t, i, j| self.voxel(t, i as i64, j)
    }

    /// The shaded sample at anchor `(a, b)` of slice `c` (an anchor of this section) that the
    /// compositing unit takes, from the section's own voxels ([`FrameUnits::shaded_from`]).
    pub fn shaded(
        &self,
        params: &FrameParams,
        units: &FrameUnits,
        c: &SliceConst,
        a: usize,
        b: usize,
    ) -> crate::units::cube5_compos::Sample {
        units.shaded_from(params, c, (a, b), &self.voxels())
    }
}

/// The base plane rendered section by section in `order`, each section from its own beats
/// ([`section_beats`] of `vol`) only, into one compositing buffer of the whole base plane. With
/// the order of [`section_order`] it is the frame's image, bit for bit; another order breaks the
/// slice order of the rays that cross a section boundary.
pub fn render_sections(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
    order: &[Section],
    p: usize,
) -> Result<BasePlane> {
    let (w, h) = params.base_plane_size();
    let mut coxels = vec![units.initial_coxel(); w * h];
    for &sec in order {
        let data = SectionVoxels::from_beats(params, sec, &section_beats(params, vol, sec, p))?;
        for s in 0..params.nk {
            let c = params.slice(s);
            for b in 0..params.nj {
                for a in sec.a0..sec.a0 + sec.ns {
                    let smp = data.shaded(params, units, &c, a, b);
                    let (r, q) = params.pixel_of(&c, a, b);
                    coxels[q * w + r] = units.compos.step(&coxels[q * w + r], &smp);
                }
            }
        }
    }
    Ok(BasePlane {
        width: w,
        height: h,
        coxels,
    })
}

/// Views of the section and window tests: the six faces (DX = 0), 45 degrees both ways, obliques
/// with DX > 0 and DX < 0.
#[cfg(test)]
pub(super) fn test_views() -> Vec<[f64; 3]> {
    let mut v: Vec<[f64; 3]> = crate::camera::FACE_DIRECTIONS.to_vec();
    v.extend([
        [1.0, 0.0, 1.0],
        [-1.0, -1.0, 1.0],
        [0.37, 0.81, -1.0],
        [-0.6, 0.3, 1.0],
        [0.9, -1.0, 0.2],
    ]);
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::TransferFunction;
    use crate::units::cube5_frame::{
        frame_phong, neighbourhood, neighbourhood_from, render_base_plane, FrameMode, FrameSetup,
    };
    use glam::DVec3;

    use super::test_views as views;

    fn units(setup: &FrameSetup, mode: FrameMode) -> FrameUnits {
        let tf = TransferFunction::head_default();
        FrameUnits::new(mode, setup, &tf, &frame_phong(&setup.params, &[])).unwrap()
    }

    /// Sections in sweep order (left to right for DX >= 0, right to left for DX < 0), each swept
    /// through all its slices from its own beats, give the frame's image bit for bit: MIP and
    /// composite, S from P to the whole face (a narrower last section where S does not divide
    /// ni), the six faces, 45 degrees, DX < 0 and DX > 0, a cube and a non-cubic volume.
    #[test]
    fn sections_in_sweep_order_change_no_bit() {
        let cube = crate::phantom::head_phantom(32, 12).unwrap();
        let big = crate::phantom::head_phantom(40, 12).unwrap();
        let odd = Volume::new(
            [40, 24, 32],
            [1.0; 3],
            12,
            (0..40 * 24 * 32)
                .map(|n| {
                    let (x, y, z) = (n % 40, (n / 40) % 24, n / (40 * 24));
                    big.get(x as i64, y as i64, z as i64) as u16
                })
                .collect(),
        )
        .unwrap();
        let mut crossing = 0;
        for (vol, widths) in [(&cube, &[4usize, 8, 16, 32][..]), (&odd, &[8, 16][..])] {
            for v in views() {
                let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
                let params = setup.params;
                crossing += usize::from(params.dx != 0);
                for mode in [FrameMode::Mip, FrameMode::Composite] {
                    let u = units(&setup, mode);
                    let want = render_base_plane(&params, vol, &u);
                    assert!(want.coxels.iter().any(|c| c.rgba[3] > 0), "{v:?}: empty");
                    for &s in widths.iter().chain([&params.ni]) {
                        let order = section_order(&params, s, 4).unwrap();
                        let got = render_sections(&params, vol, &u, &order, 4).unwrap();
                        assert!(
                            got == want,
                            "{mode:?} view {v:?} S = {s}: the image changed"
                        );
                    }
                }
            }
        }
        assert!(crossing >= 4, "views whose rays cross sections");
    }

    /// At P = 1 too (sections of one anchor: every sample's x- and x+ come from lo and hi).
    #[test]
    fn sections_of_one_anchor_at_p1() {
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        for v in [[0.3, -0.7, 1.0], [-1.0, 0.0, 1.0], [0.0, 1.0, 0.0]] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 1).unwrap();
            let params = setup.params;
            let u = units(&setup, FrameMode::Composite);
            let want = render_base_plane(&params, &vol, &u);
            for s in [1, 3, 16] {
                let order = section_order(&params, s, 1).unwrap();
                let got = render_sections(&params, &vol, &u, &order, 1).unwrap();
                assert!(got == want, "view {v:?} S = {s}");
            }
        }
    }

    /// The order is what makes it exact: against the sweep direction (right to left for DX > 0)
    /// the rays that cross a section boundary composite out of slice order and the composite image
    /// changes. (So the test above can fail.)
    #[test]
    fn sections_against_the_sweep_change_the_composite() {
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        for v in [[0.6, 0.2, 1.0], [-0.6, 0.2, 1.0]] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
            let params = setup.params;
            let u = units(&setup, FrameMode::Composite);
            let want = render_base_plane(&params, &vol, &u);
            let mut order = section_order(&params, 8, 4).unwrap();
            order.reverse();
            let got = render_sections(&params, &vol, &u, &order, 4).unwrap();
            assert!(
                got != want,
                "view {v:?}: the wrong order left the image unchanged"
            );
        }
    }

    /// The edge-voxel rule: every anchor's neighbourhood computed from its section's beats (the
    /// section's columns, lo, hi0, hi1) is the whole volume's, at the section's edges too, at the
    /// face's edges (lo, hi zero there) and for a narrower last section.
    #[test]
    fn edge_voxels_give_the_whole_frames_samples_and_gradients() {
        let vol = crate::phantom::head_phantom(24, 12).unwrap();
        let trilin = crate::units::cube5_trilin::Trilin::new(
            crate::units::cube5_trilin::TrilinConfig::DEFAULT,
        )
        .unwrap();
        for v in [
            [0.3, -0.7, 1.0],
            [-1.0, 0.4, 0.2],
            [0.0, 0.0, -1.0],
            [1.0, 1.0, 0.0],
        ] {
            let params = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4)
                .unwrap()
                .params;
            for (width, p) in [(8, 4), (16, 4), (4, 1)] {
                for sec in section_order(&params, width, p).unwrap() {
                    let beats = section_beats(&params, &vol, sec, p);
                    let data = SectionVoxels::from_beats(&params, sec, &beats).unwrap();
                    for s in 0..params.nk {
                        let c = params.slice(s);
                        for b in 0..params.nj {
                            for a in sec.a0..sec.a0 + sec.ns {
                                assert_eq!(
                                    neighbourhood_from(&params, &c, (a, b), &trilin, &data.voxels()),
                                    neighbourhood(&params, &vol, &c, a, b, &trilin),
                                    "view {v:?} S {width} P {p} section {sec:?} slice {s} anchor ({a}, {b})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// The beats the frame expects are the ones `cube5_section_buf` delivers (its reference,
    /// every block present), marks and edge voxels included.
    #[test]
    fn section_beats_are_the_section_buffers_beams() {
        use crate::units::cube5_section_buf::{section_beams, SectionBufConfig, SectionCmd};
        use crate::units::cube5_skewmem::BlockLut;
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        let lut = BlockLut::identity(vol.dims, 8).unwrap();
        for v in [[0.3, -0.7, 1.0], [-1.0, 0.4, 0.2], [0.0, 1.0, 0.0]] {
            let params = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4)
                .unwrap()
                .params;
            let cfg = SectionBufConfig {
                section: 16,
                ..SectionBufConfig::DEFAULT
            };
            for sec in section_order(&params, 16, 4).unwrap() {
                let cmd = SectionCmd {
                    axis_k: params.axis_k as u32,
                    reversed: params.k_reversed,
                    dims: [params.ni, params.nj, params.nk].map(|n| n as u32),
                    a0: sec.a0 as u32,
                };
                let want = section_beams(&cfg, &vol, &lut, &cmd).unwrap();
                assert_eq!(section_beats(&params, &vol, sec, 4), want, "{v:?} {sec:?}");
            }
        }
    }

    #[test]
    fn bad_section_widths_refused() {
        let params = FrameSetup::new([16; 3], [1.0; 3], DVec3::Z, 4)
            .unwrap()
            .params;
        assert!(section_order(&params, 0, 4).is_err());
        assert!(section_order(&params, 6, 4).is_err());
        assert_eq!(section_order(&params, 12, 4).unwrap().len(), 2);
    }
}
