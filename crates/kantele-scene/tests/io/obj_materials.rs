//! MTL materials mapped onto glTF's material model (the table *OBJ and MTL materials* in
//! `docs/rendering-rules.md`): colours, factors, and the textures each statement fills, with
//! their colour spaces.

use crate::common::*;
use glam::{Vec3, Vec4};
use kantele::scene::{AlphaMode, Material, Scene};
use kantele::shade::texture::ColorSpace;
use kantele_scene::load_scene;

const MTL: &str = "\
newmtl pbr
Kd 0.5 0.5 0.5
map_Kd base.png
map_d -imfchan r mask.png
Ke 0 0 0
map_Ke base.png
Ks 0.25 0.25 0.25
map_Ks base.png
Ns 250
Pr 0.3
map_Pr -imfchan g rough.png
Pm 0.7
map_Pm -imfchan b metal.png
norm -bm 2 normal.png
map_Bump base.png
Pc 0.5
Pcr 0.25

newmtl plain
Kd 1 0 0
Ns 250
Tr 0.75
Ks 0.5 0.5 0.5
Ke 0.1 0.2 0.3
Pm 0.4

newmtl glossy
Ns 1000
Pr 0.2

newmtl blender roughness map
map_Ns rough.png

newmtl leaf
map_Kd leaf.png
map_d leaf.png
";

/// One triangle per material, with texture coordinates.
fn obj() -> String {
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n");
    for name in ["pbr", "plain", "glossy", "blender roughness map", "leaf"] {
        obj.push_str(&format!("usemtl {name}\nf 1/1 2/2 3/3\n"));
    }
    obj
}

fn material<'s>(scene: &'s Scene, name: &str) -> &'s Material {
    scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}

