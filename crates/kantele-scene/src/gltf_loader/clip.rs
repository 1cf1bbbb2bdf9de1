//! The file's animations: their names, the one a load plays ([`AnimationChoice`]) and its
//! channels read into [`Keyframes`].
//!
//! The loader keeps the animations' JSON aside before the `gltf` crate validates the document
//! (see `gltf_patch`), so channels it could not express (`KHR_animation_pointer`, unknown
//! paths) never make a file invalid; they are reported as ignored. The chosen animation is
//! checked here: every problem in it is a one-line error.

use gltf::accessor::{DataType, Dimensions};
use serde_json::Value;

use super::animation::{Interpolation, Keyframes};
use crate::accessor::{read_f32, BufferData};
use crate::budget::Budget;

pub(crate) use crate::choices::AnimationChoice;

/// What a channel animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Path {
    /// The node's translation (3 values).
    Translation,
    /// The node's rotation (a quaternion, 4 values).
    Rotation,
    /// The node's scale (3 values).
    Scale,
    /// The morph target weights of the node's mesh (one per target).
    Weights,
}

/// One channel: a node's property and its keyframes.
#[derive(Clone, Debug)]
pub(crate) struct Channel {
    /// The node's index in the file.
    pub node: usize,
    /// The property.
    pub path: Path,
    /// Its keyframes (`width` 3, 4, or the number of morph targets).
    pub keys: Keyframes,
}

/// The animation a load plays.
#[derive(Clone, Debug)]
pub(crate) struct Clip {
    /// Its index in the file.
    pub index: usize,
    /// Its name (`animation N` when it has none).
    pub name: String,
    /// Its channels, in file order (a later channel of the same node and path wins).
    pub channels: Vec<Channel>,
}

impl Clip {
    /// The earliest first key and the latest last key of its channels ((0, 0) without any).
    pub(crate) fn time_range(&self) -> (f32, f32) {
        let mut range: Option<(f32, f32)> = None;
        for channel in &self.channels {
            let (a, b) = channel.keys.time_range();
            range = Some(range.map_or((a, b), |(lo, hi)| (lo.min(a), hi.max(b))));
        }
        range.unwrap_or((0.0, 0.0))
    }
}

/// The name of animation `index` for reports: its own, or `animation N`.
pub(crate) fn animation_name(animation: &Value, index: usize) -> String {
    match animation.get("name").and_then(Value::as_str) {
        Some(n) if !n.is_empty() => n.to_string(),
        _ => format!("animation {index}"),
    }
}

/// The channel paths of all animations that are not played (not one of `translation`,
/// `rotation`, `scale`, `weights`, or without a target node), once each, for the list of
/// ignored features.
pub(crate) fn unplayable_paths(animations: &[Value]) -> Vec<String> {
    let mut out = Vec::new();
    let channels = animations
        .iter()
        .filter_map(|a| a.get("channels").and_then(Value::as_array))
        .flatten();
    for channel in channels {
        let target = channel.get("target");
        let path = target
            .and_then(|t| t.get("path"))
            .and_then(Value::as_str)
            .unwrap_or("(none)");
        let known = matches!(path, "translation" | "rotation" | "scale" | "weights");
        let has_node = target.and_then(|t| t.get("node")).is_some();
        let feature = if !known {
            format!("animation channels with path '{path}'")
        } else if !has_node {
            "animation channels without a target node".to_string()
        } else {
            continue;
        };
        if !out.contains(&feature) {
            out.push(feature);
        }
    }
    out
}

/// The index of the chosen animation, or a one-line error that lists the file's animations.
pub(crate) fn choose(animations: &[Value], choice: &AnimationChoice) -> Result<usize, String> {
    let found = match choice {
        AnimationChoice::Index(i) => (*i < animations.len()).then_some(*i),
        AnimationChoice::Name(name) => animations
            .iter()
            .position(|a| a.get("name").and_then(Value::as_str) == Some(name.as_str())),
    };
    let asked = match choice {
        AnimationChoice::Index(i) => format!("animation {i}"),
        AnimationChoice::Name(name) => format!("animation '{name}'"),
    };
    found.ok_or_else(|| {
        if animations.is_empty() {
            return format!("{asked} was asked for, but the file has no animations");
        }
        const SHOWN: usize = 20;
        let mut list: Vec<String> = animations
            .iter()
            .enumerate()
            .take(SHOWN)
            .map(|(i, a)| format!("{i} '{}'", animation_name(a, i)))
            .collect();
        if animations.len() > SHOWN {
            list.push(format!("… ({} more)", animations.len() - SHOWN));
        }
        crate::one_line(&format!(
            "{asked} is not in the file; its animations are: {}",
            list.join(", ")
        ))
    })
}

