//! `KHR_draco_mesh_compression`: primitives whose attributes and indices are one Draco stream.
//!
//! As for `EXT_meshopt_compression`, the decoded data reaches the accessors as buffer views:
//! before the `gltf` crate reads the JSON, each accessor that a Draco primitive fills (the
//! attributes its extension maps, and its indices) gets a buffer view of its own, appended to
//! the file's (the spec says to ignore an accessor's own `bufferView`, `byteOffset` and
//! `sparse` there). After the buffers are read, each stream is decoded once and its data
//! written into those views in the accessor's component type, so that the accessor readers,
//! the budget and every check apply as for uncompressed data.

use std::collections::HashMap;

use draco_oxide_core::attribute::{Attribute, ComponentDataType};
use draco_oxide_core::types::PointIdx;
use gltf::accessor::DataType;
use serde_json::{json, Map, Value};

use crate::budget::{vec_with_capacity, Budget};
use crate::draco_stream::{decode_mesh, Expected};

/// The extension's name.
const EXTENSION: &str = "KHR_draco_mesh_compression";

/// One Draco primitive, as found in the JSON.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DracoPrimitive {
    /// Where it is, for messages: `mesh M primitive P`.
    pub what: String,
    /// The buffer view holding the stream.
    pub stream_view: usize,
    /// Attributes the stream fills: (accessor, Draco unique id, the view made for it).
    pub attributes: Vec<(usize, u64, usize)>,
    /// The index accessor and the view made for it.
    pub indices: Option<(usize, usize)>,
    /// The POSITION accessor (its count is the vertex count).
    pub position: usize,
}

/// Finds the Draco primitives of the JSON document and gives each accessor they fill a buffer
/// view of its own; an error for a primitive that this loader cannot decode.
pub(crate) fn patch_json(root: &mut Map<String, Value>) -> Result<Vec<DracoPrimitive>, String> {
    let mut found = Vec::new();
    let Some(Value::Array(meshes)) = root.get("meshes") else {
        return Ok(found);
    };
    let index = |v: Option<&Value>| {
        v.and_then(Value::as_u64)
            .and_then(|i| usize::try_from(i).ok())
    };
    let view_count = root
        .get("bufferViews")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let mut next_view = view_count;
    // Accessor → the primitive and stream source it was given to.
    let mut filled: HashMap<usize, (usize, Option<u64>)> = HashMap::new();
    for (m, mesh) in meshes.iter().enumerate() {
        let primitives = mesh.get("primitives").and_then(Value::as_array);
        for (p, primitive) in primitives.into_iter().flatten().enumerate() {
            let Some(ext) = primitive.pointer(&format!("/extensions/{EXTENSION}")) else {
                continue;
            };
            let what = format!("mesh {m} primitive {p} ({EXTENSION})");
            let mode = primitive.get("mode").and_then(Value::as_u64).unwrap_or(4);
            if mode != 4 && mode != 5 {
                return Err(format!(
                    "{what}: mode {mode}; Draco primitives are TRIANGLES or TRIANGLE_STRIP"
                ));
            }
            let stream_view = index(ext.get("bufferView"))
                .filter(|&v| v < view_count)
                .ok_or_else(|| format!("{what}: 'bufferView' is missing or out of range"))?;
            let map = ext
                .get("attributes")
                .and_then(Value::as_object)
                .ok_or_else(|| format!("{what}: 'attributes' is missing"))?;
            let primitive_attributes = primitive.get("attributes").and_then(Value::as_object);
            let position = primitive_attributes
                .and_then(|a| index(a.get("POSITION")))
                .ok_or_else(|| format!("{what} has no POSITION attribute"))?;
            let mut entry = DracoPrimitive {
                what: what.clone(),
                stream_view,
                attributes: Vec::new(),
                indices: None,
                position,
            };
            let mut claim = |accessor: usize, uid: Option<u64>| -> Result<usize, String> {
                let source = (stream_view, uid);
                if let Some(previous) = filled.insert(accessor, source) {
                    if previous != source {
                        return Err(format!(
                            "{what}: accessor {accessor} is also filled from other Draco data"
                        ));
                    }
                }
                next_view += 1;
                Ok(next_view - 1)
            };
            for (semantic, uid) in map {
                let uid = uid
                    .as_u64()
                    .ok_or_else(|| format!("{what}: the Draco id of {semantic} is not a number"))?;
                let accessor = primitive_attributes
                    .and_then(|a| index(a.get(semantic)))
                    .ok_or_else(|| {
                        format!("{what}: {semantic} is compressed but not an attribute of the primitive")
                    })?;
                let view = claim(accessor, Some(uid))?;
                entry.attributes.push((accessor, uid, view));
            }
            if let Some(accessor) = index(primitive.get("indices")) {
                let view = claim(accessor, None)?;
                entry.indices = Some((accessor, view));
            }
            found.push(entry);
        }
    }
    // Point the accessors at their new views (numbered in this order), each view as long as
    // its accessor's data and in the stream's buffer.
    let mut new_views = Vec::new();
    for d in &found {
        let buffer = root
            .get("bufferViews")
            .and_then(|v| v.get(d.stream_view))
            .and_then(|v| v.get("buffer"))
            .cloned()
            .unwrap_or(json!(0));
        let accessors = root
            .get_mut("accessors")
            .and_then(Value::as_array_mut)
            .ok_or_else(|| format!("{}: the file has no accessors", d.what))?;
        let slots = d
            .attributes
            .iter()
            .map(|&(a, _, v)| (a, v))
            .chain(d.indices);
        for (accessor, view) in slots {
            let object = accessors
                .get_mut(accessor)
                .and_then(Value::as_object_mut)
                .ok_or_else(|| format!("{}: accessor {accessor} does not exist", d.what))?;
            object.remove("sparse");
            object.remove("byteOffset");
            object.insert("bufferView".to_string(), json!(view));
            let length = element_bytes(object).saturating_mul(count(object)).max(1);
            debug_assert_eq!(view, view_count + new_views.len());
            new_views.push(json!({"buffer": buffer, "byteLength": length}));
        }
    }
    if !new_views.is_empty() {
        root.get_mut("bufferViews")
            .and_then(Value::as_array_mut)
            .ok_or("'bufferViews' is not a list")?
            .extend(new_views);
    }
    Ok(found)
}

