//! ER-perspective (`er_perspective`, docs/numerics/er_perspective.md): the regions, the ray
//! spacing and the samples per slice of the contract, the merge's rounding, refusals, and the
//! model against its f64 reference and the exact perspective.

use cube5_model::er_perspective::{
    merge_coxels, render_er, render_er_f64, render_er_f64_with, ErJob, ErMerge, ErScheme, ErSetup,
};
use cube5_model::phantom::head_phantom;
use cube5_model::render::image_error;
use cube5_model::render::{render_reference, CompositeMode, Projection, RenderParams};
use cube5_model::units::cube5_compos::{ComposConfig, Coxel};
use cube5_model::units::cube5_frame::{FrameConfig, FrameSetup};
use glam::DVec3;
use rand::{Rng, SeedableRng};

fn persp(direction: [f64; 3], fov: f64, size: u32) -> RenderParams {
    RenderParams {
        width: size,
        height: size,
        direction: Some(direction),
        projection: Projection::Perspective,
        fov,
        step: 0.5,
        ..RenderParams::default()
    }
}

fn scheme(rays_per_voxel: u32) -> ErScheme {
    ErScheme {
        rays_per_voxel,
        merge: ErMerge::Bartlett,
    }
}

/// A set-up with the eye placed by hand: `e` slices in front of the first slice of a view along
/// `dir` (voxel space = physical at unit spacing), laterally at `lateral` (frame axes i, j).
fn placed(dims: [usize; 3], dir: DVec3, e: f64, lateral: [f64; 2], rho: u32) -> ErSetup {
    let frame = FrameSetup::new(dims, [1.0; 3], dir, 1).unwrap();
    let p = frame.params;
    let mut eye = [0.0; 3];
    eye[p.axis_i] = lateral[0];
    eye[p.axis_j] = lateral[1];
    eye[p.axis_k] = if p.k_reversed {
        (p.nk - 1) as f64 + e
    } else {
        -e
    };
    ErSetup::with_eye(
        frame,
        scheme(rho),
        DVec3::from_array(eye),
        dir,
        (DVec3::X, DVec3::Y),
        0.5,
        [1.0; 3],
    )
    .unwrap()
}

/// A random set-up: dimensions in `edges`, a direction, an eye `1..max_e` slices in front at a
/// random lateral place (inside or outside the face), base rate 1, 2 or 4 by `case`; `None` for a
/// direction too short to name a view.
#[allow(clippy::type_complexity)]
fn random_setup(
    rng: &mut rand::rngs::StdRng,
    case: usize,
    edges: std::ops::Range<usize>,
    max_e: f64,
) -> Option<(ErSetup, ([usize; 3], DVec3, f64, u32))> {
    let dims = [(); 3].map(|_| rng.random_range(edges.clone()));
    let dir = DVec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let rho = [1, 2, 4][case % 3];
    let e = rng.random_range(1.0..max_e);
    let lateral = [rng.random_range(-30.0..60.0), rng.random_range(-30.0..60.0)];
    (dir.length() >= 0.1).then(|| (placed(dims, dir, e, lateral, rho), (dims, dir, e, rho)))
}

/// Regions start at 0, never decrease, grow by at most one per slice, and match the contract's
/// bounds `E 2^r <= d < E 2^(r+1)`; the ray spacing stays in `[G/2, G]`, is `G/2` exactly at
/// every region's front boundary and grows within a region.
#[test]
fn regions_are_exponential_and_the_spacing_stays_in_bounds() {
    let one = 1i64 << 16;
    for (e, rho) in [
        (1.0, 1),
        (1.37, 2),
        (3.0, 1),
        (7.9, 4),
        (40.0, 1),
        (0.999 + 1.0, 2),
    ] {
        let s = placed([16, 24, 100], DVec3::Z, e, [8.0, 12.0], rho);
        let g = s.g();
        assert_eq!(g, one / i64::from(rho));
        let mut last = (0u32, 0i64);
        for k in 0..100 {
            let (r, h) = s.slice_spacing(k);
            let d = s.e + k as i64 * one;
            assert!(
                (s.e << r) <= d && d < (s.e << (r + 1)),
                "e {e}: slice {k} region {r}"
            );
            assert!(
                g / 2 <= h && h <= g,
                "e {e}: slice {k}: H {h} outside [G/2, G]"
            );
            if k == 0 {
                assert_eq!(r, 0, "slice 0 is in region 0");
            } else {
                assert!(r == last.0 || r == last.0 + 1, "e {e}: slice {k}");
                if r == last.0 {
                    assert!(
                        h >= last.1,
                        "e {e}: slice {k}: spacing falls within a region"
                    );
                }
            }
            last = (r, h);
        }
        for r in 0..6 {
            assert_eq!(s.spacing_at(s.e << r), (r, g / 2), "front of region {r}");
            let (rr, h) = s.spacing_at((s.e << (r + 1)) - 1);
            assert_eq!((rr, h), (r, g), "rear of region {r}");
        }
    }
}

