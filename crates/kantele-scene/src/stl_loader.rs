//! STL (stereolithography): binary and ASCII, facets parsed by `stl_io`.
//!
//! A file is binary when its size is exactly `84 + 50 × n` for the triangle count `n` in its
//! header, also when the header starts with `solid` as some exporters write it; otherwise text
//! starting with `solid` is ASCII (one or more `solid … endsolid` blocks), and anything else is
//! binary with the count checked against the size.
//!
//! Every triangle gets its own three corners with the normal of its corners' winding, as the
//! renderer computes flat normals: the facet normals of the file are not read (exporters often
//! write zeros or normals that disagree with the winding, which would light a face from the
//! wrong side; the winding-based normal is always consistent with the face the camera sees).

use std::io::Cursor;
use std::path::Path;

use glam::Vec3;
use kantele_rules::scene::{Mesh, Topology};

use crate::budget::{vec_with_capacity, Budget};
use crate::single_mesh::{face_normals, load_single_mesh};
use crate::{one_line, LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Bytes of a binary STL header: 80 free bytes and the triangle count.
const BINARY_HEADER_BYTES: u64 = 84;

/// Bytes of one binary STL triangle: normal, three corners, attribute word.
const BINARY_TRIANGLE_BYTES: u64 = 50;

/// Fewest bytes an ASCII facet can take (`facet normal 0 0 0`, `outer loop`, three
/// `vertex 0 0 0`, `endloop`, `endfacet`, each on a line of its own): bounds the triangles of a
/// text before it is parsed.
const MIN_ASCII_FACET_BYTES: u64 = 86;

/// Bytes of the mesh per triangle: three positions, normals and indices.
const MESH_BYTES_PER_TRIANGLE: u64 = 3 * (12 + 12 + 4);

/// Loads an `.stl` file.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    load_single_mesh(path, options, read_mesh)
}

/// How an STL file is encoded.
#[derive(Debug, PartialEq)]
enum StlKind {
    /// Binary with this many triangles (and possibly bytes after them).
    Binary(u64),
    /// ASCII text.
    Ascii,
}

/// Tells binary from ASCII STL; an error for a file that is neither.
fn stl_kind(bytes: &[u8]) -> Result<StlKind, String> {
    let size = bytes.len() as u64;
    let declared = bytes
        .get(80..84)
        .and_then(|b| <[u8; 4]>::try_from(b).ok())
        .map(|b| u32::from_le_bytes(b) as u64);
    let binary_size = |n: u64| BINARY_HEADER_BYTES + BINARY_TRIANGLE_BYTES * n;
    if let Some(n) = declared.filter(|&n| binary_size(n) == size) {
        return Ok(StlKind::Binary(n));
    }
    if bytes.trim_ascii_start().starts_with(b"solid") {
        return Ok(StlKind::Ascii);
    }
    match declared {
        Some(n) if binary_size(n) <= size => Ok(StlKind::Binary(n)),
        Some(n) => Err(format!(
            "the binary STL header declares {n} triangles ({} bytes) but the file has {size} bytes (truncated?)",
            binary_size(n)
        )),
        None => Err(format!(
            "not an STL file: {size} bytes, too short for binary STL and not text starting with 'solid'"
        )),
    }
}

/// The mesh of an STL file's bytes (its material is left at 0).
fn read_mesh(
    mut bytes: Vec<u8>,
    name: String,
    budget: &mut Budget,
    info: &mut SceneInfo,
) -> Result<Mesh, String> {
    let positions = match stl_kind(&bytes)? {
        StlKind::Binary(count) => {
            let size = bytes.len() as u64;
            let used = BINARY_HEADER_BYTES + BINARY_TRIANGLE_BYTES * count;
            if size > used {
                info.warn(format!(
                    "{} bytes after the last of the {count} triangles are ignored",
                    size - used
                ));
            }
            budget.charge(count, MESH_BYTES_PER_TRIANGLE, "the triangles")?;
            // stl_io reads text whose first line starts with `solid ` as ASCII: a line break
            // first (the header is free text) makes it read the binary data.
            if let Some(first) = bytes.first_mut() {
                *first = b'\n';
            }
            let mut positions = vec_with_capacity(3 * count as usize, "the triangles")?;
            read_triangles(&bytes, &mut positions)?;
            positions
        }
        StlKind::Ascii => {
            let most = bytes.len() as u64 / MIN_ASCII_FACET_BYTES;
            budget.charge(most, MESH_BYTES_PER_TRIANGLE, "the triangles")?;
            budget.charge(bytes.len() as u64, 1, "the STL text")?;
            read_ascii(&bytes, info)?
        }
    };
    drop(bytes);
    let normals = face_normals(&positions);
    let indices = (0..positions.len() as u32).collect();
    Ok(Mesh {
        name,
        positions,
        normals: Some(normals),
        indices,
        topology: Topology::Triangles,
        ..Mesh::default()
    })
}

