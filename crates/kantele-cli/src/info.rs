//! `kantele info`: what a scene holds.

use anyhow::{bail, Result};
use kantele::scene::{AlphaMode, Light, Scene};
use kantele_scene::LoadedScene;
use serde_json::{json, Value};

use crate::cli::InfoArgs;
use crate::scenes;

fn alpha_mode(m: AlphaMode) -> String {
    match m {
        AlphaMode::Opaque => "OPAQUE".into(),
        AlphaMode::Mask { cutoff } => format!("MASK({cutoff})"),
        AlphaMode::Blend => "BLEND".into(),
    }
}

/// The scene described as JSON (also the source of the table).
pub fn describe(loaded: &LoadedScene) -> Value {
    let scene: &Scene = &loaded.scene;
    let info = &loaded.info;
    let meshes: Vec<Value> = scene
        .meshes
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "vertices": m.positions.len(),
                "triangles": m.triangle_count(),
                "material": m.material,
                "normals": m.normals.is_some(),
                "texcoords": m.texcoords.is_some(),
                "colors": m.colors.is_some(),
            })
        })
        .collect();
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "alpha_mode": alpha_mode(m.alpha_mode),
                "double_sided": m.double_sided,
                "unlit": m.unlit,
                "textured": m.base_color_texture.is_some(),
                "base_color_factor": m.base_color_factor.to_array(),
            })
        })
        .collect();
    let textures: Vec<Value> = scene
        .textures
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let (width, height) = texture_size(loaded, i, t);
            json!({ "width": width, "height": height, "levels": mip_levels(width, height) })
        })
        .collect();
    let light = match scene.light {
        Light::Headlight => json!({ "kind": "headlight" }),
        Light::Directional { to_light, color } => {
            json!({ "kind": "directional", "to_light": to_light.to_array(), "color": color.to_array() })
        }
    };
    let sphere = scene
        .bounding_sphere()
        .map(|(c, r)| json!({ "center": c.to_array(), "radius": r }));
    let cam = &scene.camera;
    json!({
        "source": info.source,
        "nodes": info.node_count,
        "draws": scene.draws.len(),
        "triangles": scene.triangle_count(),
        "resolution": [scene.resolution.0, scene.resolution.1],
        "meshes": meshes,
        "materials": materials,
        "textures": textures,
        "cameras": info.cameras,
        "camera": {
            "from_file": info.camera_from_file,
            "yfov": cam.yfov,
            "ymag": cam.ymag,
            "aspect_ratio": cam.aspect_ratio,
            "znear": cam.znear,
            "zfar": cam.zfar,
        },
        "lights": info.lights,
        "light": light,
        "ambient": scene.ambient,
        "clear_color": scene.clear_color.to_array(),
        "bounding_sphere": sphere,
        "extensions_used": info.extensions_used,
        "scenes": info.scenes.iter().map(|f| json!({
            "index": f.index,
            "name": f.name,
            "default": f.is_default,
            "drawn": f.loaded,
        })).collect::<Vec<_>>(),
        "animations": info.animations.iter().map(|a| json!({
            "index": a.index,
            "name": a.name,
            "duration_seconds": a.duration_seconds,
        })).collect::<Vec<_>>(),
        "variants": info.variants,
        "variant": info.variant_loaded.and_then(|i| info.variants.get(i)),
        "warnings": info.warnings,
        "ignored": info.ignored,
    })
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn list(v: &[String]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

/// The human-readable report.
pub fn table(loaded: &LoadedScene) -> String {
    use std::fmt::Write;
    let scene = &loaded.scene;
    let info = &loaded.info;
    let mut s = String::new();
    let cam = &scene.camera;
    let _ = writeln!(s, "source      {}", info.source);
    let _ = writeln!(
        s,
        "resolution  {}x{}",
        scene.resolution.0, scene.resolution.1
    );
    let _ = writeln!(s, "nodes       {}", info.node_count);
    let _ = writeln!(s, "draws       {}", scene.draws.len());
    let _ = writeln!(s, "triangles   {}", scene.triangle_count());
    let _ = writeln!(
        s,
        "camera      {} (yfov {:.2}°, znear {}, zfar {})",
        if info.camera_from_file {
            "from the file"
        } else {
            "framing (made up)"
        },
        cam.yfov.to_degrees(),
        cam.znear,
        cam.zfar.map_or("infinite".to_string(), |f| f.to_string())
    );
    let _ = writeln!(s, "cameras     {}", list(&info.cameras));
    let light = match scene.light {
        Light::Headlight => "headlight".to_string(),
        Light::Directional { to_light, color } => {
            format!("directional, L = {to_light:.3}, colour {color:.3}")
        }
    };
    let _ = writeln!(
        s,
        "lights      {} (using: {light}, ambient {})",
        list(&info.lights),
        scene.ambient
    );
    let _ = writeln!(s, "extensions  {}", list(&info.extensions_used));
    if !info.scenes.is_empty() {
        let scenes: Vec<String> = info
            .scenes
            .iter()
            .map(|f| {
                let mut text = format!("{}", f.index);
                if let Some(name) = &f.name {
                    let _ = write!(text, " '{name}'");
                }
                match (f.is_default, f.loaded) {
                    (true, true) => text.push_str(" (default, drawn)"),
                    (true, false) => text.push_str(" (default)"),
                    (false, true) => text.push_str(" (drawn)"),
                    (false, false) => {}
                }
                text
            })
            .collect();
        let _ = writeln!(s, "scenes      {}", scenes.join(", "));
    }
    let animations: Vec<String> = info
        .animations
        .iter()
        .map(|a| {
            let name = a
                .name
                .as_deref()
                .map(|n| format!(" '{n}'"))
                .unwrap_or_default();
            format!("{}{name} ({:.3} s)", a.index, a.duration_seconds)
        })
        .collect();
    let _ = writeln!(s, "animations  {}", list(&animations));
    if !info.variants.is_empty() {
        let drawn = info
            .variant_loaded
            .and_then(|i| info.variants.get(i))
            .map_or("the default materials".to_string(), |v| format!("'{v}'"));
        let _ = writeln!(s, "variants    {} (drawn: {drawn})", list(&info.variants));
    }
    if let Some((c, r)) = scene.bounding_sphere() {
        let _ = writeln!(s, "bounds      centre {c:.3}, radius {r:.3}");
    }

    let _ = writeln!(s, "\nmeshes ({})", scene.meshes.len());
    let _ = writeln!(
        s,
        "  {:>4}  {:<24} {:>10} {:>10} {:>8}  attributes",
        "#", "name", "vertices", "triangles", "material"
    );
    for (i, m) in scene.meshes.iter().enumerate() {
        let mut attrs = vec!["POSITION"];
        if m.normals.is_some() {
            attrs.push("NORMAL");
        }
        if m.texcoords.is_some() {
            attrs.push("TEXCOORD_0");
        }
        if m.colors.is_some() {
            attrs.push("COLOR_0");
        }
        let _ = writeln!(
            s,
            "  {:>4}  {:<24} {:>10} {:>10} {:>8}  {}",
            i,
            m.name,
            m.positions.len(),
            m.triangle_count(),
            m.material,
            attrs.join(" ")
        );
    }

    let _ = writeln!(s, "\nmaterials ({})", scene.materials.len());
    let _ = writeln!(
        s,
        "  {:>4}  {:<24} {:<12} {:<12} {:<6} {:<8}",
        "#", "name", "alpha", "double-sided", "unlit", "textured"
    );
    for (i, m) in scene.materials.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {:>4}  {:<24} {:<12} {:<12} {:<6} {:<8}",
            i,
            m.name,
            alpha_mode(m.alpha_mode),
            yes(m.double_sided),
            yes(m.unlit),
            yes(m.base_color_texture.is_some())
        );
    }

    let _ = writeln!(s, "\ntextures ({})", scene.textures.len());
    for (i, t) in scene.textures.iter().enumerate() {
        let (width, height) = texture_size(loaded, i, t);
        let _ = writeln!(
            s,
            "  {:>4}  {}x{}, {} levels",
            i,
            width,
            height,
            mip_levels(width, height)
        );
    }

    let _ = writeln!(s, "\nwarnings ({})", info.warnings.len());
    for w in &info.warnings {
        let _ = writeln!(s, "  {w}");
    }
    s
}

/// Runs `kantele info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let inputs = scenes::inputs(&args.input)?;
    if inputs.len() != 1 && !args.json {
        bail!(
            "info describes one scene at a time ({} given); use --json for several (one line each)",
            inputs.len()
        );
    }
    for input in &inputs {
        // Describing needs only the image headers: textures are not decoded.
        let loaded = input.without_texture_decoding().load()?;
        if args.json {
            println!("{}", describe(&loaded));
        } else {
            print!("{}", table(&loaded));
        }
    }
    Ok(())
}

/// A texture's size: from the image header when the loader recorded it (textures are not
/// decoded for `info`), else the texture's own.
fn texture_size(
    loaded: &LoadedScene,
    index: usize,
    texture: &kantele::shade::texture::Texture,
) -> (u32, u32) {
    loaded
        .info
        .texture_sizes
        .get(index)
        .copied()
        .unwrap_or((texture.width(), texture.height()))
}

/// Levels of a full mip chain down to 1 × 1.
fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}
