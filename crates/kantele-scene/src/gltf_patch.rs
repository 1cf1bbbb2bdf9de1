//! The glTF JSON, read and patched before the `gltf` crate sees it: valid files that its
//! deserializer or validation would reject are made acceptable, accessors filled from Draco data
//! get buffer views of their own, and what this loader cannot decode is refused with one line
//! naming the extension, whether or not the file lists it as required.

use serde_json::Value;

/// Facts gathered while patching.
#[derive(Debug, Default)]
pub(crate) struct Patched {
    /// Per glTF texture: the image it shows (`EXT_texture_webp` first, then `source`), or
    /// `None` when it has none that can be decoded.
    pub texture_images: Vec<Option<usize>>,
    /// Number of animations dropped (they are not played).
    pub animations: usize,
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
    // Animations are not played: drop them, so channels the `gltf` crate cannot express
    // (KHR_animation_pointer, unknown paths, missing nodes) cannot make the file invalid.
    if let Some(Value::Array(list)) = object.remove("animations") {
        patched.animations = list.len();
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
            let webp = index(texture.pointer("/extensions/EXT_texture_webp/source"));
            let source = index(texture.get("source"));
            let chosen = webp.or(source);
            if chosen.is_none() {
                for (ext, what) in [
                    ("KHR_texture_basisu", "KTX2 / Basis Universal"),
                    ("EXT_texture_avif", "AVIF"),
                    ("MSFT_texture_dds", "DDS"),
                ] {
                    if texture.pointer(&format!("/extensions/{ext}")).is_some() {
                        return Err(format!(
                            "texture {t} uses {ext} ({what} images) without a fallback image, which this loader cannot decode"
                        ));
                    }
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
    fn patches_valid_files_and_refuses_draco_and_basis() {
        let mut v: Value = serde_json::from_str(
            r#"{"asset":{"version":"2.0"},"scenes":[{}],"animations":[{"channels":[{"target":{"path":"pointer"}}]}],
                "images":[{"uri":"a.png"},{"uri":"b.webp"}],
                "textures":[{"source":0},{"source":0,"extensions":{"EXT_texture_webp":{"source":1}}},{}]}"#,
        )
        .unwrap();
        let p = patch(&mut v).unwrap();
        assert_eq!(p.animations, 1);
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
        let mut basis: Value = serde_json::from_str(
            r#"{"images":[{"uri":"a.ktx2"}],"textures":[{"extensions":{"KHR_texture_basisu":{"source":0}}}]}"#,
        )
        .unwrap();
        assert!(patch(&mut basis)
            .unwrap_err()
            .contains("KHR_texture_basisu"));
    }
}
