//! PLY (polygon file format): ASCII, `binary_little_endian` and `binary_big_endian`, parsed by
//! `ply-rs-bw` one element at a time straight into the mesh's arrays.
//!
//! Read: the `vertex` element's `x`, `y`, `z` (any scalar type), normals (`nx`, `ny`, `nz`),
//! texture coordinates (`u`/`v`, `s`/`t`, `texture_u`/`texture_v`, `texture_s`/`texture_t`)
//! and colours (`red`, `green`, `blue`, optional `alpha`: integers as 0–255, 16-bit ones as
//! 0–65535, floats as 0–1; sRGB-encoded like an image's, decoded to linear), and the `face`
//! element's `vertex_indices` (or `vertex_index`) lists of any length, triangulated by ear
//! clipping. A file without faces is a point cloud. Other elements and properties are skipped.
//!
//! Before anything the file controls is allocated, the declared element counts are checked
//! against the bytes that follow the header (every element takes at least one byte), and the
//! arrays they need are charged to the budget.

use std::io::Cursor;
use std::path::Path;

use glam::{Vec2, Vec3, Vec4};
use kantele_rules::color::srgb_to_linear;
use kantele_rules::scene::{Mesh, Topology};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use crate::budget::{vec_with_capacity, Budget};
use crate::ear_clip::triangulate_faces;
use crate::mesh_util::{first_index_out_of_range, flat_normals};
use crate::single_mesh::load_single_mesh;
use crate::{one_line, LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Loads a `.ply` file.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    load_single_mesh(path, options, |bytes, name, budget, info| {
        read_mesh(&bytes, name, budget, info)
    })
}

/// The mesh of a PLY file's bytes (its material is left at 0).
fn read_mesh(
    bytes: &[u8],
    name: String,
    budget: &mut Budget,
    info: &mut SceneInfo,
) -> Result<Mesh, String> {
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = Parser::<SkippedRecord>::new()
        .read_header(&mut reader)
        .map_err(|e| format!("not a valid PLY file: {}", one_line(&e.to_string())))?;
    let payload_bytes = (bytes.len() as u64).saturating_sub(reader.get_ref().position());
    check_counts(&header, payload_bytes)?;
    let layout = VertexLayout::of(&header, info)?;
    let vertex_count = header.elements.get("vertex").map_or(0, |e| e.count);
    let mut vertices = VertexArrays::new(vertex_count, &layout, budget)?;
    let mut faces = FaceLists::default();
    let last_needed = header
        .elements
        .values()
        .rposition(|e| e.name == "vertex" || e.name == "face");
    for (k, element) in header.elements.values().enumerate() {
        match element.name.as_str() {
            "vertex" => read_elements(&mut reader, header.encoding, element, |record| {
                vertices.push(&record, &layout);
                Ok(())
            })?,
            "face" => {
                if element.count > 0 {
                    check_face_element(element)?;
                }
                read_elements(&mut reader, header.encoding, element, |record| {
                    faces.push(record, budget)
                })?;
            }
            other => {
                info.ignore(format!("PLY element '{other}'"));
                // Elements after the last one needed are not read at all.
                if last_needed.is_some_and(|last| k < last) {
                    read_elements(&mut reader, header.encoding, element, |_: SkippedRecord| {
                        Ok(())
                    })?;
                }
            }
        }
    }
    if header
        .comments
        .iter()
        .any(|c| c.trim_start().starts_with("TextureFile"))
    {
        info.ignore("the texture file named in a PLY comment");
    }
    build_mesh(name, vertices, faces, budget)
}

/// The mesh of the vertices and faces read: triangles, or points when the file has no faces
/// (no face element, or one of none).
fn build_mesh(
    name: String,
    vertices: VertexArrays,
    faces: FaceLists,
    budget: &mut Budget,
) -> Result<Mesh, String> {
    let n = vertices.positions.len();
    if let Some((position, index)) = first_index_out_of_range(&faces.indices, n) {
        let face = face_of_corner(&faces.arities, position);
        return Err(format!(
            "face {face}: vertex index {index} is out of range for {n} vertices"
        ));
    }
    let point_cloud = faces.arities.is_empty();
    let mut mesh = Mesh {
        name,
        positions: vertices.positions,
        normals: vertices.normals,
        texcoords: vertices.texcoords,
        colors: vertices.colors,
        ..Mesh::default()
    };
    if point_cloud {
        budget.charge(n as u64, 4, "the points")?;
        mesh.topology = Topology::Points;
        mesh.indices = (0..n as u32).collect();
        return Ok(mesh);
    }
    mesh.topology = Topology::Triangles;
    mesh.indices = triangulate_faces(&faces.indices, &faces.arities, &mesh.positions, budget)?;
    drop(faces);
    if mesh.normals.is_none() && !mesh.indices.is_empty() {
        // De-indexed: one vertex (position, normal, texcoord, colour) per corner.
        budget.charge(mesh.indices.len() as u64, 48, "flat normals")?;
        flat_normals(&mut mesh);
    }
    Ok(mesh)
}

