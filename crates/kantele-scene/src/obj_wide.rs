//! OBJ `l` (polyline) and `p` (points) statements, which `tobj` does not read: the positions
//! they use and their index lists, grouped by material in file order. A polyline `l a b c`
//! becomes the segments `(a, b), (b, c)`; `v/vt` references use the position only; negative
//! indices count back from the last `v` read so far.

use glam::Vec3;
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
    /// The statements' groups, in file order.
    pub groups: Vec<WideGroup>,
    /// One message per statement that could not be read (skipped).
    pub warnings: Vec<String>,
}

/// Reads the `v`, `usemtl`, `l` and `p` statements of OBJ text.
pub(crate) fn read_lines_points(source: &str) -> ObjWide {
    let mut out = ObjWide::default();
    let mut material: Option<String> = None;
    for (number, line) in source.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        match keyword {
            Some("v") => {
                let mut c = [0.0f32; 3];
                for value in &mut c {
                    *value = words
                        .next()
                        .and_then(|w| w.parse().ok())
                        .unwrap_or(f32::NAN);
                }
                out.positions.push(Vec3::from_array(c));
            }
            Some("usemtl") => {
                material = Some(words.next().unwrap_or(UNNAMED_MATERIAL).to_string());
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
    out.groups.retain(|g| !g.indices.is_empty());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polylines_become_segments_and_points_keep_their_vertices() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\np 1/1 -1\nusemtl red\nl -3 -1\nl 9 1\n";
        let wide = read_lines_points(text);
        assert_eq!(wide.positions.len(), 3);
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
}