/// The samples of every slice lie between `N^2 = ni nj rho^2` and `4 N^2` ([195]), for random
/// views, fields of view, eye distances, base rates, non-cubic volumes; and the merge extents hold
/// every ray a merge writes.
#[test]
fn samples_per_slice_stay_between_n2_and_4n2() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(14);
    for case in 0..300 {
        let Some((s, (dims, dir, e, rho))) = random_setup(&mut rng, case, 4..40, 60.0) else {
            continue;
        };
        let p = *s.params();
        let layout = s.layout();
        let n2 = (p.ni * p.nj) as u64 * u64::from(rho * rho);
        for (k, count) in layout.samples_per_slice().iter().enumerate() {
            assert!(
                n2 <= *count && *count <= 4 * n2,
                "case {case} (dims {dims:?}, dir {dir:?}, e {e:.2}, rho {rho}): slice {k} has {count} samples, bound {n2}..{}",
                4 * n2
            );
        }
        for (k, rays) in layout.rays.iter().enumerate() {
            let ext = layout.extent[layout.region[k] as usize];
            assert!(
                ext.m0 <= rays.m0 && rays.m1 <= ext.m1 && ext.n0 <= rays.n0 && rays.n1 <= ext.n1,
                "case {case}: slice {k}"
            );
        }
    }
}

/// The contract's merge: weights (1, 2, 1) x (1, 2, 1) / 16, round half up, no overflow at the
/// largest coxel, the empty coxel's other fields; the what-if keeps the centre.
#[test]
fn the_bartlett_merge_rounds_half_up() {
    let cfg = ComposConfig::DEFAULT;
    let empty = Coxel::empty(&cfg);
    let with = |v: [u64; 4]| Coxel {
        rgba: v,
        terminated: true,
        ..empty
    };
    let mut nb = [[empty; 3]; 3];
    nb[1][1] = with([16, 8, 1, 0]);
    let out = merge_coxels(&nb, ErMerge::Bartlett, &empty);
    // 4/16 of 16 = 4; of 8 = 2; of 1 = 0.25 -> 0.
    assert_eq!(out.rgba, [4, 2, 0, 0]);
    assert_eq!((out.z, out.terminated), (empty.z, false));
    nb[0][0] = with([8, 8, 8, 8]); // corner weight 1/16: 0.5 rounds up
    assert_eq!(
        merge_coxels(&nb, ErMerge::Bartlett, &empty).rgba,
        [5, 3, 1, 1]
    );
    let top = cfg.chan_max();
    let full = [[with([top; 4]); 3]; 3];
    assert_eq!(
        merge_coxels(&full, ErMerge::Bartlett, &empty).rgba,
        [top; 4]
    );
    assert_eq!(
        merge_coxels(&nb, ErMerge::Centre, &empty).rgba,
        [16, 8, 1, 0]
    );
}

/// Refusals: an eye less than one slice in front of the volume, a parallel view, a base rate
/// other than 1, 2, 4, and modes other than composite and MIP; each names what it refuses.
#[test]
fn what_the_scheme_cannot_do_is_refused() {
    let frame = FrameSetup::new([16; 3], [1.0; 3], DVec3::Z, 1).unwrap();
    for e in [0.5, 0.0, -3.0, 8.0 - 20.0] {
        let err = ErSetup::with_eye(
            frame,
            scheme(1),
            DVec3::new(8.0, 8.0, -e),
            DVec3::Z,
            (DVec3::X, DVec3::Y),
            0.5,
            [1.0; 3],
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("view") && err.contains("in front"), "{err}");
    }
    let vol = head_phantom(16, 12).unwrap();
    let tf = cube5_model::transfer::TransferFunction::head_default();
    let parallel = RenderParams {
        projection: Projection::Parallel,
        ..persp([1.0, 0.3, 0.2], 40.0, 16)
    };
    let err = render_er(&vol, &tf, &parallel, &FrameConfig::DEFAULT, scheme(1))
        .unwrap_err()
        .to_string();
    assert!(err.contains("projection"), "{err}");
    let err = render_er(
        &vol,
        &tf,
        &persp([1.0, 0.3, 0.2], 40.0, 16),
        &FrameConfig::DEFAULT,
        scheme(3),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("rays_per_voxel 3"), "{err}");
    let xray = RenderParams {
        mode: CompositeMode::Xray,
        ..persp([1.0, 0.3, 0.2], 40.0, 16)
    };
    let err = render_er(&vol, &tf, &xray, &FrameConfig::DEFAULT, scheme(1))
        .unwrap_err()
        .to_string();
    assert!(err.contains("xray"), "{err}");
}