/// The number of the face that holds corner `corner` (an index into the flat index list).
fn face_of_corner(arities: &[u32], corner: usize) -> usize {
    let mut end = 0usize;
    for (face, &arity) in arities.iter().enumerate() {
        end += arity as usize;
        if corner < end {
            return face;
        }
    }
    arities.len()
}

/// Refuses a header whose elements cannot fit in the bytes after it (every binary element
/// takes its scalars' and list counts' bytes, every ASCII one two bytes a property and at least
/// one a line), so no count the file declares is trusted beyond the file's own size.
fn check_counts(header: &Header, payload_bytes: u64) -> Result<(), String> {
    let mut needed: u128 = 0;
    for element in header.elements.values() {
        let each = match header.encoding {
            Encoding::Ascii => (2 * element.properties.len() as u64).max(1),
            Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => element
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) | PropertyType::List(t, _) => scalar_bytes(t),
                })
                .sum::<u64>()
                .max(1),
        };
        needed += element.count as u128 * each as u128;
        // The last ASCII line may lack its line break.
        let available = match header.encoding {
            Encoding::Ascii => payload_bytes as u128 + 1,
            _ => payload_bytes as u128,
        };
        if needed > available {
            return Err(format!(
                "the header declares {} '{}' elements, more than the {payload_bytes} bytes after it can hold (a truncated file or a wrong count)",
                element.count, element.name
            ));
        }
    }
    Ok(())
}

/// Bytes of one binary scalar.
fn scalar_bytes(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Refuses a `face` element whose corner list is missing or not of integers.
fn check_face_element(element: &ElementDef) -> Result<(), String> {
    let list = element
        .properties
        .values()
        .find(|p| is_corner_list(&p.name))
        .ok_or("the face element has no vertex_indices list")?;
    match &list.data_type {
        PropertyType::List(_, ScalarType::Float | ScalarType::Double) => {
            Err("the faces' vertex_indices are not integers".to_string())
        }
        PropertyType::List(..) => Ok(()),
        PropertyType::Scalar(_) => Err("the faces' vertex_indices is not a list".to_string()),
    }
}

/// Whether a face property is the list of its corners.
fn is_corner_list(name: &str) -> bool {
    matches!(name, "vertex_indices" | "vertex_index")
}

/// Reads the `element.count` records of an element, in the file's encoding, handing each to
/// `take`; errors name the element and the record.
fn read_elements<E: PropertyAccess>(
    reader: &mut Reader<Cursor<&[u8]>>,
    encoding: Encoding,
    element: &ElementDef,
    mut take: impl FnMut(E) -> Result<(), String>,
) -> Result<(), String> {
    let parser = Parser::<E>::new();
    for k in 0..element.count {
        let cursor = reader.get_mut();
        let record = match encoding {
            Encoding::Ascii => {
                let line = next_line(cursor)
                    .map_err(|e| format!("{} {k} of {}: {e}", element.name, element.count))?;
                parser.read_ascii_element(line, element)
            }
            Encoding::BinaryLittleEndian => parser.read_little_endian_element(cursor, element),
            Encoding::BinaryBigEndian => parser.read_big_endian_element(cursor, element),
        };
        let record = record.map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                format!(
                    "the file ends inside {} {k} of {} (truncated)",
                    element.name, element.count
                )
            } else {
                format!(
                    "{} {k} of {}: {}",
                    element.name,
                    element.count,
                    one_line(&e.to_string())
                )
            }
        })?;
        take(record)?;
    }
    Ok(())
}

/// The next line of ASCII data (with its line break), as text.
fn next_line<'a>(cursor: &mut Cursor<&'a [u8]>) -> Result<&'a str, String> {
    let data: &'a [u8] = cursor.get_ref();
    let start = usize::try_from(cursor.position()).unwrap_or(usize::MAX);
    let rest = data.get(start..).unwrap_or_default();
    if rest.is_empty() {
        return Err("the file ends here (truncated)".to_string());
    }
    let end = rest
        .iter()
        .position(|&b| b == b'\n')
        .map_or(rest.len(), |i| i + 1);
    cursor.set_position((start + end) as u64);
    std::str::from_utf8(&rest[..end]).map_err(|_| "the line is not ASCII text".to_string())
}

