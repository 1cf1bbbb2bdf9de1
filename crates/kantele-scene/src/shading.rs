//! What a loader sets up for the shading model it chose: PBR scenes without lights get the
//! built-in studio environment and, without a background of their own, a grey one.

use glam::Vec4;
use kantele_rules::scene::{LightKind, PunctualLight, Scene, Shading};
use kantele_rules::shade::environment::{Environment, EnvironmentLight};
use kantele_rules::shade::pbr::MAX_LIGHTS;

use crate::budget::Budget;
use crate::environment_file::load_environment;
use crate::{EnvironmentChoice, LoadOptions, SceneInfo};

/// The background of PBR scenes whose file gives none: a linear grey of 0.2 (sRGB 124), on
/// which black and white materials both show.
pub(crate) const PBR_BACKGROUND: Vec4 = Vec4::new(0.2, 0.2, 0.2, 1.0);

/// Sets `scene.shading` (`options.shading`, else `default`) and what goes with it. Lambert
/// scenes draw the first directional light only (a note says when point or spot lights are
/// left out). PBR scenes keep at most [`MAX_LIGHTS`] lights (a warning names the rest), take
/// the environment, exposure and tone map of `options` (the studio when the file has no lights
/// and no environment was chosen), and get [`PBR_BACKGROUND`] unless `clear_color_given`.
/// An environment file that cannot be read is an error of the load.
pub(crate) fn apply(
    scene: &mut Scene,
    info: &mut SceneInfo,
    options: &LoadOptions,
    default: Shading,
    clear_color_given: bool,
    budget: &mut Budget,
) -> Result<(), String> {
    let shading = options.shading.unwrap_or(default);
    scene.shading = shading;
    match shading {
        Shading::Lambert => {
            let directional = |l: &PunctualLight| l.kind == LightKind::Directional;
            if !scene.lights.iter().all(directional) {
                info.ignore("point and spot lights (Lambert shading)");
            }
        }
        Shading::Pbr => {
            if scene.lights.len() > MAX_LIGHTS {
                info.warn(format!(
                    "the file has {} lights; the first {MAX_LIGHTS} are drawn",
                    scene.lights.len()
                ));
                scene.lights.truncate(MAX_LIGHTS);
            }
            let environment = match &options.environment {
                EnvironmentChoice::Default if scene.lights.is_empty() => {
                    Some(Environment::studio())
                }
                EnvironmentChoice::Default | EnvironmentChoice::None => None,
                EnvironmentChoice::Studio => Some(Environment::studio()),
                EnvironmentChoice::File(path) => Some(
                    load_environment(path, budget)
                        .map_err(|e| format!("environment {}: {e}", path.display()))?,
                ),
            };
            let finite_or = |v: f32, default: f32| if v.is_finite() { v } else { default };
            scene.environment = environment.map(|environment| EnvironmentLight {
                environment,
                intensity: finite_or(options.environment_intensity, 1.0).max(0.0),
                rotation: finite_or(options.environment_rotation_degrees, 0.0).to_radians(),
            });
            scene.exposure = finite_or(options.exposure, 0.0);
            scene.tonemap = options.tonemap;
            if !clear_color_given {
                scene.clear_color = PBR_BACKGROUND;
            }
        }
    }
    Ok(())
}
