//! OBJ `l` (polyline) and `p` (points) statements, which `tobj` does not read: the positions
//! they use and their index lists, grouped by material in file order. A polyline `l a b c`
//! becomes the segments `(a, b), (b, c)`; `v/vt` references use the position only; negative
//! indices count back from the last `v` read so far. A file of vertices alone (no faces,
//! lines or points) is read as one group of points, every vertex in file order.

use glam::{Vec3, Vec4};
use kantele_rules::color::srgb_to_linear;
use kantele_rules::scene::Topology;

use crate::obj_text::UNNAMED_MATERIAL;

/// Consecutive `l` or `p` statements under one material.
#[derive(Debug, PartialEq)]
pub(crate) struct WideGroup {
    /// The `usemtl` name in force (`None` before the first).
    pub material: Option<String>,
    /// Lines or points.
    pub topology: Topology,
    /// Indices into [`ObjWide::positions`]: two per segment or one per point.
    pub indices: Vec<u32>,
}

/// What the `l` and `p` statements of a file draw.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct ObjWide {
    /// Every `v` of the file, in order.
    pub positions: Vec<Vec3>,
    /// The colour of every `v` (`v x y z r g b`; white for those without one), when at least
    /// one has a colour.
    pub colors: Option<Vec<Vec4>>,
    /// The statements' groups, in file order.
    pub groups: Vec<WideGroup>,
    /// One message per statement that could not be read (skipped).
    pub warnings: Vec<String>,
}

/// Reads the `v`, `usemtl`, `l` and `p` statements of OBJ text (decoded and joined, see
/// `obj_text`); with `all_points`, every vertex is also one point of a first group.
pub(crate) fn read_lines_points(source: &str, all_points: bool) -> ObjWide {
    let mut out = ObjWide::default();
    let mut colors: Vec<Vec4> = Vec::new();
    let mut any_color = false;
    let mut material: Option<String> = None;
    for (number, line) in source.lines().enumerate() {
        let line = line.trim_start();
        let mut words = line.split_whitespace();
        let keyword = words.next();
        match keyword {
            Some("v") => {
                let values: Vec<f32> = words
                    .map(|w| w.parse().unwrap_or(f32::NAN))
                    .take(7)
                    .collect();
                let value = |i: usize| values.get(i).copied().unwrap_or(f32::NAN);
                let position = Vec3::new(value(0), value(1), value(2));
                // `v x y z w`: homogeneous, as `tobj` reads it.
                let w = if values.len() == 4 { value(3) } else { 1.0 };
                out.positions
                    .push(if w != 0.0 { position / w } else { position });
                if values.len() == 6 {
                    any_color = true;
                    colors.push(vertex_color([value(3), value(4), value(5)]));
                } else {
                    colors.push(Vec4::ONE);
                }
            }
            Some("usemtl") => {
                let name = line["usemtl".len()..].trim();
                let name = if name.is_empty() {
                    UNNAMED_MATERIAL
                } else {
                    name
                };
                material = Some(name.to_string());
            }
            Some(kind @ ("l" | "p")) => {
                let count = out.positions.len();
                let resolve = |word: &str| -> Option<u32> {
                    let k: i64 = word.split('/').next()?.parse().ok()?;
                    let index = if k > 0 { k - 1 } else { count as i64 + k };
                    (0..count as i64).contains(&index).then_some(index as u32)
                };
                let Some(vertices) = words.map(resolve).collect::<Option<Vec<u32>>>() else {
                    out.warnings.push(format!(
                        "line {}: '{kind}' statement with a bad vertex reference is skipped",
                        number + 1
                    ));
                    continue;
                };
                let topology = if kind == "l" {
                    Topology::Lines
                } else {
                    Topology::Points
                };
                let same = out
                    .groups
                    .last()
                    .is_some_and(|g| g.topology == topology && g.material == material);
                if !same {
                    out.groups.push(WideGroup {
                        material: material.clone(),
                        topology,
                        indices: Vec::new(),
                    });
                }
                let Some(group) = out.groups.last_mut() else {
                    continue;
                };
                if topology == Topology::Lines {
                    for w in vertices.windows(2) {
                        group.indices.extend([w[0], w[1]]);
                    }
                } else {
                    group.indices.extend(vertices);
                }
            }
            _ => {}
        }
    }
    if all_points {
        out.groups.insert(
            0,
            WideGroup {
                material: None,
                topology: Topology::Points,
                indices: (0..out.positions.len() as u32).collect(),
            },
        );
    }
    out.groups.retain(|g| !g.indices.is_empty());
    out.colors = any_color.then_some(colors);
    out
}

/// The colour of an OBJ vertex (`v x y z r g b`): sRGB-encoded values in [0, 1], as the tools
/// that write them (MeshLab, ZBrush, Open3D) store display colours and as PLY's are read;
/// clamped to [0, 1] and decoded to linear. Opaque.
pub(crate) fn vertex_color(rgb: [f32; 3]) -> Vec4 {
    let channel = |c: f32| srgb_to_linear(if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) });
    Vec4::new(channel(rgb[0]), channel(rgb[1]), channel(rgb[2]), 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polylines_become_segments_and_points_keep_their_vertices() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\np 1/1 -1\nusemtl red\nl -3 -1\nl 9 1\n";
        let wide = read_lines_points(text, false);
        assert_eq!(wide.positions.len(), 3);
        assert_eq!(wide.colors, None);
        assert_eq!(
            wide.groups,
            vec![
                WideGroup {
                    material: None,
                    topology: Topology::Lines,
                    indices: vec![0, 1, 1, 2],
                },
                WideGroup {
                    material: None,
                    topology: Topology::Points,
                    indices: vec![0, 2],
                },
                WideGroup {
                    material: Some("red".into()),
                    topology: Topology::Lines,
                    indices: vec![0, 2],
                },
            ]
        );
        assert_eq!(wide.warnings.len(), 1, "{:?}", wide.warnings);
        assert!(wide.warnings[0].starts_with("line 8:"));
    }

    #[test]
    fn vertices_alone_are_points_with_their_colours() {
        let wide = read_lines_points("v 0 0 0 1 0 0\nv 2 0 0 2\n  usemtl a b\np 2\n", true);
        assert_eq!(wide.groups.len(), 2);
        assert_eq!(wide.positions[1], Vec3::X);
        assert_eq!(wide.groups[0].topology, Topology::Points);
        assert_eq!(wide.groups[0].indices, vec![0, 1]);
        assert_eq!(wide.groups[1].material.as_deref(), Some("a b"));
        assert_eq!(
            wide.colors,
            Some(vec![Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::ONE])
        );
    }
}