/// An accessor's `count` in the JSON (0 when malformed: validation reports it).
fn count(accessor: &Map<String, Value>) -> u64 {
    accessor.get("count").and_then(Value::as_u64).unwrap_or(0)
}

/// Bytes of one element of an accessor in the JSON (0 when malformed).
fn element_bytes(accessor: &Map<String, Value>) -> u64 {
    let component = match accessor.get("componentType").and_then(Value::as_u64) {
        Some(5120 | 5121) => 1,
        Some(5122 | 5123) => 2,
        Some(5125 | 5126) => 4,
        _ => 0,
    };
    let components = match accessor.get("type").and_then(Value::as_str) {
        Some("SCALAR") => 1,
        Some("VEC2") => 2,
        Some("VEC3") => 3,
        Some("VEC4") | Some("MAT2") => 4,
        Some("MAT3") => 9,
        Some("MAT4") => 16,
        _ => 0,
    };
    component * components
}

/// Decodes every Draco primitive: view index → the bytes of the accessor it was made for.
pub(crate) fn decode_views(
    document: &gltf::Document,
    buffers: &[Vec<u8>],
    primitives: &[DracoPrimitive],
    budget: &mut Budget,
) -> Result<HashMap<usize, Vec<u8>>, String> {
    let mut out = HashMap::new();
    let accessors: Vec<gltf::Accessor> = document.accessors().collect();
    for d in primitives {
        decode_primitive(d, document, &accessors, buffers, budget, &mut out)
            .map_err(|e| format!("{}: {e}", d.what))?;
    }
    Ok(out)
}

fn decode_primitive(
    d: &DracoPrimitive,
    document: &gltf::Document,
    accessors: &[gltf::Accessor],
    buffers: &[Vec<u8>],
    budget: &mut Budget,
    out: &mut HashMap<usize, Vec<u8>>,
) -> Result<(), String> {
    let accessor = |i: usize| {
        accessors
            .get(i)
            .ok_or_else(|| format!("accessor {i} does not exist"))
    };
    let view = document
        .views()
        .nth(d.stream_view)
        .ok_or("the Draco buffer view does not exist")?;
    let stream = buffers
        .get(view.buffer().index())
        .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
        .ok_or("the Draco data lies outside its buffer (or the buffer has no data)")?;
    let points = accessor(d.position)?.count();
    let corners = match d.indices {
        Some((a, _)) => accessor(a)?.count(),
        None => points,
    };
    // What the views will hold, then what decoding needs.
    for &(a, _, _) in &d.attributes {
        let a = accessor(a)?;
        budget.charge(
            a.count() as u64,
            (a.dimensions().multiplicity() * a.data_type().size()) as u64,
            "decoding Draco data",
        )?;
    }
    budget.charge(corners as u64, 4, "decoding Draco data")?;
    let expected = Expected {
        corners: corners as u64,
        points: points as u64,
    };
    let mesh = decode_mesh(stream, expected, budget)?;
    for &(a, uid, view) in &d.attributes {
        let a = accessor(a)?;
        let attribute = mesh
            .get_attributes()
            .iter()
            .find(|att| att.get_id().as_usize() as u64 == uid)
            .ok_or_else(|| format!("the Draco data has no attribute with id {uid}"))?;
        let bytes = attribute_bytes(attribute, a)
            .map_err(|e| format!("accessor {} (Draco attribute {uid}): {e}", a.index()))?;
        out.insert(view, bytes);
    }
    let faces = mesh.get_faces();
    let flat = faces.iter().flatten().map(|&p| usize::from(p));
    match d.indices {
        Some((a, view)) => {
            let a = accessor(a)?;
            let mut bytes = vec_with_capacity(corners * a.data_type().size(), "Draco indices")?;
            for i in flat {
                if i >= points {
                    return Err(format!("index {i} is out of range for {points} vertices"));
                }
                write_component(&mut bytes, i as f64, a.data_type());
            }
            out.insert(view, bytes);
        }
        // Without indices the vertices are drawn in order: the decoder must have kept it.
        None => {
            if !flat.eq(0..points) {
                return Err(
                    "the primitive has no indices, but the Draco data reorders its vertices"
                        .to_string(),
                );
            }
        }
    }
    Ok(())
}