/// Views straight down each axis (both senses) and oblique ones, fields of view 20-140 degrees,
/// composite and MIP: the model is its f64 reference's up to the fixed point (>= 45 dB), and the
/// scheme is near the exact perspective (>= 28 dB composite; MIP >= 24 dB); on the axis views the
/// slice axis is the view's axis.
#[test]
fn views_down_each_axis_and_oblique_are_near_both_references() {
    let vol = head_phantom(32, 12).unwrap();
    let tf = cube5_model::transfer::TransferFunction::head_default();
    let mut views: Vec<([f64; 3], f64)> = cube5_model::camera::FACE_DIRECTIONS
        .iter()
        .map(|&d| (d, 60.0))
        .collect();
    views.extend([
        ([0.7, 0.5, -0.3], 20.0),
        ([-0.2, 0.9, 0.4], 90.0),
        ([0.6, -0.6, 0.55], 140.0),
    ]);
    for (i, (dir, fov)) in views.iter().enumerate() {
        for mode in [CompositeMode::Composite, CompositeMode::Mip] {
            let params = RenderParams {
                mode,
                up: (i < 6 && dir[2] != 0.0).then_some([0.0, 1.0, 0.0]),
                ..persp(*dir, *fov, 48)
            };
            let run = render_er(&vol, &tf, &params, &FrameConfig::DEFAULT, scheme(1)).unwrap();
            if i < 6 {
                let axis = dir.iter().position(|c| *c != 0.0).unwrap();
                let setup = ErSetup::new(vol.dims, vol.spacing, &params, scheme(1)).unwrap();
                assert_eq!(setup.params().axis_k, axis, "{dir:?}");
            }
            let (f64_img, _) = render_er_f64(&vol, &tf, &params, scheme(1)).unwrap();
            let reference = render_reference(&vol, &tf, &params).unwrap();
            // The frame's fixed point alone (the same f64 warp on both), then the bit-exact
            // perspective warp's image (nearest-row scanline samples, docs/numerics/pwarp.md).
            let own = image_error(&run.image_f64_warp, &f64_img).psnr_db;
            let warped = image_error(&run.image, &f64_img).psnr_db;
            let exact = image_error(&run.image, &reference).psnr_db;
            eprintln!(
                "{dir:?} fov {fov} {}: {own:.1} dB (f64 warp), {warped:.1} dB (cube5_pwarp) against its f64; {exact:.1} dB against the exact perspective",
                mode.name()
            );
            let floor = if mode == CompositeMode::Mip {
                24.0
            } else {
                28.0
            };
            assert!(
                own >= 45.0 && warped >= 33.0 && exact >= floor,
                "{dir:?} fov {fov} {}: {own:.1} dB against its f64 (f64 warp), {warped:.1} dB with cube5_pwarp, {exact:.1} dB against the exact perspective",
                mode.name()
            );
            let s = &run.stats;
            assert!(s.min_per_slice() >= s.n2 && s.max_per_slice() <= 4 * s.n2);
        }
    }
}

/// The Bartlett merge is better than dropping the neighbours (the what-if) where the regions
/// merge: a wide view with several regions, against the exact perspective (PSNR and largest
/// error: dropped rays alias, [156]).
#[test]
fn bartlett_beats_dropping_rays() {
    let vol = head_phantom(48, 12).unwrap();
    let tf = cube5_model::transfer::TransferFunction::head_default();
    let params = persp([0.6, -0.7, 0.4], 120.0, 96);
    let reference = render_reference(&vol, &tf, &params).unwrap();
    let psnr = |merge| {
        let run = render_er(
            &vol,
            &tf,
            &params,
            &FrameConfig::DEFAULT,
            ErScheme {
                rays_per_voxel: 1,
                merge,
            },
        )
        .unwrap();
        assert!(run.stats.regions >= 2, "{:?}", run.stats);
        image_error(&run.image, &reference)
    };
    let (b, c) = (psnr(ErMerge::Bartlett), psnr(ErMerge::Centre));
    assert!(
        b.psnr_db > c.psnr_db + 0.1 && b.max_abs < c.max_abs,
        "bartlett {b:?}, centre {c:?}"
    );
}

