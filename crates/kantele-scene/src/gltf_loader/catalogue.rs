//! The file's scenes, animations and material variants (`KHR_materials_variants`): what
//! [`crate::SceneInfo`] lists of them, and the user's choice of scene and of variant.
//!
//! The extension's JSON is read here rather than through the `gltf` crate's optional support,
//! which maps a material index that is out of range to the default material without a word;
//! here it is an error naming the primitive.

use std::collections::HashMap;

use gltf::accessor::Dimensions;
use serde_json::Value;

use super::{named, Loader};
use crate::accessor::{read_f32, BufferData};
use crate::budget::Budget;
use crate::choices::{unknown_scene, unknown_variant, FileAnimation, FileScene};
use crate::{LoadError, SceneChoice};

/// The extension's name, in the file's `extensions` objects.
const VARIANTS: &str = "KHR_materials_variants";

/// An animation's name and its samplers' input (key time) accessors, read from the JSON before
/// the document is patched.
#[derive(Debug)]
pub(super) struct AnimationTimes {
    /// Its `name`.
    name: Option<String>,
    /// Per sampler: its `input` accessor index (`None`: missing or not an index).
    inputs: Vec<Option<usize>>,
}

/// The animations of the glTF JSON `root`, charged to `budget`.
pub(super) fn read_animations(
    root: &Value,
    budget: &mut Budget,
) -> Result<Vec<AnimationTimes>, String> {
    let Some(list) = root.get("animations").and_then(Value::as_array) else {
        return Ok(Vec::new());
    };
    let mut animations = Vec::new();
    for animation in list {
        let name = animation.get("name").and_then(Value::as_str);
        let samplers = animation.get("samplers").and_then(Value::as_array);
        let count = samplers.map_or(0, Vec::len) as u64;
        let bytes = 64 + name.map_or(0, str::len) as u64 + 16 * count;
        budget.charge(1, bytes, "the list of animations")?;
        let inputs = samplers
            .into_iter()
            .flatten()
            .map(|s| {
                s.get("input")
                    .and_then(Value::as_u64)
                    .and_then(|i| usize::try_from(i).ok())
            })
            .collect();
        animations.push(AnimationTimes {
            name: name.map(str::to_string),
            inputs,
        });
    }
    Ok(animations)
}

impl<'a> Loader<'a> {
    /// Lists the file's animations and variants in the info and resolves the variant choice.
    pub(super) fn catalogue(&mut self) -> Result<(), LoadError> {
        self.list_animations()?;
        let variants = self.variant_names();
        self.budget
            .charge(
                variants.iter().map(|v| 32 + v.len() as u64).sum(),
                1,
                "the list of material variants",
            )
            .map_err(|e| self.invalid(e))?;
        if let Some(wanted) = &self.options.variant {
            match variants.iter().position(|v| v == wanted) {
                Some(index) => self.info.variant_loaded = Some(index),
                None => return Err(self.invalid(unknown_variant(wanted, &variants))),
            }
        }
        self.info.variants = variants;
        Ok(())
    }

    /// The names of the file's material variants (`variant N` for one without a name).
    fn variant_names(&self) -> Vec<String> {
        let list = self
            .document
            .extension_value(VARIANTS)
            .and_then(|v| v.get("variants"))
            .and_then(Value::as_array);
        list.into_iter()
            .flatten()
            .enumerate()
            .map(|(i, v)| named(v.get("name").and_then(Value::as_str), "variant", i))
            .collect()
    }

    /// The material the chosen variant maps `primitive` to, if a variant was chosen and the
    /// primitive's `mappings` name it (the first mapping that does).
    pub(super) fn variant_material(
        &self,
        primitive: &gltf::Primitive,
        what: &str,
    ) -> Result<Option<usize>, LoadError> {
        let Some(variant) = self.info.variant_loaded else {
            return Ok(None);
        };
        let Some(extension) = primitive.extension_value(VARIANTS) else {
            return Ok(None);
        };
        let index = |v: &Value| v.as_u64().and_then(|i| usize::try_from(i).ok());
        let mappings = extension.get("mappings").and_then(Value::as_array);
        for mapping in mappings.into_iter().flatten() {
            let variants = mapping.get("variants").and_then(Value::as_array);
            if !variants
                .into_iter()
                .flatten()
                .any(|v| index(v) == Some(variant))
            {
                continue;
            }
            let count = self.document.materials().len();
            return match mapping.get("material").and_then(index) {
                Some(material) if material < count => Ok(Some(material)),
                Some(material) => Err(self.invalid(format!(
                    "{what}: {VARIANTS} maps variant '{}' to material {material}, but the file has {count} materials",
                    self.info.variants[variant]
                ))),
                None => Err(self.invalid(format!(
                    "{what}: a {VARIANTS} mapping of variant '{}' has no material index",
                    self.info.variants[variant]
                ))),
            };
        }
        Ok(None)
    }