/// Reads animation `index` (its JSON `animation`) into a [`Clip`]; `node_count` is the number of
/// nodes in the file. Channels that [`unplayable_paths`] names are left out.
pub(crate) fn read_clip(
    animation: &Value,
    index: usize,
    node_count: usize,
    document: &gltf::Document,
    data: &BufferData,
    budget: &mut Budget,
) -> Result<Clip, String> {
    let name = animation_name(animation, index);
    let what = format!("animation '{name}'");
    let samplers = animation
        .get("samplers")
        .and_then(Value::as_array)
        .map_or(&[][..], Vec::as_slice);
    let channels = animation
        .get("channels")
        .and_then(Value::as_array)
        .map_or(&[][..], Vec::as_slice);
    let mut out = Vec::new();
    for (c, channel) in channels.iter().enumerate() {
        let what = format!("{what} channel {c}");
        let target = channel.get("target");
        let path = match target.and_then(|t| t.get("path")).and_then(Value::as_str) {
            Some("translation") => Path::Translation,
            Some("rotation") => Path::Rotation,
            Some("scale") => Path::Scale,
            Some("weights") => Path::Weights,
            _ => continue,
        };
        let Some(node) = target.and_then(|t| t.get("node")) else {
            continue;
        };
        let node = node
            .as_u64()
            .and_then(|n| usize::try_from(n).ok())
            .filter(|&n| n < node_count)
            .ok_or_else(|| {
                format!("{what}: target node {node} is not one of the file's {node_count} nodes")
            })?;
        let sampler_index = channel.get("sampler").and_then(Value::as_u64);
        let sampler = sampler_index
            .and_then(|s| samplers.get(usize::try_from(s).ok()?))
            .ok_or_else(|| {
                format!(
                    "{what}: sampler {} is not one of the animation's {} samplers",
                    channel.get("sampler").unwrap_or(&Value::Null),
                    samplers.len()
                )
            })?;
        let what = format!("{what} (sampler {})", sampler_index.unwrap_or_default());
        let keys = read_sampler(sampler, path, document, data, budget)
            .map_err(|e| format!("{what}: {e}"))?;
        out.push(Channel { node, path, keys });
    }
    Ok(Clip {
        index,
        name,
        channels: out,
    })
}

/// Reads a sampler's input (times) and output (values) for a channel of `path`.
fn read_sampler(
    sampler: &Value,
    path: Path,
    document: &gltf::Document,
    data: &BufferData,
    budget: &mut Budget,
) -> Result<Keyframes, String> {
    let interpolation_name = sampler.get("interpolation").and_then(Value::as_str);
    let interpolation = Interpolation::from_name(interpolation_name).ok_or_else(|| {
        format!(
            "interpolation '{}' is not STEP, LINEAR or CUBICSPLINE",
            interpolation_name.unwrap_or_default()
        )
    })?;
    let accessor = |key: &str| -> Result<gltf::Accessor, String> {
        let index = sampler.get(key);
        index
            .and_then(Value::as_u64)
            .and_then(|i| document.accessors().nth(usize::try_from(i).ok()?))
            .ok_or_else(|| {
                format!(
                    "{key} accessor {} is not one of the file's {} accessors",
                    index.unwrap_or(&Value::Null),
                    document.accessors().len()
                )
            })
    };
    let input = accessor("input")?;
    let output = accessor("output")?;
    if input.dimensions() != Dimensions::Scalar || input.data_type() != DataType::F32 {
        return Err(format!(
            "input accessor {} is {:?} {:?}, not float SCALAR times",
            input.index(),
            input.data_type(),
            input.dimensions()
        ));
    }
    let float_or_normalized = output.data_type() == DataType::F32
        || (output.normalized() && output.data_type() != DataType::U32);
    let (dimensions, ok_type) = match path {
        Path::Translation | Path::Scale => (Dimensions::Vec3, output.data_type() == DataType::F32),
        Path::Rotation => (Dimensions::Vec4, float_or_normalized),
        Path::Weights => (Dimensions::Scalar, float_or_normalized),
    };
    if output.dimensions() != dimensions || !ok_type {
        return Err(format!(
            "output accessor {} is {:?} {:?}{}, which glTF does not allow for {path:?}",
            output.index(),
            output.data_type(),
            output.dimensions(),
            if output.normalized() {
                " (normalized)"
            } else {
                ""
            }
        ));
    }
    let keys = input.count();
    let per_key_elements = match interpolation {
        Interpolation::CubicSpline => 3,
        _ => 1,
    };
    let width = match path {
        Path::Translation | Path::Scale => 3,
        Path::Rotation => 4,
        Path::Weights => {
            let slots = keys.checked_mul(per_key_elements).filter(|&s| s > 0);
            match slots {
                Some(s) if output.count() % s == 0 && output.count() > 0 => output.count() / s,
                _ => {
                    return Err(format!(
                    "output accessor {} has {} weights, not a whole number per key of {keys} keys",
                    output.index(),
                    output.count()
                ))
                }
            }
        }
    };
    let label = format!("input accessor {}", input.index());
    let times = read_f32(data, &input, budget, &label)?;
    let label = format!("output accessor {}", output.index());
    let values = read_f32(data, &output, budget, &label)?;
    Keyframes::new(times, values, width, interpolation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn choices_by_index_and_name_and_unknown_ones_list_the_animations() {
        let list = vec![json!({"name": "Walk"}), json!({}), json!({"name": "Run"})];
        assert_eq!(choose(&list, &AnimationChoice::Index(1)), Ok(1));
        assert_eq!(choose(&list, &AnimationChoice::Name("Run".into())), Ok(2));
        let e = choose(&list, &AnimationChoice::Name("Jump".into())).unwrap_err();
        assert_eq!(
            e,
            "animation 'Jump' is not in the file; its animations are: 0 'Walk', 1 'animation 1', 2 'Run'"
        );
        let e = choose(&list, &AnimationChoice::Index(3)).unwrap_err();
        assert!(e.starts_with("animation 3 is not in the file"), "{e}");
        let e = choose(&[], &AnimationChoice::Index(0)).unwrap_err();
        assert!(e.contains("no animations"), "{e}");
    }

    #[test]
    fn unplayable_channels_are_named_once() {
        let list = vec![json!({"channels": [
            {"target": {"path": "pointer"}},
            {"target": {"path": "pointer"}},
            {"target": {"path": "rotation"}},
            {"target": {"node": 0, "path": "scale"}}
        ]})];
        assert_eq!(
            unplayable_paths(&list),
            vec![
                "animation channels with path 'pointer'".to_string(),
                "animation channels without a target node".to_string()
            ]
        );
    }
}