/// A vertex property Kantele reads.
#[derive(Clone, Copy, Debug, PartialEq)]
enum VertexSlot {
    X,
    Y,
    Z,
    Nx,
    Ny,
    Nz,
    U,
    V,
    Red,
    Green,
    Blue,
    Alpha,
}

const SLOT_COUNT: usize = 12;

impl VertexSlot {
    /// The slot a vertex property's name fills, under the names writers use.
    fn of(name: &str) -> Option<Self> {
        Some(match name {
            "x" => Self::X,
            "y" => Self::Y,
            "z" => Self::Z,
            "nx" | "normal_x" => Self::Nx,
            "ny" | "normal_y" => Self::Ny,
            "nz" | "normal_z" => Self::Nz,
            "u" | "s" | "texture_u" | "texture_s" => Self::U,
            "v" | "t" | "texture_v" | "texture_t" => Self::V,
            "red" | "diffuse_red" => Self::Red,
            "green" | "diffuse_green" => Self::Green,
            "blue" | "diffuse_blue" => Self::Blue,
            "alpha" => Self::Alpha,
            _ => return None,
        })
    }
}

/// One vertex as read: the value of each slot (0 where the file has none).
struct VertexRecord {
    values: [f32; SLOT_COUNT],
}

impl VertexRecord {
    fn set(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        match VertexSlot::of(name) {
            Some(slot) => {
                self.values[slot as usize] = value;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }

    fn get(&self, slot: VertexSlot) -> f32 {
        self.values[slot as usize]
    }
}

impl PropertyAccess for VertexRecord {
    fn new() -> Self {
        Self {
            values: [0.0; SLOT_COUNT],
        }
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value)
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
}

/// Which attributes the file's vertices have, from the header.
struct VertexLayout {
    normals: bool,
    texcoords: bool,
    colors: bool,
    /// What the red, green and blue channels are divided by to make 0–1.
    color_scale: [f32; 3],
    /// The same for alpha; `None` when the file has none (opaque).
    alpha_scale: Option<f32>,
}

impl VertexLayout {
    /// The layout of the `vertex` element (none: no attributes). Positions are required; an
    /// attribute with only some of its properties is left out with a warning.
    fn of(header: &Header, info: &mut SceneInfo) -> Result<Self, String> {
        let mut types: [Option<&ScalarType>; SLOT_COUNT] = [None; SLOT_COUNT];
        let Some(vertex) = header.elements.get("vertex") else {
            return Ok(Self {
                normals: false,
                texcoords: false,
                colors: false,
                color_scale: [1.0; 3],
                alpha_scale: None,
            });
        };
        for property in vertex.properties.values() {
            if let (Some(slot), PropertyType::Scalar(t)) =
                (VertexSlot::of(&property.name), &property.data_type)
            {
                types[slot as usize] = Some(t);
            }
        }
        let has = |slots: &[VertexSlot]| slots.iter().all(|&s| types[s as usize].is_some());
        let some = |slots: &[VertexSlot]| slots.iter().any(|&s| types[s as usize].is_some());
        use VertexSlot::*;
        if !has(&[X, Y, Z]) {
            return Err("the vertex element has no x, y and z".to_string());
        }
        let mut attribute = |slots: &[VertexSlot], what: &str| {
            if has(slots) {
                true
            } else {
                if some(slots) {
                    info.warn(format!(
                        "the vertices have only some of their {what} properties; {what} are not read"
                    ));
                }
                false
            }
        };
        let normals = attribute(&[Nx, Ny, Nz], "normal");
        let texcoords = attribute(&[U, V], "texture coordinate");
        let colors = attribute(&[Red, Green, Blue], "colour");
        let scale = |slot: VertexSlot| types[slot as usize].map_or(1.0, color_scale);
        Ok(Self {
            normals,
            texcoords,
            colors,
            color_scale: [scale(Red), scale(Green), scale(Blue)],
            alpha_scale: types[Alpha as usize].map(color_scale),
        })
    }
}

/// What a colour channel of the given type is divided by: 16-bit integers span 0–65535, other
/// integers 0–255, floats 0–1.
fn color_scale(t: &ScalarType) -> f32 {
    match t {
        ScalarType::Short | ScalarType::UShort => 65535.0,
        ScalarType::Float | ScalarType::Double => 1.0,
        ScalarType::Char | ScalarType::UChar | ScalarType::Int | ScalarType::UInt => 255.0,
    }
}

/// The vertex attributes being read, in the mesh's form.
struct VertexArrays {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    texcoords: Option<Vec<Vec2>>,
    colors: Option<Vec<Vec4>>,
}

impl VertexArrays {
    /// Room for `count` vertices of `layout`, charged to the budget first.
    fn new(count: usize, layout: &VertexLayout, budget: &mut Budget) -> Result<Self, String> {
        if u32::try_from(count).is_err() {
            return Err(format!("{count} vertices are more than 2^32 − 1"));
        }
        let each = 12
            + 12 * layout.normals as u64
            + 8 * layout.texcoords as u64
            + 16 * layout.colors as u64;
        budget.charge(count as u64, each, "the vertices")?;
        let what = "the vertices";
        Ok(Self {
            positions: vec_with_capacity(count, what)?,
            normals: layout
                .normals
                .then(|| vec_with_capacity(count, what))
                .transpose()?,
            texcoords: layout
                .texcoords
                .then(|| vec_with_capacity(count, what))
                .transpose()?,
            colors: layout
                .colors
                .then(|| vec_with_capacity(count, what))
                .transpose()?,
        })
    }

    /// Appends one vertex.
    fn push(&mut self, record: &VertexRecord, layout: &VertexLayout) {
        use VertexSlot::*;
        let vec3 = |a, b, c| Vec3::new(record.get(a), record.get(b), record.get(c));
        self.positions.push(vec3(X, Y, Z));
        if let Some(normals) = &mut self.normals {
            normals.push(vec3(Nx, Ny, Nz));
        }
        // PLY's v runs upwards; Kantele's downwards from the image's top row.
        if let Some(texcoords) = &mut self.texcoords {
            texcoords.push(Vec2::new(record.get(U), 1.0 - record.get(V)));
        }
        if let Some(colors) = &mut self.colors {
            let unit = |value: f32, scale: f32| (value / scale).clamp(0.0, 1.0);
            let [red, green, blue] = layout.color_scale;
            let channel = |slot, scale| srgb_to_linear(unit(record.get(slot), scale));
            let [r, g, b] = [
                channel(Red, red),
                channel(Green, green),
                channel(Blue, blue),
            ];
            let a = layout
                .alpha_scale
                .map_or(1.0, |scale| unit(record.get(Alpha), scale));
            colors.push(Vec4::new(r, g, b, a));
        }
    }
}

/// One face as read: its corners, and the first negative index if any.
struct FaceRecord {
    corners: Vec<u32>,
    negative: Option<i64>,
}

impl FaceRecord {
    fn set_corners<T: Copy + Into<i64>>(
        &mut self,
        name: &str,
        values: &[T],
    ) -> PropertyAccessResult {
        if !is_corner_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.corners.clear();
        self.corners.reserve(values.len());
        for &value in values {
            let value: i64 = value.into();
            match u32::try_from(value) {
                Ok(index) => self.corners.push(index),
                Err(_) => {
                    self.negative.get_or_insert(value);
                }
            }
        }
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for FaceRecord {
    fn new() -> Self {
        Self {
            corners: Vec::new(),
            negative: None,
        }
    }
    fn set_list_char(&mut self, name: &str, values: Vec<i8>) -> PropertyAccessResult {
        self.set_corners(name, &values)
    }
    fn set_list_uchar(&mut self, name: &str, values: Vec<u8>) -> PropertyAccessResult {
        self.set_corners(name, &values)
    }
    fn set_list_short(&mut self, name: &str, values: Vec<i16>) -> PropertyAccessResult {
        self.set_corners(name, &values)
    }
    fn set_list_ushort(&mut self, name: &str, values: Vec<u16>) -> PropertyAccessResult {
        self.set_corners(name, &values)
    }
    fn set_list_int(&mut self, name: &str, values: Vec<i32>) -> PropertyAccessResult {
        self.set_corners(name, &values)
    }
    fn set_list_uint(&mut self, name: &str, values: Vec<u32>) -> PropertyAccessResult {
        if !is_corner_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.corners = values;
        PropertyAccessResult::Set
    }
}

/// The faces read so far: every face's corners in one list, and each face's corner count.
#[derive(Default)]
struct FaceLists {
    indices: Vec<u32>,
    arities: Vec<u32>,
}

impl FaceLists {
    /// Appends one face, charging its corners to the budget (with room for the lists to grow).
    fn push(&mut self, face: FaceRecord, budget: &mut Budget) -> Result<(), String> {
        let number = self.arities.len();
        if let Some(index) = face.negative {
            return Err(format!("face {number}: vertex index {index} is negative"));
        }
        let arity = u32::try_from(face.corners.len())
            .map_err(|_| format!("face {number} has more than 2^32 − 1 corners"))?;
        budget.charge(face.corners.len() as u64 + 1, 8, "the faces")?;
        self.arities.push(arity);
        self.indices.extend_from_slice(&face.corners);
        Ok(())
    }
}

/// A record of an element that is skipped: nothing is kept.
struct SkippedRecord;

impl PropertyAccess for SkippedRecord {
    fn new() -> Self {
        SkippedRecord
    }
}
