//! Options the perspective examples share (`slab_perspective`, `er_perspective`).

use cube5_model::render::CompositeMode;
use cube5_model::scene::Scene;
use std::path::PathBuf;

type Error = Box<dyn std::error::Error>;

/// `scenes/head-perspective.toml` with the command line's options applied: the shared ones
/// ([`scene_option`], `--png DIR`, returned) and the example's own (`own(flag, value)` returns
/// `Ok(false)` for a flag it does not know). Every option takes a value.
pub fn perspective_scene(
    mut own: impl FnMut(&str, &str) -> Result<bool, Error>,
) -> Result<(Scene, Option<PathBuf>), Error> {
    let mut scene = Scene::load(&cube5_model::repo_root().join("scenes/head-perspective.toml"))?;
    let mut png = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let value = args.next().ok_or(format!("{a}: needs a value"))?;
        if a == "--png" {
            png = Some(PathBuf::from(&value));
        } else if !(scene_option(&mut scene, &a, &value)? || own(&a, &value)?) {
            return Err(format!("unknown option {a}").into());
        }
    }
    Ok((scene, png))
}

/// A comma-separated list.
pub fn list<T: std::str::FromStr>(v: &str) -> Result<Vec<T>, T::Err> {
    v.split(',').map(str::parse).collect()
}

/// Applies `--size N`, `--image PX` (square) or `--mode composite|mip` to `scene`; `Ok(false)` when
/// `flag` is none of them.
pub fn scene_option(scene: &mut Scene, flag: &str, value: &str) -> Result<bool, Error> {
    match flag {
        "--size" => scene.volume.size = value.parse()?,
        "--image" => {
            scene.image.width = value.parse()?;
            scene.image.height = scene.image.width;
        }
        "--mode" => {
            scene.render.mode = match value {
                "mip" => CompositeMode::Mip,
                "composite" => CompositeMode::Composite,
                _ => return Err(format!("--mode {value}: composite or mip").into()),
            }
        }
        _ => return Ok(false),
    }
    Ok(true)
}
