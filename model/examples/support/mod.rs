//! Options the perspective examples share (`slab_perspective`, `er_perspective`).

use cube5_model::render::CompositeMode;
use cube5_model::scene::Scene;

/// Applies `--size N`, `--image PX` (square) or `--mode composite|mip` to `scene`; `Ok(false)` when
/// `flag` is none of them.
pub fn scene_option(
    scene: &mut Scene,
    flag: &str,
    value: &str,
) -> Result<bool, Box<dyn std::error::Error>> {
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