    /// Lists the file's scenes in the info and picks the one to draw: the chosen one, else
    /// the default (`scene`, else scene 0); `None` when the file has none and none was chosen.
    pub(super) fn chosen_scene(&mut self) -> Result<Option<gltf::Scene<'a>>, LoadError> {
        let document = self.document;
        let count = document.scenes().len();
        self.budget
            .charge(count as u64, 64, "the list of scenes")
            .map_err(|e| self.invalid(e))?;
        let default = document
            .default_scene()
            .map(|s| s.index())
            .or((count > 0).then_some(0));
        let mut scenes: Vec<FileScene> = document
            .scenes()
            .map(|s| FileScene {
                index: s.index(),
                name: s.name().map(str::to_string),
                is_default: Some(s.index()) == default,
                loaded: false,
            })
            .collect();
        let chosen = match &self.options.scene {
            None => default,
            Some(choice) => {
                let found = match choice {
                    SceneChoice::Index(i) => (*i < count).then_some(*i),
                    SceneChoice::Name(name) => scenes
                        .iter()
                        .position(|s| s.name.as_deref() == Some(name.as_str())),
                };
                if found.is_none() {
                    return Err(self.invalid(unknown_scene(choice, &scenes)));
                }
                found
            }
        };
        if let Some(i) = chosen {
            scenes[i].loaded = true;
        }
        self.info.scenes = scenes;
        Ok(chosen.and_then(|i| document.scenes().nth(i)))
    }

    /// Lists the animations with their lengths: the largest key time of their samplers.
    fn list_animations(&mut self) -> Result<(), LoadError> {
        let animations = std::mem::take(&mut self.animations);
        self.budget
            .charge(animations.len() as u64, 64, "the list of animations")
            .map_err(|e| self.invalid(e))?;
        let mut latest_time: HashMap<usize, Option<f32>> = HashMap::new();
        for (index, animation) in animations.into_iter().enumerate() {
            let label = named(animation.name.as_deref(), "animation", index);
            let mut duration: Option<f32> = None;
            for input in animation.inputs {
                let latest = match input {
                    None => Err("a sampler has no input accessor".to_string()),
                    Some(accessor) => match latest_time.get(&accessor) {
                        Some(&known) => Ok(known),
                        None => {
                            let read = self.latest_key_time(accessor);
                            latest_time.insert(accessor, read.clone().ok().flatten());
                            read
                        }
                    },
                };
                match latest {
                    Ok(Some(t)) => duration = Some(duration.map_or(t, |d| d.max(t))),
                    Ok(None) => {}
                    Err(e) => self.info.warn(format!(
                        "animation '{label}': {e}; its duration leaves that sampler out"
                    )),
                }
            }
            self.info.animations.push(FileAnimation {
                index,
                name: animation.name,
                duration_seconds: duration.unwrap_or(0.0),
            });
        }
        Ok(())
    }

    /// The largest finite key time of input accessor `index`: its `max`, else the largest of
    /// its values (`None`: it has none).
    fn latest_key_time(&mut self, index: usize) -> Result<Option<f32>, String> {
        let accessor = self.document.accessors().nth(index).ok_or_else(|| {
            format!(
                "sampler input accessor {index} is not in the file ({} accessors)",
                self.document.accessors().len()
            )
        })?;
        if accessor.dimensions() != Dimensions::Scalar {
            return Err(format!("sampler input accessor {index} is not SCALAR"));
        }
        let declared = accessor
            .max()
            .and_then(|m| m.get(0).and_then(Value::as_f64))
            .map(|m| m as f32)
            .filter(|m| m.is_finite());
        if declared.is_some() {
            return Ok(declared);
        }
        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let label = format!("animation input accessor {index}");
        let times = read_f32(&data, &accessor, &mut self.budget, &label)?;
        Ok(times.into_iter().filter(|t| t.is_finite()).reduce(f32::max))
    }
}
