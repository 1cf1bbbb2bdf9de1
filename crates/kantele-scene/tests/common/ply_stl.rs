//! PLY and STL writers for the tests and the fuzz seeds: small meshes in every encoding the
//! loaders read.

/// A PLY payload encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlyFormat {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

impl PlyFormat {
    /// The three encodings.
    pub const ALL: [PlyFormat; 3] = [
        PlyFormat::Ascii,
        PlyFormat::BinaryLittleEndian,
        PlyFormat::BinaryBigEndian,
    ];

    /// The name in the `format` line.
    pub fn name(self) -> &'static str {
        match self {
            PlyFormat::Ascii => "ascii",
            PlyFormat::BinaryLittleEndian => "binary_little_endian",
            PlyFormat::BinaryBigEndian => "binary_big_endian",
        }
    }
}

/// A mesh to write as PLY: positions, optional per-vertex normals, texture coordinates and
/// 8-bit colours, and faces of any size.
#[derive(Clone, Debug, Default)]
pub struct PlyMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    /// Written as `s`, `t` (v up, as PLY writers do).
    pub texcoords: Option<Vec<[f32; 2]>>,
    /// Written as `red`, `green`, `blue`, `alpha` (uchar).
    pub colors: Option<Vec<[u8; 4]>>,
    /// `vertex_indices` of each face; `None` writes no face element at all (a point cloud).
    pub faces: Option<Vec<Vec<i32>>>,
    /// Writes an `edge` element (which the loader skips) between the vertices and the faces.
    pub edge_element: bool,
}

/// One value of a record, as PLY stores it.
enum Value {
    Float(f32),
    UChar(u8),
    Int(i32),
}

/// Appends one record (one line in ASCII).
fn write_record(out: &mut Vec<u8>, values: &[Value], format: PlyFormat) {
    for (k, value) in values.iter().enumerate() {
        match format {
            PlyFormat::Ascii => {
                if k > 0 {
                    out.push(b' ');
                }
                let text = match value {
                    Value::Float(v) => format!("{v}"),
                    Value::UChar(v) => format!("{v}"),
                    Value::Int(v) => format!("{v}"),
                };
                out.extend_from_slice(text.as_bytes());
            }
            PlyFormat::BinaryLittleEndian => match value {
                Value::Float(v) => out.extend(v.to_le_bytes()),
                Value::UChar(v) => out.push(*v),
                Value::Int(v) => out.extend(v.to_le_bytes()),
            },
            PlyFormat::BinaryBigEndian => match value {
                Value::Float(v) => out.extend(v.to_be_bytes()),
                Value::UChar(v) => out.push(*v),
                Value::Int(v) => out.extend(v.to_be_bytes()),
            },
        }
    }
    if format == PlyFormat::Ascii {
        out.push(b'\n');
    }
}

impl PlyMesh {
    /// The mesh as a PLY file. Every vertex also has a `confidence` property that the loader
    /// does not read.
    pub fn to_ply(&self, format: PlyFormat) -> Vec<u8> {
        let mut header = format!(
            "ply\nformat {} 1.0\ncomment written by a Kantele test\nelement vertex {}\n\
             property float x\nproperty float y\nproperty float z\nproperty float confidence\n",
            format.name(),
            self.positions.len()
        );
        if self.normals.is_some() {
            header += "property float nx\nproperty float ny\nproperty float nz\n";
        }
        if self.texcoords.is_some() {
            header += "property float s\nproperty float t\n";
        }
        if self.colors.is_some() {
            header += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
        }
        if self.edge_element {
            header += "element edge 1\nproperty int vertex1\nproperty int vertex2\n";
        }
        if let Some(faces) = &self.faces {
            header += &format!(
                "element face {}\nproperty list uchar int vertex_indices\n",
                faces.len()
            );
        }
        header += "end_header\n";
        let mut out = header.into_bytes();
        for (i, p) in self.positions.iter().enumerate() {
            let mut values: Vec<Value> = p.iter().map(|&v| Value::Float(v)).collect();
            values.push(Value::Float(0.5));
            if let Some(normals) = &self.normals {
                values.extend(normals[i].iter().map(|&v| Value::Float(v)));
            }
            if let Some(texcoords) = &self.texcoords {
                values.extend(texcoords[i].iter().map(|&v| Value::Float(v)));
            }
            if let Some(colors) = &self.colors {
                values.extend(colors[i].iter().map(|&v| Value::UChar(v)));
            }
            write_record(&mut out, &values, format);
        }
        if self.edge_element {
            write_record(&mut out, &[Value::Int(0), Value::Int(1)], format);
        }
        for face in self.faces.iter().flatten() {
            let mut values = vec![Value::UChar(face.len() as u8)];
            values.extend(face.iter().map(|&i| Value::Int(i)));
            write_record(&mut out, &values, format);
        }
        out
    }
}

