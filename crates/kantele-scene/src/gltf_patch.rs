//! The glTF JSON, read and patched before the `gltf` crate sees it: valid files that its
//! deserializer or validation would reject are made acceptable, accessors filled from Draco data
//! get buffer views of their own, and what this loader cannot decode is refused with one line
//! naming the extension, whether or not the file lists it as required.

use serde_json::Value;

/// Facts gathered while patching.
#[derive(Debug, Default)]
pub(crate) struct Patched {
    /// Per glTF texture: the image it shows (`KHR_texture_basisu` first, then
    /// `MSFT_texture_dds`, then `EXT_texture_webp`, then `source`), or
    /// `None` when it has none that can be decoded.
    pub texture_images: Vec<Option<usize>>,
    /// The file's animations, taken out of the JSON (the loader reads the one it plays).
    pub animations: Vec<Value>,
    /// Warnings to record.
    pub warnings: Vec<String>,
    /// `KHR_draco_mesh_compression` primitives, their accessors given views of their own.
    pub draco: Vec<crate::draco_views::DracoPrimitive>,
}

/// Splits a `.glb` into its JSON and binary chunk; other bytes are taken as JSON text.
pub(crate) fn split_glb(bytes: &[u8]) -> Result<(Vec<u8>, Option<Vec<u8>>), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes.to_vec(), None));
    }
    let glb =
        gltf::binary::Glb::from_slice(bytes).map_err(|e| format!("not a valid GLB file: {e}"))?;
    Ok((glb.json.into_owned(), glb.bin.map(|b| b.into_owned())))
}

/// Patches the document in place; an error for content this loader cannot decode.
pub(crate) fn patch(root: &mut Value) -> Result<Patched, String> {
    let Some(object) = root.as_object_mut() else {
        return Err("not a valid glTF file: the JSON is not an object".to_string());
    };
    let mut patched = Patched::default();
    // Animations are read by the loader itself: taken out, so channels the `gltf` crate cannot
    // express (KHR_animation_pointer, unknown paths, missing nodes) cannot make the file invalid.
    if let Some(Value::Array(list)) = object.remove("animations") {
        patched.animations = list;
    }
    // A scene without `nodes` is valid glTF (an empty scene); the crate requires the field.
    if let Some(Value::Array(scenes)) = object.get_mut("scenes") {
        for scene in scenes.iter_mut().filter_map(Value::as_object_mut) {
            scene
                .entry("nodes")
                .or_insert_with(|| Value::Array(Vec::new()));
        }
    }
    patched.draco = crate::draco_views::patch_json(object)?;
    let image_count = object
        .get("images")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let index = |v: Option<&Value>| {
        v.and_then(Value::as_u64)
            .and_then(|i| usize::try_from(i).ok())
    };
    if let Some(Value::Array(textures)) = object.get("textures") {
        for (t, texture) in textures.iter().enumerate() {
            let basisu = index(texture.pointer("/extensions/KHR_texture_basisu/source"));
            let dds = index(texture.pointer("/extensions/MSFT_texture_dds/source"));
            let webp = index(texture.pointer("/extensions/EXT_texture_webp/source"));
            let source = index(texture.get("source"));
            let chosen = basisu.or(dds).or(webp).or(source);
            if chosen.is_none() {
                if texture.pointer("/extensions/EXT_texture_avif").is_some() {
                    return Err(format!(
                        "texture {t} uses EXT_texture_avif (AVIF images) without a fallback image, which this loader cannot decode"
                    ));
                }
                patched
                    .warnings
                    .push(format!("texture {t} has no image; drawn untextured"));
            }
            match chosen {
                Some(i) if i >= image_count => {
                    return Err(format!(
                        "texture {t} refers to image {i}, but the file has {image_count} images"
                    ))
                }
                _ => patched.texture_images.push(chosen),
            }
        }
    }
    Ok(patched)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_valid_files_and_refuses_draco() {
        let mut v: Value = serde_json::from_str(
            r#"{"asset":{"version":"2.0"},"scenes":[{}],"animations":[{"channels":[{"target":{"path":"pointer"}}]}],
                "images":[{"uri":"a.png"},{"uri":"b.webp"}],
                "textures":[{"source":0},{"source":0,"extensions":{"EXT_texture_webp":{"source":1}}},{}]}"#,
        )
        .unwrap();
        let p = patch(&mut v).unwrap();
        assert_eq!(p.animations.len(), 1);
        assert!(v.get("animations").is_none());
        assert_eq!(v["scenes"][0]["nodes"], Value::Array(vec![]));
        assert_eq!(p.texture_images, vec![Some(0), Some(1), None]);
        assert_eq!(p.warnings.len(), 1);

        let mut draco: Value = serde_json::from_str(
            r#"{"meshes":[{"primitives":[{"attributes":{},"extensions":{"KHR_draco_mesh_compression":{}}}]}]}"#,
        )
        .unwrap();
        assert!(patch(&mut draco)
            .unwrap_err()
            .contains("KHR_draco_mesh_compression"));
        let mut avif: Value = serde_json::from_str(
            r#"{"images":[{"uri":"a.avif"}],"textures":[{"extensions":{"EXT_texture_avif":{"source":0}}}]}"#,
        )
        .unwrap();
        assert!(patch(&mut avif).unwrap_err().contains("EXT_texture_avif"));
    }

    #[test]
    fn basis_images_come_before_the_fallback() {
        // The KTX2 image first, with or without a fallback in `source`.
        let mut v: Value = serde_json::from_str(
            r#"{"images":[{"uri":"a.png"},{"uri":"b.ktx2"}],
                "textures":[{"source":0,"extensions":{"KHR_texture_basisu":{"source":1}}},
                            {"extensions":{"KHR_texture_basisu":{"source":1}}},
                            {"source":1}]}"#,
        )
        .unwrap();
        let p = patch(&mut v).unwrap();
        assert_eq!(p.texture_images, vec![Some(1), Some(1), Some(1)]);
        assert!(p.warnings.is_empty());
        // A KTX2 image index out of range is refused like any other.
        let mut bad: Value = serde_json::from_str(
            r#"{"images":[{"uri":"a.png"}],"textures":[{"source":0,"extensions":{"KHR_texture_basisu":{"source":5}}}]}"#,
        )
        .unwrap();
        assert!(patch(&mut bad).unwrap_err().contains("image 5"));
    }

    #[test]
    fn dds_images_come_before_the_fallback() {
        // The DDS image first, with or without a fallback in `source`; a KTX2 image before both.
        let mut v: Value = serde_json::from_str(
            r#"{"images":[{"uri":"a.png"},{"uri":"b.dds"},{"uri":"c.ktx2"}],
                "textures":[{"source":0,"extensions":{"MSFT_texture_dds":{"source":1}}},
                            {"extensions":{"MSFT_texture_dds":{"source":1}}},
                            {"source":0,"extensions":{"MSFT_texture_dds":{"source":1},
                                                      "KHR_texture_basisu":{"source":2}}}]}"#,
        )
        .unwrap();
        let p = patch(&mut v).unwrap();
        assert_eq!(p.texture_images, vec![Some(1), Some(1), Some(2)]);
        assert!(p.warnings.is_empty());
        let mut bad: Value = serde_json::from_str(
            r#"{"images":[{"uri":"a.png"}],"textures":[{"source":0,"extensions":{"MSFT_texture_dds":{"source":7}}}]}"#,
        )
        .unwrap();
        assert!(patch(&mut bad).unwrap_err().contains("image 7"));
    }
}