/// Appends the corners of every triangle of one binary STL or one ASCII `solid … endsolid`
/// block (as `stl_io` reads it) to `positions`.
fn read_triangles(stl: &[u8], positions: &mut Vec<Vec3>) -> Result<(), String> {
    let mut cursor = Cursor::new(stl);
    let triangles = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| format!("not a valid STL file: {}", one_line(&e.to_string())))?;
    for (k, triangle) in triangles.enumerate() {
        let triangle = triangle.map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                format!("the file ends inside triangle {k} (truncated)")
            } else {
                format!("triangle {k}: {}", one_line(&e.to_string()))
            }
        })?;
        positions.extend(triangle.vertices.map(|v| Vec3::from_array(v.0)));
    }
    Ok(())
}

/// The corners of the triangles of every `solid … endsolid` block of an ASCII STL. Each block
/// goes to `stl_io` with its `solid` and `endsolid` lines rewritten (a bare `solid`, a name in
/// another encoding than UTF-8), so that only the facets are left to it.
fn read_ascii(text: &[u8], info: &mut SceneInfo) -> Result<Vec<Vec3>, String> {
    let mut positions = Vec::new();
    let mut block: Vec<u8> = Vec::new();
    let mut in_block = false;
    let mut blocks = 0usize;
    for (number, line) in text.split(|&b| b == b'\n').enumerate() {
        let first_word = line
            .split(|b| b.is_ascii_whitespace())
            .find(|w| !w.is_empty())
            .unwrap_or_default();
        match first_word {
            b"solid" => {
                if in_block {
                    return Err(format!(
                        "line {}: 'solid' inside another solid (missing 'endsolid')",
                        number + 1
                    ));
                }
                in_block = true;
                block.clear();
                block.extend_from_slice(b"solid stl\n");
            }
            b"endsolid" if in_block => {
                block.extend_from_slice(b"endsolid\n");
                read_triangles(&block, &mut positions)?;
                in_block = false;
                blocks += 1;
            }
            b"" => {}
            _ if in_block => {
                block.extend_from_slice(line);
                block.push(b'\n');
            }
            _ => {
                return Err(format!(
                    "line {}: text outside 'solid … endsolid'",
                    number + 1
                ))
            }
        }
    }
    if in_block {
        return Err("the file ends before 'endsolid' (truncated)".to_string());
    }
    if blocks > 1 {
        info.warn(format!("{blocks} solids in one file are drawn as one mesh"));
    }
    Ok(positions)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary(header: &[u8], count: u32, triangles: usize) -> Vec<u8> {
        let mut bytes = vec![b' '; 80];
        bytes[..header.len()].copy_from_slice(header);
        bytes.extend(count.to_le_bytes());
        bytes.extend(std::iter::repeat_n(0u8, 50 * triangles));
        bytes
    }

    #[test]
    fn binary_and_ascii_are_told_apart_by_size() {
        assert_eq!(
            stl_kind(&binary(b"solid made by a CAD tool", 2, 2)),
            Ok(StlKind::Binary(2))
        );
        assert_eq!(stl_kind(&binary(b"x", 1, 1)), Ok(StlKind::Binary(1)));
        assert_eq!(stl_kind(b"solid cube\nendsolid cube\n"), Ok(StlKind::Ascii));
        assert_eq!(stl_kind(b"  solid\n"), Ok(StlKind::Ascii));
        // A "solid" header with a size that does not match is text.
        assert_eq!(stl_kind(&binary(b"solid x", 5, 1)), Ok(StlKind::Ascii));
        // Trailing bytes after the triangles are accepted; too few bytes are not.
        assert_eq!(stl_kind(&binary(b"x", 1, 2)), Ok(StlKind::Binary(1)));
        let e = stl_kind(&binary(b"x", 3, 2)).unwrap_err();
        assert!(e.contains("3 triangles") && e.contains("truncated"), "{e}");
        assert!(stl_kind(b"").unwrap_err().contains("not an STL file"));
    }
}