/// A unit quad at z = 0 (corners 0–3) and a pentagon, a house shape at z = 1 (corners 4–8),
/// facing +z, with normals, texture coordinates and colours, and the `edge` element.
pub fn quad_and_pentagon() -> PlyMesh {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 1.0],
        [3.0, 0.0, 1.0],
        [3.0, 1.0, 1.0],
        [2.5, 1.5, 1.0],
        [2.0, 1.0, 1.0],
    ];
    let n = positions.len();
    PlyMesh {
        normals: Some(vec![[0.0, 0.0, 1.0]; n]),
        texcoords: Some(positions.iter().map(|p| [p[0] / 3.0, p[1] / 2.0]).collect()),
        colors: Some((0..n).map(|i| [255, 128, 0, 255 - i as u8]).collect()),
        faces: Some(vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7, 8]]),
        edge_element: true,
        positions,
    }
}

/// The corners of a triangle.
pub type Triangle = [[f32; 3]; 3];

/// A tetrahedron with its faces wound counter-clockwise seen from outside.
pub fn tetrahedron() -> Vec<Triangle> {
    let [a, b, c, d] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    vec![[a, c, b], [a, b, d], [a, d, c], [b, c, d]]
}

/// The triangles as ASCII STL: `solid` line as given, each facet with a zero normal (the
/// loader takes normals from the winding), `line_end` after every line.
pub fn stl_ascii(triangles: &[Triangle], solid_line: &str, line_end: &str) -> Vec<u8> {
    let mut text = format!("{solid_line}{line_end}");
    for t in triangles {
        text += &format!("  facet normal 0 0 0{line_end}    outer loop{line_end}");
        for v in t {
            text += &format!("      vertex {} {} {}{line_end}", v[0], v[1], v[2]);
        }
        text += &format!("    endloop{line_end}  endfacet{line_end}");
    }
    text += &format!("endsolid{line_end}");
    text.into_bytes()
}

/// The triangles as binary STL with the given header text (at most 80 bytes) and facet normal.
pub fn stl_binary(triangles: &[Triangle], header: &[u8], normal: [f32; 3]) -> Vec<u8> {
    let mut out = vec![b' '; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        for v in std::iter::once(&normal).chain(t) {
            for c in v {
                out.extend(c.to_le_bytes());
            }
        }
        out.extend([0, 0]);
    }
    out
}

/// The seeds of the `ply` fuzz target (`fuzz/corpus/ply`): names and bytes.
pub fn ply_fuzz_seeds() -> Vec<(String, Vec<u8>)> {
    let mut seeds: Vec<(String, Vec<u8>)> = PlyFormat::ALL
        .iter()
        .map(|&format| {
            (
                format!("seed-quad-pentagon-{}.ply", format.name()),
                quad_and_pentagon().to_ply(format),
            )
        })
        .collect();
    let mut cloud = quad_and_pentagon();
    cloud.faces = None;
    cloud.edge_element = false;
    cloud.texcoords = None;
    seeds.push((
        "seed-point-cloud.ply".to_string(),
        cloud.to_ply(PlyFormat::BinaryBigEndian),
    ));
    seeds
}

/// The seeds of the `stl` fuzz target (`fuzz/corpus/stl`): names and bytes.
pub fn stl_fuzz_seeds() -> Vec<(String, Vec<u8>)> {
    let triangles = tetrahedron();
    vec![
        (
            "seed-tetrahedron-ascii.stl".to_string(),
            stl_ascii(&triangles, "solid tetrahedron", "\n"),
        ),
        (
            "seed-tetrahedron-solid-header.stl".to_string(),
            stl_binary(&triangles, b"solid tetrahedron", [0.0, 0.0, 1.0]),
        ),
    ]
}
