//! Co-simulation of the frame's render modes beyond MIP and composite (docs/numerics/frame.md,
//! "Render modes"): MinIP, X-ray and first-opaque, and the 2-D transfer function. Every frame is
//! compared pixel by pixel and channel by channel with the frame model
//! (`cube5_frame::render_base_plane`, the exact per-sample model for these modes), under random
//! back-pressure on the read-out on every frame; the model's image is also checked against the
//! test bench's own fold of the unit models (`model_image`). Small volumes (16^3), P = 4, with and
//! without gradient and shader; and the depth test against opaque geometry (`DepthTest = 1`,
//! docs/numerics/frame.md, "Opaque geometry") in every mode.

mod support;

use cube5_model::phantom::{bubbles_phantom, head_phantom};
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_model::volume::Volume;
use cube5_tb::frame::*;
use cube5_tb::rtl::Traffic;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::rc::Rc;
use support::{must, seed};

/// The default-width configuration with four pipelines, with (`shade`) or without gradient and
/// shader.
fn p4(shade: bool) -> FrameRtl {
    FrameRtl::all()
        .into_iter()
        .filter(|r| r.p == 4 && r.default_widths() && r.shade == shade && !r.depth_test)
        .max_by_key(|r| r.max_dim_log2)
        .unwrap_or_else(|| {
            panic!(
                "no cube5_frame variant with P = 4, Shade = {}",
                u8::from(shade)
            )
        })
}

/// A 16^3 volume with empty slabs front and back along z (blocks of 8 empty: the sweep may leave
/// out whole slices), a noisy blob between.
fn slab_volume(s: u64) -> Volume {
    use rand::Rng;
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let n = 16;
    let mut data = vec![0u16; n * n * n];
    for z in 8..16 {
        for y in 2..14 {
            for x in 1..15 {
                data[x + n * (y + n * z)] = rng.random_range(200..4096);
            }
        }
    }
    Volume::new([n; 3], [1.0; 3], 12, data).unwrap()
}

/// Views: an oblique one, its reverse along the slice axis, and along -x.
const VIEWS: [(&str, [f64; 3]); 3] = [
    ("oblique", [0.45, -0.3, 1.0]),
    ("oblique reversed", [-0.6, 0.35, -1.0]),
    ("-x", [-1.0, 0.2, 0.1]),
];

/// Renders `render` with `look` at every view on `rtl` for each volume; returns the frames'
/// models' images (for the callers' checks of what the frames exercised).
fn modes_bit_exact(
    rtl: FrameRtl,
    vols: &[Volume],
    render: Render,
    look: &Look,
    s: u64,
) -> Vec<Expected> {
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mut done = Vec::new();
    for (vi, vol) in vols.iter().enumerate() {
        let lut = BlockLut::from_volume(vol, rtl.block as usize, 0).unwrap();
        let seen = Rc::new(as_seen(vol, &lut).unwrap());
        let mut bench = must(FrameBench::new(rtl, vol, &lut, s as u32));
        bench.skip_empty = true;
        for (n, (name, dir)) in VIEWS.iter().enumerate() {
            let e = Expected::new(&rtl, &seen, name, *dir, render, look).unwrap();
            // The model's image is the test bench's own fold of the unit models.
            let units = Units::new(
                &rtl,
                render,
                &{
                    let mut setup = cube5_model::units::cube5_frame::FrameSetup::new(
                        seen.dims,
                        seen.spacing,
                        (*dir).into(),
                        1,
                    )
                    .unwrap();
                    if let Some(x) = look.xray_shift {
                        setup.xray_shift = x;
                    }
                    setup
                },
                look,
            )
            .unwrap();
            // (The fold knows no geometry: frames with the depth test are checked against the
            // model alone, and the model's geometry against its own rules in the model's tests.)
            if !rtl.depth_test {
                let (w, h, fold) = model_image(&e.params, &seen, &units);
                assert!(
                    (w, h) == (e.w, e.h) && fold == e.want,
                    "{render:?} {name}: the frame model differs from the unit models' fold"
                );
            }
            let traffic = Traffic::random(&mut rng, 0.0, 0.3);
            let st = must(bench.check(&e, &traffic, s + 100 * vi as u64 + n as u64));
            eprintln!(
                "{} {render:?} volume {vi} {name}: {} x {} bit-exact, {} cycles, slices skipped {:?}",
                rtl.variant, e.w, e.h, st.cycles, st.skip
            );
            if render == Render::Minip {
                assert_eq!(st.skip, (0, 0), "MinIP never skips empty slices");
            }
            done.push(e);
        }
    }
    done
}