/// The rays of a slice are exactly those whose anchor lies on the face (`0 <= X >> 16 < ni`, the
/// same for `j`): the first and last of each range are inside, their neighbours outside; and the
/// f64 layout puts every slice in the same region as the fixed-point one for eyes away from a
/// boundary.
#[test]
fn the_rays_of_a_slice_are_those_whose_anchor_is_on_the_face() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(141);
    for case in 0..200 {
        let Some((s, _)) = random_setup(&mut rng, case, 2..30, 40.0) else {
            continue;
        };
        let p = *s.params();
        let layout = s.layout();
        let (f64_layout, _) = s.layout_f64();
        for (k, rays) in layout.rays.iter().enumerate() {
            let h = s.slice_spacing(k).1;
            let anchor = |e0: i64, m: i64| (e0 + m * h) >> 16;
            let on = |a: i64, n: usize| a >= 0 && a < n as i64;
            for (e0, lo, hi, n) in [
                (s.ei, rays.m0, rays.m1, p.ni),
                (s.ej, rays.n0, rays.n1, p.nj),
            ] {
                assert!(
                    on(anchor(e0, lo), n) && on(anchor(e0, hi), n),
                    "case {case} slice {k}"
                );
                assert!(
                    !on(anchor(e0, lo - 1), n) && !on(anchor(e0, hi + 1), n),
                    "case {case} slice {k}"
                );
            }
            let d = s.eye[2] + k as f64;
            let near_boundary =
                (0..12).any(|r| (d / (s.eye[2] * f64::from(1u32 << r)) - 1.0).abs() < 1e-3);
            if !near_boundary {
                assert_eq!(
                    layout.region[k], f64_layout.region[k],
                    "case {case} slice {k}"
                );
            }
        }
    }
}

/// An eye inside the volume's bounding sphere (2 slices in front of the first slice, over the
/// face's centre; the scene's camera never puts it there): five regions, four merges, the bound
/// on every slice, and the model within the fixed point of its f64 reference, composite and MIP.
#[test]
fn an_eye_inside_the_bounding_sphere_renders_with_many_regions() {
    let vol = head_phantom(32, 12).unwrap();
    let tf = cube5_model::transfer::TransferFunction::head_default();
    for mode in [CompositeMode::Composite, CompositeMode::Mip] {
        let params = RenderParams {
            mode,
            up: Some([0.0, 1.0, 0.0]),
            ..persp([0.0, 0.0, 1.0], 90.0, 48)
        };
        let job = ErJob::new(&vol, &tf, &params, &FrameConfig::DEFAULT, scheme(1)).unwrap();
        let s = &job.setup;
        let eye = DVec3::new(15.5, 15.5, -2.0);
        assert!(
            (eye - DVec3::splat(15.5)).length() < 16.0 * 3f64.sqrt(),
            "inside the sphere"
        );
        let placed = ErSetup::with_eye(
            s.frame,
            s.scheme,
            eye,
            s.dir,
            (s.right, s.up),
            s.tan_half,
            s.spacing,
        )
        .unwrap();
        let job = job.with_setup(placed).unwrap();
        let run = job.render();
        let st = &run.stats;
        assert_eq!(
            (st.regions, st.region_starts.clone()),
            (5, vec![0, 2, 6, 14, 30])
        );
        assert!(
            st.min_per_slice() >= st.n2 && st.max_per_slice() <= 4 * st.n2,
            "{st:?}"
        );
        assert!(
            run.image.rgb.iter().any(|c| c[0] > 0.1),
            "{}: a black image",
            mode.name()
        );
        let (ideal, _) = render_er_f64_with(&job.setup, &vol, &tf, &params).unwrap();
        let own = image_error(&run.image, &ideal).psnr_db;
        assert!(own >= 45.0, "{}: {own:.1} dB against its f64", mode.name());
    }
}