fn close(a: Vec4, b: Vec4) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn mtl_statements_fill_the_gltf_material() {
    let dir = temp_dir("obj-materials");
    let gray = |v: u8| [v, v, v, 255];
    let files: [(&str, Vec<u8>); 6] = [
        ("base.png", test_png()),
        // 4 × 1, red 0, 255, 0, 255: the alpha of `pbr`.
        (
            "mask.png",
            png(4, 1, &[0, 9, 9, 255, 255, 9, 9, 255].repeat(2)),
        ),
        // 1 × 1, green 128: roughness.
        ("rough.png", png(1, 1, &[7, 128, 7, 255])),
        // 2 × 1, blue 51 and 255: metallic.
        ("metal.png", png(2, 1, &[0, 0, 51, 255, 0, 0, 255, 255])),
        ("normal.png", png(1, 1, &gray(128))),
        // A leaf with an alpha channel, named by map_Kd and map_d.
        ("leaf.png", png(2, 1, &[0, 200, 0, 0, 0, 200, 0, 255])),
    ];
    for (name, bytes) in &files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    std::fs::write(dir.join("m.mtl"), MTL).unwrap();
    std::fs::write(dir.join("m.obj"), obj()).unwrap();
    let loaded = load_scene(&dir.join("m.obj")).unwrap_or_else(|e| panic!("{e}"));
    let scene = &loaded.scene;
    let warnings = loaded.info.warnings.join("\n");
    assert!(!warnings.contains("cannot"), "{warnings}");
    assert!(scene.materials.iter().all(|m| m.double_sided));
    let space = |t: Option<kantele::scene::TextureBinding>| {
        scene.textures[t.expect("a texture").texture].source_color_space()
    };
    let size = |t: Option<kantele::scene::TextureBinding>| {
        let t = &scene.textures[t.expect("a texture").texture];
        (t.width(), t.height())
    };

    let pbr = material(scene, "pbr");
    assert_eq!(pbr.base_color_factor, Vec4::new(0.5, 0.5, 0.5, 1.0));
    assert_eq!(pbr.alpha_mode, AlphaMode::Blend);
    // map_Kd (2 × 2) with map_d's (4 × 1) red as alpha, at the larger size on each axis, sRGB.
    assert_eq!(space(pbr.base_color_texture), ColorSpace::Srgb);
    assert_eq!(size(pbr.base_color_texture), (4, 2));
    let base = &scene.textures[pbr.base_color_texture.unwrap().texture];
    let level = base.level(0).unwrap();
    assert_eq!((level.texel(0, 0).w, level.texel(1, 0).w), (0.0, 1.0));
    // Ke 0 with map_Ke: the map shows (factor 1).
    assert_eq!(pbr.emissive, Vec3::ONE);
    assert_eq!(space(pbr.emissive_texture), ColorSpace::Srgb);
    // Ks 0.25 → F0 0.02; map_Ks is the specular colour texture.
    assert!((pbr.dielectric_f0 - Vec3::splat(0.02)).abs().max_element() < 1e-6);
    assert_eq!(space(pbr.specular_color_texture), ColorSpace::Srgb);
    // Maps give roughness and metallic (factors 1), in one linear texture: G from map_Pr's
    // green, B from map_Pm's blue, at the larger size.
    assert_eq!((pbr.roughness, pbr.metallic), (1.0, 1.0));
    assert_eq!(space(pbr.metallic_roughness_texture), ColorSpace::Linear);
    assert_eq!(size(pbr.metallic_roughness_texture), (2, 1));
    let mr = &scene.textures[pbr.metallic_roughness_texture.unwrap().texture];
    let level = mr.level(0).unwrap();
    assert!(close(
        level.texel(0, 0),
        Vec4::new(1.0, 128.0 / 255.0, 0.2, 1.0)
    ));
    assert!(close(
        level.texel(1, 0),
        Vec4::new(1.0, 128.0 / 255.0, 1.0, 1.0)
    ));
    // `norm` wins over map_Bump; -bm is the normal scale; linear.
    assert_eq!(pbr.normal_scale, 2.0);
    assert_eq!(space(pbr.normal_texture), ColorSpace::Linear);
    assert_eq!(size(pbr.normal_texture), (1, 1));
    assert_eq!((pbr.clearcoat, pbr.clearcoat_roughness), (0.5, 0.25));

    let plain = material(scene, "plain");
    assert_eq!(plain.base_color_factor, Vec4::new(1.0, 0.0, 0.0, 0.25));
    assert_eq!(plain.alpha_mode, AlphaMode::Blend);
    assert_eq!(plain.roughness, 0.5, "Ns 250");
    assert_eq!(plain.metallic, 0.4);
    assert!(
        (plain.dielectric_f0 - Vec3::splat(0.04))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(plain.emissive, Vec3::new(0.1, 0.2, 0.3));
    assert!(plain.base_color_texture.is_none() && plain.metallic_roughness_texture.is_none());

    let glossy = material(scene, "glossy");
    assert_eq!(
        (glossy.roughness, glossy.metallic),
        (0.2, 0.0),
        "Pr wins over Ns"
    );
    assert_eq!(glossy.alpha_mode, AlphaMode::Opaque);

    // map_Ns alone is a roughness map, as Blender writes and reads it.
    let blender = material(scene, "blender roughness map");
    assert_eq!((blender.roughness, blender.metallic), (1.0, 0.0));
    assert_eq!(size(blender.metallic_roughness_texture), (1, 1));

    // map_d naming map_Kd's own image reads its alpha: the image itself, blended.
    let leaf = material(scene, "leaf");
    assert_eq!(leaf.alpha_mode, AlphaMode::Blend);
    assert_eq!(size(leaf.base_color_texture), (2, 1));
    assert_eq!(
        scene.textures[leaf.base_color_texture.unwrap().texture]
            .level(0)
            .unwrap()
            .texel(0, 0)
            .w,
        0.0
    );
}

/// Without decoding (descriptions), made textures are placeholders of the size they would have.
#[test]
fn made_textures_without_decoding_have_their_size() {
    let dir = temp_dir("obj-materials-undecoded");
    std::fs::write(dir.join("rough.png"), png(3, 1, &[9; 12])).unwrap();
    std::fs::write(dir.join("metal.png"), png(1, 2, &[9; 8])).unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl m\nmap_Pr rough.png\nmap_Pm metal.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
    )
    .unwrap();
    let options = kantele_scene::LoadOptions {
        decode_textures: false,
        ..kantele_scene::LoadOptions::default()
    };
    let loaded = kantele_scene::load_scene_with(&dir.join("m.obj"), &options).unwrap();
    assert_eq!(loaded.info.texture_sizes, vec![(3, 2)]);
}
