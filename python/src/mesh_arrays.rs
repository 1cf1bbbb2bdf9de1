//! `Scene.from_arrays`: a scene of one mesh given as numpy arrays (trimesh's
//! `mesh.vertices, mesh.faces`, ...).

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::color::srgb_to_linear;
use kantele::scene::{Draw, Material, Mesh, Scene, TextureBinding};
use kantele::shade::texture::{ColorSpace, Sampler, Texture};
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::errors::{render_error, value_error};

/// The numpy arrays of a mesh, as given.
pub struct MeshArrays<'py> {
    /// (N, 3) positions.
    pub vertices: Bound<'py, PyAny>,
    /// (M, 3) vertex indices, counter-clockwise = front.
    pub faces: Bound<'py, PyAny>,
    /// (N, 3) normals.
    pub normals: Option<Bound<'py, PyAny>>,
    /// (N, 3|4) colours: `uint8` sRGB or float linear.
    pub colors: Option<Bound<'py, PyAny>>,
    /// (N, 2) texture coordinates, (0, 0) = the texture's top-left corner.
    pub uvs: Option<Bound<'py, PyAny>>,
    /// (H, W, 3|4) texture: `uint8` sRGB or float linear.
    pub texture: Option<Bound<'py, PyAny>>,
}

/// `numpy.ascontiguousarray(obj, dtype)`, with a `ValueError` naming the argument.
fn contiguous<'py>(
    obj: &Bound<'py, PyAny>,
    dtype: &str,
    name: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let numpy = obj.py().import("numpy")?;
    numpy
        .call_method1("ascontiguousarray", (obj, dtype))
        .map_err(|e| value_error(format!("{name}: cannot be read as a {dtype} array ({e})")))
}

/// numpy's dtype kind character (`'u'`, `'i'`, `'f'`, `'b'`, ...) of `obj` as an array.
fn dtype_kind(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<String> {
    let numpy = obj.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("{name}: not an array ({e})")))?;
    array.getattr("dtype")?.getattr("kind")?.extract()
}

/// A C-contiguous array of `dtype` whose shape is (`rows` or any, one of `columns`).
fn table<'py, T: numpy::Element + Copy>(
    obj: &Bound<'py, PyAny>,
    dtype: &str,
    name: &str,
    rows: Option<usize>,
    columns: &[usize],
) -> PyResult<(Vec<T>, usize, usize)> {
    let array = contiguous(obj, dtype, name)?;
    let array: PyReadonlyArrayDyn<'py, T> = array.extract()?;
    let shape = array.shape().to_vec();
    let want_rows = rows.map_or("N".to_string(), |r| r.to_string());
    let want_cols = columns
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(" or ");
    if shape.len() != 2 || rows.is_some_and(|r| shape[0] != r) || !columns.contains(&shape[1]) {
        return Err(value_error(format!(
            "{name}: expected shape ({want_rows}, {want_cols}), got {shape:?}"
        )));
    }
    let data = array.as_slice()?.to_vec();
    Ok((data, shape[0], shape[1]))
}

fn finite_check(values: &[f32], name: &str) -> PyResult<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(value_error(format!(
            "{name}: value {} at row {} is not finite",
            values[i],
            i / 3
        ))),
        None => Ok(()),
    }
}