/// A decoded attribute as the accessor's bytes: one value per point, converted to the
/// accessor's component type as the reference decoder's typed read does (plain numeric
/// conversion; normalization is the accessor's, applied when it is read).
fn attribute_bytes(attribute: &Attribute, accessor: &gltf::Accessor) -> Result<Vec<u8>, String> {
    let points = attribute.len();
    if points != accessor.count() {
        return Err(format!(
            "the Draco data holds {points} values, but the accessor declares {}",
            accessor.count()
        ));
    }
    let components = attribute.get_num_components();
    if components != accessor.dimensions().multiplicity() {
        return Err(format!(
            "the Draco data has {components} components per value, but the accessor is {:?}",
            accessor.dimensions()
        ));
    }
    let source = attribute.get_component_type();
    let size = source.size();
    if size == 0 {
        return Err("the Draco attribute has no component type".to_string());
    }
    let target = accessor.data_type();
    let raw = attribute.get_data_as_bytes();
    let mut bytes = vec_with_capacity(
        points * components * target.size(),
        "Draco attribute values",
    )?;
    for p in 0..points {
        let value = usize::from(attribute.get_unique_val_idx(PointIdx::from(p)));
        let element = value
            .checked_mul(components * size)
            .and_then(|start| raw.get(start..start.checked_add(components * size)?))
            .ok_or("the Draco attribute's values are short")?;
        for component in element.chunks_exact(size) {
            write_component(&mut bytes, read_component(component, source), target);
        }
    }
    Ok(bytes)
}

/// One little-endian component of a Draco type as `f64` (exact for every 32-bit type).
fn read_component(b: &[u8], ty: ComponentDataType) -> f64 {
    let word = |n: usize| {
        let mut w = [0u8; 8];
        w[..n].copy_from_slice(&b[..n]);
        u64::from_le_bytes(w)
    };
    match ty {
        ComponentDataType::I8 => b[0] as i8 as f64,
        ComponentDataType::U8 => b[0] as f64,
        ComponentDataType::I16 => word(2) as u16 as i16 as f64,
        ComponentDataType::U16 => word(2) as f64,
        ComponentDataType::I32 => word(4) as u32 as i32 as f64,
        ComponentDataType::U32 => word(4) as f64,
        ComponentDataType::I64 => word(8) as i64 as f64,
        ComponentDataType::U64 => word(8) as f64,
        ComponentDataType::F32 => f32::from_bits(word(4) as u32) as f64,
        ComponentDataType::F64 => f64::from_bits(word(8)),
        ComponentDataType::Invalid => 0.0,
    }
}

/// Appends one component in a glTF component type (integers saturate, as `as` does).
fn write_component(out: &mut Vec<u8>, v: f64, ty: DataType) {
    match ty {
        DataType::I8 => out.push(v as i8 as u8),
        DataType::U8 => out.push(v as u8),
        DataType::I16 => out.extend((v as i16).to_le_bytes()),
        DataType::U16 => out.extend((v as u16).to_le_bytes()),
        DataType::U32 => out.extend((v as u32).to_le_bytes()),
        DataType::F32 => out.extend((v as f32).to_le_bytes()),
    }
}

/// A `.glb` whose one triangle primitive is `stream` (Draco attribute 0 as POSITION, 32-bit
/// indices), the accessor counts read from the stream's header so that the loader decodes it:
/// the `draco` fuzz target's input as a scene.
pub(crate) fn single_stream_glb(stream: &[u8]) -> Vec<u8> {
    let (corners, points) = crate::draco_stream::header_counts(stream).unwrap_or((3, 3));
    let document = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": [EXTENSION],
        "extensionsRequired": [EXTENSION],
        "buffers": [{"byteLength": stream.len().max(1)}],
        "bufferViews": [{"buffer": 0, "byteLength": stream.len().max(1)}],
        "accessors": [
            {"componentType": 5126, "type": "VEC3", "count": points,
             "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0]},
            {"componentType": 5125, "type": "SCALAR", "count": corners}
        ],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0},
            "indices": 1,
            "extensions": {EXTENSION: {"bufferView": 0, "attributes": {"POSITION": 0}}}
        }]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let mut text = document.to_string().into_bytes();
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut bin = stream.to_vec();
    bin.resize(bin.len().max(1).next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut glb = Vec::with_capacity(total);
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((text.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(text);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    glb
}