#[test]
fn minip_frames_bit_exact_with_and_without_shade() {
    let s = seed(71);
    let vols = [bubbles_phantom(16, 12).unwrap(), slab_volume(s)];
    for shade in [false, true] {
        let frames = modes_bit_exact(p4(shade), &vols, Render::Minip, &Look::default(), s);
        // Rays no sample reaches read out as the MinIP coxel (A all ones, black) and the others
        // took their first sample.
        let untouched = frames
            .iter()
            .flat_map(|e| e.want.iter().map(move |c| *c == e.units.initial_coxel()))
            .filter(|&u| u)
            .count();
        let total: usize = frames.iter().map(|e| e.want.len()).sum();
        assert!(
            untouched > 0 && untouched < total / 2,
            "{untouched} of {total} rays untouched"
        );
    }
}

#[test]
fn xray_frames_bit_exact_and_saturating() {
    let s = seed(72);
    let vols = [head_phantom(16, 12).unwrap(), slab_volume(s)];
    modes_bit_exact(p4(false), &vols, Render::Xray, &Look::default(), s);
    // XrayShift 0: full sums that saturate at the coxel's all-ones code.
    let look = Look {
        xray_shift: Some(0),
        ..Look::default()
    };
    let frames = modes_bit_exact(p4(true), &vols[1..], Render::Xray, &look, s + 1);
    let chan_max = frames[0].units.compos.config().chan_max();
    assert!(
        frames
            .iter()
            .any(|e| e.want.iter().any(|c| c.rgba[0] == chan_max)),
        "some X-ray sum saturates"
    );
}

#[test]
fn first_opaque_frames_bit_exact() {
    let s = seed(73);
    let vols = [head_phantom(16, 12).unwrap(), slab_volume(s)];
    for threshold in [0.5, 0.05] {
        let look = Look {
            tf: dense_tf(),
            threshold,
            ..Look::default()
        };
        let frames = modes_bit_exact(p4(true), &vols, Render::FirstOpaque, &look, s);
        let hits: usize = frames
            .iter()
            .map(|e| e.want.iter().filter(|c| c.terminated).count())
            .sum();
        let total: usize = frames.iter().map(|e| e.want.len()).sum();
        assert!(
            hits > 0 && hits < total,
            "threshold {threshold}: {hits} of {total} rays hit"
        );
    }
}

#[test]
fn two_d_transfer_function_frames_bit_exact() {
    let s = seed(74);
    let vols = [head_phantom(16, 12).unwrap(), slab_volume(s)];
    let look = Look {
        tf: dense_tf(),
        boundary: Some(0.25),
        early_termination: true,
        ..Look::default()
    };
    let two_d = modes_bit_exact(p4(true), &vols, Render::Composite, &look, s);
    // The 2-D table changes the image (the magnitude reaches the shader's index).
    let one_d = Expected::new(
        &p4(true),
        &two_d[0].seen,
        VIEWS[0].0,
        VIEWS[0].1,
        Render::Composite,
        &Look {
            boundary: None,
            ..look.clone()
        },
    )
    .unwrap();
    assert!(
        one_d.want != two_d[0].want,
        "the 2-D table changes the image"
    );
    let look = Look {
        threshold: 0.3,
        ..look
    };
    modes_bit_exact(p4(true), &vols[..1], Render::FirstOpaque, &look, s + 1);
}