fn decode_colors(data: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<Vec4>> {
    let srgb8 = dtype_kind(data, "colors")? == "u" && {
        let numpy = data.py().import("numpy")?;
        let arr = numpy.call_method1("asarray", (data,))?;
        arr.getattr("dtype")?
            .getattr("itemsize")?
            .extract::<usize>()?
            == 1
    };
    if srgb8 {
        let (bytes, _, c) = table::<u8>(data, "uint8", "colors", Some(n), &[3, 4])?;
        Ok(bytes
            .chunks_exact(c)
            .map(|p| {
                let a = if c == 4 { p[3] as f32 / 255.0 } else { 1.0 };
                Vec4::new(
                    srgb_to_linear(p[0] as f32 / 255.0),
                    srgb_to_linear(p[1] as f32 / 255.0),
                    srgb_to_linear(p[2] as f32 / 255.0),
                    a,
                )
            })
            .collect())
    } else {
        let (values, _, c) = table::<f32>(data, "float32", "colors", Some(n), &[3, 4])?;
        Ok(values
            .chunks_exact(c)
            .map(|p| Vec4::new(p[0], p[1], p[2], if c == 4 { p[3] } else { 1.0 }))
            .collect())
    }
}

fn decode_texture(image: &Bound<'_, PyAny>) -> PyResult<Texture> {
    let numpy = image.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (image,))
        .map_err(|e| value_error(format!("texture: not an array ({e})")))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 3 || !(shape[2] == 3 || shape[2] == 4) {
        return Err(value_error(format!(
            "texture: expected shape (H, W, 3 or 4), got {shape:?}"
        )));
    }
    let (h, w, c) = (shape[0], shape[1], shape[2]);
    let (Ok(w32), Ok(h32)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(value_error(format!("texture: {w}x{h} is too large")));
    };
    let flat = array.call_method1("reshape", ((h * w, c),))?;
    let is_u8 = array
        .getattr("dtype")?
        .getattr("kind")?
        .extract::<String>()?
        == "u"
        && array
            .getattr("dtype")?
            .getattr("itemsize")?
            .extract::<usize>()?
            == 1;
    let texture = if is_u8 {
        let (bytes, _, _) = table::<u8>(&flat, "uint8", "texture", None, &[c])?;
        let rgba: Vec<u8> = if c == 4 {
            bytes
        } else {
            bytes
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect()
        };
        Texture::from_rgba8(w32, h32, &rgba, ColorSpace::Srgb)
    } else {
        let (values, _, _) = table::<f32>(&flat, "float32", "texture", None, &[c])?;
        let texels = values
            .chunks_exact(c)
            .map(|p| Vec4::new(p[0], p[1], p[2], if c == 4 { p[3] } else { 1.0 }))
            .collect();
        Texture::from_rgba_f32(w32, h32, texels)
    };
    texture.map_err(|e| value_error(format!("texture: {e}")))
}

/// Builds a one-mesh scene from numpy arrays, framed by the loaders' default camera.
pub fn scene_from_arrays(arrays: &MeshArrays<'_>, double_sided: bool) -> PyResult<Scene> {
    let (positions, n, _) = table::<f32>(&arrays.vertices, "float32", "vertices", None, &[3])?;
    finite_check(&positions, "vertices")?;
    if n > u32::MAX as usize {
        return Err(value_error(format!("vertices: {n} is more than 2^32 - 1")));
    }
    let kind = dtype_kind(&arrays.faces, "faces")?;
    if kind != "i" && kind != "u" {
        return Err(value_error(format!(
            "faces: expected an integer array, got dtype kind '{kind}'"
        )));
    }
    let (faces, _, _) = table::<i64>(&arrays.faces, "int64", "faces", None, &[3])?;
    let mut indices = Vec::with_capacity(faces.len());
    for (position, &i) in faces.iter().enumerate() {
        if i < 0 || i as u64 >= n as u64 {
            return Err(value_error(format!(
                "faces: index {i} at row {} is out of range for {n} vertices",
                position / 3
            )));
        }
        indices.push(i as u32);
    }
    let normals = match &arrays.normals {
        Some(a) => {
            let (v, _, _) = table::<f32>(a, "float32", "normals", Some(n), &[3])?;
            finite_check(&v, "normals")?;
            Some(v.chunks_exact(3).map(Vec3::from_slice).collect())
        }
        None => None,
    };
    let colors = arrays
        .colors
        .as_ref()
        .map(|a| decode_colors(a, n))
        .transpose()?;
    let texcoords: Option<Vec<Vec2>> = match &arrays.uvs {
        Some(a) => {
            let (v, _, _) = table::<f32>(a, "float32", "uvs", Some(n), &[2])?;
            Some(v.chunks_exact(2).map(Vec2::from_slice).collect())
        }
        None => None,
    };
    let mut scene = Scene::default();
    let mut material = Material {
        name: "arrays".into(),
        double_sided,
        ..Material::default()
    };
    if let Some(image) = &arrays.texture {
        if texcoords.is_none() {
            return Err(value_error(
                "texture: needs uvs (texture coordinates per vertex)",
            ));
        }
        scene.textures.push(Arc::new(decode_texture(image)?));
        material.base_color_texture = Some(TextureBinding {
            texture: 0,
            sampler: Sampler::default(),
            texcoord: 0,
        });
    }
    scene.materials.push(material);
    scene.meshes.push(Mesh {
        name: "arrays".into(),
        positions: positions.chunks_exact(3).map(Vec3::from_slice).collect(),
        normals,
        texcoords,
        colors,
        indices,
        material: 0,
        ..Mesh::default()
    });
    scene.draws.push(Draw {
        mesh: 0,
        model: Mat4::IDENTITY,
        node_name: "arrays".into(),
        node_index: 0,
    });
    scene.validate().map_err(render_error)?;
    scene.camera = kantele_scene::mesh_util::framing_camera(&scene);
    Ok(scene)
}
