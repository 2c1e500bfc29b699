//! The camera (issue 14's list): continuous through the poles, a view up and a roll, and the images
//! of the frame model and of the reference turn with it.
//!
//! The images are of a marker volume: one bright ball off the centre along a known world axis; the
//! ball's angle on the image (counterclockwise from the image's right, about the image centre) is
//! the camera's prediction `atan2(m . up, m . right)` for the marker's offset `m`.

use cube5_model::camera::{self, Camera};
use cube5_model::render::{render_reference, CompositeMode, ImageF64, RenderParams, View};
use cube5_model::scene::{Scene, ViewSpec};
use cube5_model::scene_render::{frame_config, FrameJob};
use cube5_model::transfer::TransferFunction;
use cube5_model::volume::Volume;
use glam::{DMat3, DVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const N: usize = 24;
const IMG: u32 = 48;

/// A 24^3 volume, zero but for a ball of radius 3 voxels centred at the volume centre plus
/// `offset` voxels (a smooth edge, so the images have no aliasing to speak of).
fn marker_volume(offset: DVec3) -> Volume {
    let c = DVec3::splat((N as f64 - 1.0) / 2.0) + offset;
    let mut data = vec![0u16; N * N * N];
    for z in 0..N {
        for y in 0..N {
            for x in 0..N {
                let d = (DVec3::new(x as f64, y as f64, z as f64) - c).length();
                let v = ((3.5 - d) / 1.5).clamp(0.0, 1.0);
                data[x + N * (y + N * z)] = (v * 4095.0).round() as u16;
            }
        }
    }
    Volume::new([N; 3], [1.0; 3], 12, data).unwrap()
}

/// Angle in degrees (counterclockwise from the image's right) of the brightness centroid about the
/// image centre.
fn marker_angle(img: &ImageF64) -> f64 {
    let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
    for (i, c) in img.rgb.iter().enumerate() {
        let w = c[0];
        let (px, py) = ((i as u32 % img.width) as f64, (i as u32 / img.width) as f64);
        sx += w * (px + 0.5 - f64::from(img.width) / 2.0);
        sy += w * (f64::from(img.height) / 2.0 - (py + 0.5));
        sw += w;
    }
    assert!(sw > 1.0, "the marker is not in the image");
    (sy / sw).atan2(sx / sw).to_degrees()
}

/// The camera's prediction of the marker's angle.
fn predicted_angle(cam: &Camera, offset: DVec3) -> f64 {
    offset.dot(cam.up).atan2(offset.dot(cam.right)).to_degrees()
}

/// Difference of two angles in degrees, in -180..180.
fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

fn mip_params(view: View) -> RenderParams {
    RenderParams {
        width: IMG,
        height: IMG,
        view,
        mode: CompositeMode::Mip,
        step: 0.5,
        ..Default::default()
    }
}

/// The image of `scene` (at `IMG`^2, MIP) on the frame model, as `cube5 render` shows it.
fn frame_image(scene_text: &str, vol: &Volume) -> (ImageF64, Camera) {
    let text =
        format!("[image]\nwidth = {IMG}\nheight = {IMG}\n[render]\nmode = \"mip\"\n{scene_text}");
    let scene = Scene::parse(&text, "test").unwrap();
    let job = FrameJob::new(&scene, vol, frame_config(&scene).unwrap(), 1).unwrap();
    let run = job.render();
    let params = scene.render_params();
    let cam = params.camera(vol, params.direction().unwrap());
    (job.image(&scene, &run.base).unwrap(), cam)
}

/// The rotation taking camera frame `a` to camera frame `b`, as an angle in degrees.
fn rotation_between(a: &Camera, b: &Camera) -> f64 {
    let ma = DMat3::from_cols(a.right, a.up, a.dir);
    let mb = DMat3::from_cols(b.right, b.up, b.dir);
    let r = mb * ma.transpose();
    let tr = r.x_axis.x + r.y_axis.y + r.z_axis.z;
    ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

fn orbit_camera(azimuth: f64, elevation: f64, roll: f64) -> Camera {
    let params = RenderParams {
        view: View { azimuth, elevation },
        roll,
        ..mip_params(View {
            azimuth: 0.0,
            elevation: 0.0,
        })
    };
    let vol = Volume::new([2; 3], [1.0; 3], 8, vec![1; 8]).unwrap();
    params.camera(&vol, params.direction().unwrap())
}

/// Over elevations 80..100 (and -100..-80) the camera's frame turns by exactly the elevation step
/// (before issue 14 it jumped at 87.5 degrees, where +z gave way to +y as the up vector).
#[test]
fn the_orbit_turns_continuously_through_the_poles() {
    for azimuth in [0.0, 65.0, 137.0, 200.0, -30.0] {
        for (from, to) in [(80.0, 100.0), (-100.0, -80.0)] {
            let step = 0.05;
            let mut prev = orbit_camera(azimuth, from, 0.0);
            let mut e: f64 = from;
            while e < to {
                e += step;
                let cam = orbit_camera(azimuth, e, 0.0);
                let turn = rotation_between(&prev, &cam);
                assert!(
                    (turn - step).abs() < 1e-6,
                    "azimuth {azimuth}, elevation {e:.2}: the camera turned {turn} degrees for a {step}-degree step"
                );
                // The image's right is the azimuth's tangent all the way over the top.
                let a = azimuth.to_radians();
                assert!((cam.right - DVec3::new(-a.sin(), a.cos(), 0.0)).length() < 1e-9);
                prev = cam;
            }
        }
    }
}

/// The images follow the camera: a marker's angle on the reference image over elevation 80..100
/// is the camera's prediction, so it moves smoothly (it jumped by tens of degrees between 87.4
/// and 87.5 before); the frame model shows the same at the old jump and at the pole itself.
#[test]
fn the_image_turns_smoothly_over_elevation_80_to_100() {
    let offset = DVec3::new(7.0, 0.0, 0.0);
    let vol = marker_volume(offset);
    let tf = TransferFunction::head_default();
    let azimuth = 65.0;
    let mut prev: Option<f64> = None;
    for k in 0..=40 {
        let elevation = 80.0 + 0.5 * f64::from(k);
        let params = mip_params(View { azimuth, elevation });
        let cam = params.camera(&vol, params.direction().unwrap());
        let img = render_reference(&vol, &tf, &params).unwrap();
        let seen = marker_angle(&img);
        let want = predicted_angle(&cam, offset);
        assert!(
            angle_diff(seen, want).abs() < 2.0,
            "elevation {elevation}: marker at {seen:.1} degrees, camera says {want:.1}"
        );
        if let Some(p) = prev {
            assert!(
                angle_diff(seen, p).abs() < 3.0,
                "elevation {elevation}: the image turned {:.1} degrees in half a degree",
                angle_diff(seen, p)
            );
        }
        prev = Some(seen);
    }
    let mut angles = Vec::new();
    for elevation in [87.4, 87.5, 90.0, 92.6] {
        let (img, cam) = frame_image(
            &format!("[view]\nazimuth = {azimuth}\nelevation = {elevation}\n"),
            &vol,
        );
        let seen = marker_angle(&img);
        let want = predicted_angle(&cam, offset);
        assert!(
            angle_diff(seen, want).abs() < 3.0,
            "frame model, elevation {elevation}: marker at {seen:.1} degrees, camera says {want:.1}"
        );
        angles.push(seen);
    }
    assert!(
        angle_diff(angles[0], angles[1]).abs() < 3.0,
        "frame model: 87.4 -> 87.5 turned the image by {:.1} degrees",
        angle_diff(angles[0], angles[1])
    );
}

/// 1,000 random views (orbits with a roll, and directions with an up vector and a roll), each
/// changed a little: the image never turns by more than the change.
#[test]
fn a_small_change_of_view_never_turns_the_image_more_than_the_change() {
    let seed: u64 = std::env::var("CUBE5_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(14);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let vol = Volume::new([2; 3], [1.0; 3], 8, vec![1; 8]).unwrap();
    let unit = |rng: &mut ChaCha8Rng| loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if (0.1..1.0).contains(&v.length()) {
            return v.normalize();
        }
    };
    for case in 0..1000 {
        // An orbit (including elevations past the poles and exactly on them) with a roll.
        let (a, e, r) = (
            rng.random_range(-360.0..360.0),
            if case % 10 == 0 {
                90.0 * f64::from([1, -1, 3][case % 3])
            } else {
                rng.random_range(-200.0..200.0)
            },
            rng.random_range(-180.0..180.0),
        );
        let (da, de, dr): (f64, f64, f64) = (
            rng.random_range(-0.2..0.2),
            rng.random_range(-0.2..0.2),
            rng.random_range(-0.2..0.2),
        );
        let turn = rotation_between(
            &orbit_camera(a, e, r),
            &orbit_camera(a + da, e + de, r + dr),
        );
        let change = da.abs() + de.abs() + dr.abs();
        assert!(
            turn <= change + 1e-6,
            "seed {seed} case {case}: orbit ({a}, {e}, {r}) + ({da}, {de}, {dr}) turned the image {turn} degrees"
        );
        // A direction and an up vector (at least a degree apart), turned together by a small
        // rotation, with a small change of roll.
        let dir = unit(&mut rng);
        let up = loop {
            let u = unit(&mut rng);
            if dir.cross(u).length() > 1f64.to_radians().sin() {
                break u;
            }
        };
        let roll = rng.random_range(-180.0..180.0);
        let angle: f64 = rng.random_range(0.0..0.2);
        let q = glam::DQuat::from_axis_angle(unit(&mut rng), angle.to_radians());
        let look = |d: DVec3, u: DVec3, roll: f64| {
            let p = RenderParams {
                direction: Some(d.to_array()),
                up: Some(u.to_array()),
                roll,
                ..Default::default()
            };
            p.camera(&vol, p.direction().unwrap())
        };
        let turn = rotation_between(&look(dir, up, roll), &look(q * dir, q * up, roll + dr));
        assert!(
            turn <= angle + dr.abs() + 1e-6,
            "seed {seed} case {case}: direction {dir} up {up} roll {roll} turned by {angle} and {dr}: image turned {turn} degrees"
        );
    }
}

/// Looking down -z with +y up: +x right, +y up; turned 30 degrees: the picture turns 30 degrees
/// counterclockwise, in the camera, the reference and the frame model.
#[test]
fn looking_down_minus_z_with_y_up_turned_30_degrees() {
    let tf = TransferFunction::head_default();
    for (view, roll) in [
        ("direction = [0, 0, -1]\n", 0.0),
        ("direction = [0, 0, -1]\nup = [0, 1, 0]\n", 0.0),
        ("direction = [0, 0, -1]\nup = [0, 1, 0]\nroll = 30\n", 30.0),
        (
            "direction = [0, 0, -1]\nup = [0, 3, 0.5]\nroll = -45\n",
            -45.0,
        ),
        // The same view from an orbit: elevation 90 looks down -z, with up the meridian's tangent,
        // -x at azimuth 0 (right +y); turned 90 degrees so +y is up, then 30 degrees more.
        ("azimuth = 0\nelevation = 90\nroll = 120\n", 30.0),
    ] {
        let scene = Scene::parse(&format!("[view]\n{view}"), "test").unwrap();
        let params = scene.render_params();
        let cam = params.camera(&marker_volume(DVec3::ZERO), params.direction().unwrap());
        let r = f64::to_radians(roll);
        assert!(
            (cam.right - DVec3::new(r.cos(), -r.sin(), 0.0)).length() < 1e-9,
            "{view}: right {}",
            cam.right
        );
        assert!(
            (cam.up - DVec3::new(r.sin(), r.cos(), 0.0)).length() < 1e-9,
            "{view}: up {}",
            cam.up
        );
        for offset in [DVec3::new(0.0, 7.0, 0.0), DVec3::new(7.0, 0.0, 0.0)] {
            let vol = marker_volume(offset);
            let want = angle_diff(offset.y.atan2(offset.x).to_degrees() + roll, 0.0);
            assert!(angle_diff(predicted_angle(&cam, offset), want).abs() < 1e-6);
            let (img, _) = frame_image(&format!("[view]\n{view}"), &vol);
            let seen = marker_angle(&img);
            assert!(
                angle_diff(seen, want).abs() < 2.0,
                "frame model, {view}, marker {offset}: at {seen:.1} degrees, want {want:.1}"
            );
            let img = render_reference(&vol, &tf, &scene_params(&scene)).unwrap();
            let seen = marker_angle(&img);
            assert!(
                angle_diff(seen, want).abs() < 2.0,
                "reference, {view}, marker {offset}: at {seen:.1} degrees, want {want:.1}"
            );
        }
    }
}

fn scene_params(scene: &Scene) -> RenderParams {
    RenderParams {
        width: IMG,
        height: IMG,
        mode: CompositeMode::Mip,
        step: 0.5,
        ..scene.render_params()
    }
}

/// A bare direction takes +z as up, and +y looking exactly along z; roll 0 leaves the camera bit
/// for bit as it was.
#[test]
fn bare_directions_and_zero_roll() {
    let vol = marker_volume(DVec3::ZERO);
    let cam = Camera::new(DVec3::NEG_Z, vol.dims, vol.spacing, 8, 8);
    assert_eq!((cam.right, cam.up), (DVec3::X, DVec3::Y));
    let cam = Camera::new(DVec3::Z, vol.dims, vol.spacing, 8, 8);
    assert_eq!((cam.right, cam.up), (DVec3::NEG_X, DVec3::Y));
    let d = DVec3::new(0.3, -0.8, 0.2).normalize();
    let cam = Camera::new(d, vol.dims, vol.spacing, 8, 8);
    assert!(cam.up.z > 0.0 && cam.up.dot(d).abs() < 1e-12);
    assert_eq!(cam.rolled(0.0), cam);
    assert_eq!(camera::default_up(d), DVec3::Z);
}

/// An up vector along the view, a zero or NaN up and a NaN roll are refused, naming the field.
#[test]
fn bad_up_and_roll_are_refused() {
    let err = |text: &str| Scene::parse(text, "s.toml").unwrap_err().to_string();
    let e = err("[view]\ndirection = [0, 0, -1]\nup = [0, 0, 2]\n");
    assert!(
        e.contains("view.up") && e.contains("names no image up"),
        "{e}"
    );
    let e = err("[view]\nazimuth = 0\nelevation = 90\nup = [0, 0, 1]\n");
    assert!(e.contains("view.up"), "{e}");
    assert!(err("[view]\nup = [0, 0, 0]\n").contains("view.up"));
    assert!(err("[view]\nup = [nan, 0, 1]\n").contains("view.up"));
    assert!(err("[view]\nroll = nan\n").contains("view.roll"));
    // Just outside the limit is taken.
    let a = (2.0 * camera::MIN_UP_DEGREES).to_radians();
    Scene::parse(
        &format!(
            "[view]\ndirection = [0, 0, -1]\nup = [{}, 0, {}]\n",
            a.sin(),
            a.cos()
        ),
        "s.toml",
    )
    .unwrap();
}

/// Command-line angles apply over a scene's direction: the one not given is the direction's.
#[test]
fn command_line_angles_replace_the_direction() {
    let mut v = ViewSpec {
        direction: Some([0.0, 2.0, -2.0]),
        ..Default::default()
    };
    v.set_angles(Some(30.0), None);
    assert_eq!(v.direction, None);
    assert_eq!(v.azimuth, 30.0);
    assert!((v.elevation - 45.0).abs() < 1e-9, "{}", v.elevation);
    let mut v = ViewSpec {
        direction: Some([0.0, 2.0, -2.0]),
        ..Default::default()
    };
    v.set_angles(None, Some(10.0));
    assert!(
        (v.azimuth + 90.0).abs() < 1e-9 && v.elevation == 10.0,
        "{v:?}"
    );
    // Nothing given: the direction stays.
    let mut v = ViewSpec {
        direction: Some([0.0, 2.0, -2.0]),
        ..Default::default()
    };
    v.set_angles(None, None);
    assert_eq!(v.direction, Some([0.0, 2.0, -2.0]));
}