#[test]
fn shade_0_refuses_first_opaque_and_the_2d_table() {
    // (MIP, MinIP and X-ray render above on the frame without gradient and shader.)
    let s = seed(75);
    let rtl = p4(false);
    let vol = head_phantom(16, 12).unwrap();
    let lut = BlockLut::from_volume(&vol, rtl.block as usize, 0).unwrap();
    let seen = Rc::new(as_seen(&vol, &lut).unwrap());
    let mut bench = must(FrameBench::new(rtl, &vol, &lut, s as u32));
    let good = Expected::new(
        &rtl,
        &seen,
        VIEWS[0].0,
        VIEWS[0].1,
        Render::Xray,
        &Look::default(),
    )
    .unwrap();
    for (what, mode) in [
        ("first-opaque", Render::FirstOpaque.code()),
        (
            "MinIP with the 2-D table",
            Render::Minip.code() | 1 << REG_MODE_TF2D.lsb,
        ),
        ("render code 5", 5),
    ] {
        must(bench.load(&good));
        must(bench.write(&[rtl.reg(REG_MODE, mode)]));
        assert!(must(bench.refused(OP_RENDER)).error, "{what} is refused");
    }
    must(bench.load(&good));
    must(bench.render_and_compare(&good, &Traffic::full_speed(), s));
}

/// Opaque boxes and spheres, seeded, inside and around a 16^3 volume (some in front of it, some
/// cutting it, some behind), with random colours.
fn random_solids(s: u64) -> Vec<cube5_model::geometry::Solid> {
    use cube5_model::geometry::Solid;
    use rand::Rng;
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mut v = Vec::new();
    for i in 0..4 {
        let c: [f64; 3] = std::array::from_fn(|_| rng.random_range(0.0..1.0));
        let at: [f64; 3] = std::array::from_fn(|_| rng.random_range(-4.0..20.0));
        if i % 2 == 0 {
            let size: [f64; 3] = std::array::from_fn(|_| rng.random_range(1.0..7.0));
            v.push(Solid::Box {
                min: at,
                max: std::array::from_fn(|a| at[a] + size[a]),
                colour: c,
            });
        } else {
            v.push(Solid::Sphere {
                centre: at,
                radius: rng.random_range(1.5..6.0),
                colour: c,
            });
        }
    }
    v
}

/// The depth test (`DepthTest = 1`): every mode against random opaque boxes and spheres, on a
/// frame with a geometry table and the read-out's flush, bit-exact with the model; the geometry
/// hides samples and shows through (the image differs from the same frame without geometry),
/// and a frame without geometry (every pixel at `Znone`) has the image of the frame without the
/// depth test, each ray marked terminated by the flush.
#[test]
fn depth_test_against_opaque_geometry_bit_exact() {
    let s = seed(76);
    let Some(rtl) = FrameRtl::with_depth_test().into_iter().next() else {
        panic!("no cube5_frame variant with DepthTest = 1");
    };
    let vols = [head_phantom(16, 12).unwrap(), slab_volume(s)];
    for (n, render) in Render::ALL.into_iter().enumerate() {
        let look = Look {
            tf: dense_tf(),
            geometry: random_solids(s + n as u64),
            early_termination: render == Render::Composite,
            ..Look::default()
        };
        let frames = modes_bit_exact(rtl, &vols, render, &look, s + n as u64);
        let plain = Expected::new(
            &p4(true),
            &frames[0].seen,
            VIEWS[0].0,
            VIEWS[0].1,
            render,
            &Look {
                geometry: Vec::new(),
                ..look.clone()
            },
        )
        .unwrap();
        let z_none = frames[0].units.compos.config().z_none();
        let g = frames[0].geometry.as_ref().unwrap();
        let hit = g.pixels.iter().filter(|p| p.z != z_none).count();
        assert!(
            hit > 0 && hit < g.pixels.len(),
            "{render:?}: {hit} of {} pixels see geometry",
            g.pixels.len()
        );
        assert!(
            plain.want != frames[0].want,
            "{render:?}: the geometry changes the image"
        );
    }
    // No geometry: the image of the frame without the depth test, every ray terminated.
    let look = Look::default();
    let frames = modes_bit_exact(rtl, &vols[..1], Render::Composite, &look, s + 9);
    let plain = Expected::new(
        &p4(true),
        &frames[0].seen,
        VIEWS[0].0,
        VIEWS[0].1,
        Render::Composite,
        &look,
    )
    .unwrap();
    for (a, b) in frames[0].want.iter().zip(&plain.want) {
        assert!(a.terminated && a.rgba == b.rgba && a.z == b.z && a.geo == b.geo);
    }
}
