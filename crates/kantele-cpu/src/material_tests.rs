//! Tests of the built-in material shader (`material.rs`).

use super::*;
use crate::pipeline::{Indices, Renderer, RendererOptions};
use kantele_rules::scene::{Mesh, Topology};
use kantele_rules::shade::texture::ColorSpace;

/// A built-in shader with the default lane program only: its own `fragment_lanes`, never a
/// specialised program.
struct GeneralProgram<'s, 'a>(&'s MaterialShader<'a>);

impl Shader for GeneralProgram<'_, '_> {
    type Vertex = StandardVertex;
    fn varying_count(&self) -> usize {
        self.0.varying_count()
    }
    fn vertex(&self, vertex: &StandardVertex, varyings: &mut [f32]) -> Vec4 {
        self.0.vertex(vertex, varyings)
    }
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        self.0.fragment(fragment)
    }
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        self.0.fragment_lanes(fragments)
    }
}

/// A `size × size` sRGB texture (`size` a power of two up to 256) of red and green ramps and
/// their XOR in blue, prepared for the lane sampler.
fn pattern_texture(size: u32) -> Texture {
    let step = 256 / size;
    let rgba: Vec<u8> = (0..size * size)
        .flat_map(|i| {
            let (x, y) = (i % size, i / size);
            [
                (x * step) as u8,
                (y * step) as u8,
                ((x ^ y) * step) as u8,
                255,
            ]
        })
        .collect();
    let texture = Texture::from_rgba8(size, size, &rgba, ColorSpace::Srgb).expect("texture");
    texture.prepare_lane_sampling();
    texture
}

/// The colour bits of a 96 × 64 frame of `mesh` drawn with `shader`.
fn render<S: Shader<Vertex = StandardVertex>>(shader: &S, mesh: &Mesh) -> Vec<u32> {
    render_with(shader, mesh, RendererOptions::default())
}

/// [`render`] with `options`.
fn render_with<S: Shader<Vertex = StandardVertex>>(
    shader: &S,
    mesh: &Mesh,
    options: RendererOptions,
) -> Vec<u32> {
    let (vertices, indices) = StandardVertex::from_mesh(mesh);
    let mut renderer = Renderer::new(96, 64, options).expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::new(0.1, 0.2, 0.3, 1.0)), Some(1.0));
    let state = RenderState {
        cull: CullMode::None,
        ..RenderState::default()
    };
    frame
        .draw_primitives(
            shader,
            &vertices,
            Indices::U32(&indices),
            Topology::Triangles,
            state,
        )
        .expect("draw");
    frame.try_end().expect("frame");
    let color = renderer.framebuffer().read_color();
    color.iter().flatten().map(|v| v.to_bits()).collect()
}

/// A face of one vertex colour (a flat-coloured quad, as in the thesis' fill scenes) comes
/// out as exactly that colour through the untextured lane program, on every instruction
/// set, although the receding quad's perspective weights do not sum to 1 exactly.
#[test]
fn a_constant_vertex_colour_is_shaded_exactly() {
    let color = Vec4::new(0.15, 0.682_239_9, 1.0, 1.0);
    let mesh = Mesh {
        positions: vec![
            Vec3::new(-1.0, -0.6, 0.5),
            Vec3::new(1.0, -0.6, 0.5),
            Vec3::new(1.0, 0.4, -8.0),
            Vec3::new(-1.0, 0.4, -8.0),
        ],
        colors: Some(vec![color; 4]),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    };
    let view_projection = Mat4::perspective_rh(1.0, 1.5, 0.1, 20.0)
        * Mat4::look_at_rh(Vec3::new(0.0, 0.6, 1.6), Vec3::new(0.0, 0.0, -2.0), Vec3::Y);
    let material = Material {
        unlit: true,
        ..Material::default()
    };
    let lighting = Lighting {
        to_light: Vec3::Y,
        light_color: Vec3::ONE,
        ambient: 0.0,
    };
    let shader = MaterialShader::new(
        Mat4::IDENTITY,
        view_projection,
        lighting,
        &material,
        None,
        Pass::Color,
        (1, 1),
    );
    assert!(shader.untextured_color.is_some());
    let expected = color.to_array().map(f32::to_bits);
    for isa in crate::pipeline::compiled_supported() {
        let options = RendererOptions {
            isa: Some(isa),
            ..RendererOptions::default()
        };
        let bits = render_with(&shader, &mesh, options);
        let background = 0.3f32.to_bits();
        let drawn: Vec<&[u32]> = bits
            .chunks_exact(4)
            .filter(|c| c[2] != background)
            .collect();
        assert!(drawn.len() > 1000, "{isa}: {} pixels drawn", drawn.len());
        assert!(
            drawn.iter().all(|c| *c == expected),
            "{isa}: a pixel differs"
        );
    }
}

/// Small triangles (a jittered grid of cells about 3 × 3 pixels, each two triangles) leave
/// most rows of their blocks nearly empty, so the textured program's kernel shades them
/// packed ([`LaneProgram::PACKED_ROWS`]); the general program is never packed. Both give
/// the same bits, on every instruction set.
#[test]
fn packed_rows_shade_as_rows_do() {
    let texture = pattern_texture(32);
    let (columns, rows) = (32u32, 21u32);
    let mut jitter = 0x2545_f491u32;
    let mut next = move || {
        jitter ^= jitter << 13;
        jitter ^= jitter >> 17;
        jitter ^= jitter << 5;
        (jitter % 1000) as f32 / 1000.0 - 0.5
    };
    let mut mesh = Mesh {
        positions: Vec::new(),
        normals: Some(Vec::new()),
        texcoords: Some(Vec::new()),
        ..Mesh::default()
    };
    for j in 0..=rows {
        for i in 0..=columns {
            let (u, v) = (i as f32 / columns as f32, j as f32 / rows as f32);
            let x = -1.0 + 2.0 * u + 0.02 * next();
            let y = -1.0 + 2.0 * v + 0.02 * next();
            mesh.positions.push(Vec3::new(x, y, 0.5 + 0.3 * next()));
            let normal = Vec3::new(next(), next(), 1.0).normalize();
            mesh.normals.as_mut().unwrap().push(normal);
            mesh.texcoords
                .as_mut()
                .unwrap()
                .push(Vec2::new(3.0 * u, 5.0 * v * v));
        }
    }
    for j in 0..rows {
        for i in 0..columns {
            let at = j * (columns + 1) + i;
            let (right, up) = (at + 1, at + columns + 1);
            mesh.indices.extend([at, right, up + 1, at, up + 1, up]);
        }
    }
    let lighting = Lighting {
        to_light: Vec3::new(0.3, 0.4, 0.8).normalize(),
        light_color: Vec3::ONE,
        ambient: 0.2,
    };
    let material = Material::default();
    let shader = MaterialShader::new(
        Mat4::IDENTITY,
        Mat4::IDENTITY,
        lighting,
        &material,
        Some((&texture, TrilinearRepeat15::SAMPLER)),
        Pass::Color,
        (1, 1),
    );
    assert!(shader.opaque_textured().is_some());
    for isa in crate::pipeline::compiled_supported() {
        let options = RendererOptions {
            isa: Some(isa),
            ..RendererOptions::default()
        };
        let packed = render_with(&shader, &mesh, options);
        let rows = render_with(&GeneralProgram(&shader), &mesh, options);
        let drawn = packed
            .chunks_exact(4)
            .filter(|c| c[2] != 0.3f32.to_bits())
            .count();
        assert!(drawn > 5000, "{isa}: {drawn} pixels drawn");
        assert!(packed == rows, "{isa}: packed rows differ from rows");
    }
}

/// Every specialised lane program (untextured and textured, lit and unlit, with and without
/// vertex colours) gives the bits of the general program it replaces, on a receding quad
/// whose texture is magnified near the camera and minified (trilinear, repeating) far away.
#[test]
fn specialised_lane_programs_shade_as_the_general_one() {
    let texture = pattern_texture(64);
    let sampler = TrilinearRepeat15::SAMPLER;
    let mesh = |colors: bool| Mesh {
        positions: vec![
            Vec3::new(-1.0, -0.6, 0.5),
            Vec3::new(1.0, -0.6, 0.5),
            Vec3::new(1.0, 0.4, -8.0),
            Vec3::new(-1.0, 0.4, -8.0),
        ],
        normals: Some(vec![
            Vec3::new(0.0, 1.0, 0.1),
            Vec3::new(0.3, 1.0, 0.0),
            Vec3::new(0.0, 1.0, -0.4),
            Vec3::new(-0.2, 0.8, 0.0),
        ]),
        texcoords: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(3.0, 0.0),
            Vec2::new(3.0, 24.0),
            Vec2::new(0.0, 24.0),
        ]),
        colors: colors.then(|| {
            vec![
                Vec4::new(1.0, 0.5, 0.25, 1.0),
                Vec4::new(0.2, 1.0, 0.6, 0.5),
                Vec4::new(0.7, 0.3, 1.0, 1.0),
                Vec4::ONE,
            ]
        }),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    };
    let view_projection = Mat4::perspective_rh(1.0, 1.5, 0.1, 20.0)
        * Mat4::look_at_rh(Vec3::new(0.0, 0.6, 1.6), Vec3::new(0.0, 0.0, -2.0), Vec3::Y);
    let lighting = Lighting {
        to_light: Vec3::new(0.3, 0.9, 0.3).normalize(),
        light_color: Vec3::new(1.0, 0.95, 0.9),
        ambient: 0.2,
    };
    for textured in [false, true] {
        for unlit in [false, true] {
            for colors in [false, true] {
                let material = Material {
                    base_color_factor: Vec4::new(0.9, 0.8, 0.7, 1.0),
                    unlit,
                    emissive: Vec3::new(0.05, 0.0, 0.02),
                    ..Material::default()
                };
                let shader = MaterialShader::new(
                    Mat4::IDENTITY,
                    view_projection,
                    lighting,
                    &material,
                    textured.then_some((&texture, sampler)),
                    Pass::Color,
                    (1, 1),
                )
                .with_vertex_colors(colors);
                let case = format!("textured {textured}, unlit {unlit}, colours {colors}");
                // The draw does reach a specialised program.
                if textured {
                    assert!(shader.opaque_textured().is_some(), "{case}");
                } else {
                    assert!(shader.untextured_color.is_some(), "{case}");
                }
                let mesh = mesh(colors);
                let specialised = render(&shader, &mesh);
                let general = render(&GeneralProgram(&shader), &mesh);
                let drawn = specialised
                    .chunks_exact(4)
                    .filter(|c| c[2] != 0.3f32.to_bits())
                    .count();
                assert!(drawn > 1000, "{case}: {drawn} pixels drawn");
                assert!(specialised == general, "{case}: the programs differ");
            }
        }
    }
}

/// The textured program of alpha-masked and blended draws gives the bits of the general
/// program: alpha (the factor's times the texel's, which ramps across the texture) and the
/// lanes a mask discards, on the receding quad of the other programs' test, single-sided and
/// double-sided.
#[test]
fn alpha_textured_program_shades_as_the_general_one() {
    let size = 64u32;
    let rgba: Vec<u8> = (0..size * size)
        .flat_map(|i| {
            let (x, y) = (i % size, i / size);
            [
                (x * 4) as u8,
                (y * 4) as u8,
                ((x ^ y) * 4) as u8,
                (x * 4 + 2) as u8,
            ]
        })
        .collect();
    let texture = Texture::from_rgba8(size, size, &rgba, ColorSpace::Srgb).expect("texture");
    texture.prepare_lane_sampling();
    let mesh = Mesh {
        positions: vec![
            Vec3::new(-1.0, -0.6, 0.5),
            Vec3::new(1.0, -0.6, 0.5),
            Vec3::new(1.0, 0.4, -8.0),
            Vec3::new(-1.0, 0.4, -8.0),
        ],
        normals: Some(vec![Vec3::Y, Vec3::new(0.3, 1.0, 0.0), Vec3::Z, Vec3::X]),
        texcoords: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(3.0, 0.0),
            Vec2::new(3.0, 24.0),
            Vec2::new(0.0, 24.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    };
    let view_projection = Mat4::perspective_rh(1.0, 1.5, 0.1, 20.0)
        * Mat4::look_at_rh(Vec3::new(0.0, 0.6, 1.6), Vec3::new(0.0, 0.0, -2.0), Vec3::Y);
    let lighting = Lighting {
        to_light: Vec3::new(0.3, 0.9, 0.3).normalize(),
        light_color: Vec3::ONE,
        ambient: 0.1,
    };
    // Pixels outside the quad: the blended draw keeps every lane it covers.
    let mut uncovered = 0;
    for alpha_mode in [AlphaMode::Blend, AlphaMode::Mask { cutoff: 0.4 }] {
        for double_sided in [false, true] {
            let material = Material {
                base_color_factor: Vec4::new(0.9, 0.8, 0.7, 0.8),
                alpha_mode,
                double_sided,
                emissive: Vec3::new(0.05, 0.0, 0.02),
                ..Material::default()
            };
            let shader = MaterialShader::new(
                Mat4::IDENTITY,
                view_projection,
                lighting,
                &material,
                Some((&texture, TrilinearRepeat15::SAMPLER)),
                Pass::Color,
                (1, 1),
            )
            .with_vertex_colors(false);
            let case = format!("{alpha_mode:?}, double-sided {double_sided}");
            assert!(shader.alpha_textured().is_some(), "{case}");
            let specialised = render(&shader, &mesh);
            let general = render(&GeneralProgram(&shader), &mesh);
            let cleared = specialised
                .chunks_exact(4)
                .filter(|c| c[2] == 0.3f32.to_bits())
                .count();
            if let AlphaMode::Mask { .. } = alpha_mode {
                // The mask keeps some of the quad and discards some (the clear shows there).
                assert!(
                    cleared > uncovered + 200 && cleared < 64 * 96 - 200,
                    "{case}: {cleared} cleared, {uncovered} outside the quad"
                );
            } else {
                uncovered = cleared;
                let alphas: std::collections::HashSet<u32> =
                    specialised.chunks_exact(4).map(|c| c[3]).collect();
                assert!(alphas.len() > 20, "{case}: alpha does not vary");
            }
            assert!(specialised == general, "{case}: the programs differ");
        }
    }
}

/// A built-in shader seen only through its per-fragment entry: the default `fragment_lanes`
/// (each lane's scalar fragment, [`FragmentLanes::lane`]).
struct ScalarFragments<'s, 'a>(&'s MaterialShader<'a>);

impl Shader for ScalarFragments<'_, '_> {
    type Vertex = StandardVertex;
    fn varying_count(&self) -> usize {
        self.0.varying_count()
    }
    fn vertex(&self, vertex: &StandardVertex, varyings: &mut [f32]) -> Vec4 {
        self.0.vertex(vertex, varyings)
    }
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        self.0.fragment(fragment)
    }
}

/// A draw that reads no other varying renormalises its normal from the direction alone
/// (`varying_direction`, no perspective division), one with vertex colours from the
/// perspective-correct normal: either way the scalar fragment and the lane programs take the
/// same one, so a lit receding quad with a different normal at each vertex (and its normals
/// pass) comes out the same, bit for bit, from both, on every instruction set; the normals
/// written are unit vectors within rounding, and the two rules' normals agree within rounding
/// (the same direction).
#[test]
fn scalar_fragments_and_lane_programs_take_the_same_normal_direction() {
    let mesh = Mesh {
        positions: vec![
            Vec3::new(-1.0, -0.6, 0.5),
            Vec3::new(1.0, -0.6, 0.5),
            Vec3::new(1.0, 0.4, -8.0),
            Vec3::new(-1.0, 0.4, -8.0),
        ],
        normals: Some(vec![
            Vec3::new(0.0, 1.0, 0.1),
            Vec3::new(0.3, 1.0, 0.0),
            Vec3::new(0.0, 1.0, -0.4),
            Vec3::new(-0.2, 0.8, 0.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    };
    let view_projection = Mat4::perspective_rh(1.0, 1.5, 0.1, 20.0)
        * Mat4::look_at_rh(Vec3::new(0.0, 0.6, 1.6), Vec3::new(0.0, 0.0, -2.0), Vec3::Y);
    let lighting = Lighting {
        to_light: Vec3::new(0.3, 0.9, 0.3).normalize(),
        light_color: Vec3::new(1.0, 0.95, 0.9),
        ambient: 0.2,
    };
    let material = Material {
        base_color_factor: Vec4::new(0.9, 0.8, 0.7, 1.0),
        ..Material::default()
    };
    // The normals pass of the last instruction set, without and with vertex colours.
    let mut normals_by_rule: [Vec<u32>; 2] = Default::default();
    for (pass, vertex_colors) in [
        (Pass::Color, false),
        (Pass::Color, true),
        (Pass::Normals, false),
        (Pass::Normals, true),
    ] {
        let shader = MaterialShader::new(
            Mat4::IDENTITY,
            view_projection,
            lighting,
            &material,
            None,
            pass,
            (1, 1),
        )
        .with_vertex_colors(vertex_colors);
        for isa in crate::pipeline::compiled_supported() {
            let options = RendererOptions {
                isa: Some(isa),
                ..RendererOptions::default()
            };
            let lanes = render_with(&shader, &mesh, options);
            let scalar = render_with(&ScalarFragments(&shader), &mesh, options);
            let drawn = lanes
                .chunks_exact(4)
                .filter(|c| c[2] != 0.3f32.to_bits())
                .count();
            assert!(drawn > 1000, "{pass:?}, {isa:?}: {drawn} pixels drawn");
            assert!(
                lanes == scalar,
                "{pass:?}, {isa:?}: scalar and lanes differ"
            );
            if pass == Pass::Normals {
                for c in lanes.chunks_exact(4).filter(|c| c[2] != 0.3f32.to_bits()) {
                    let n = Vec3::new(
                        f32::from_bits(c[0]),
                        f32::from_bits(c[1]),
                        f32::from_bits(c[2]),
                    );
                    assert!((n.length() - 1.0).abs() < 1e-6, "{isa:?}: normal {n}");
                }
                normals_by_rule[usize::from(vertex_colors)] = lanes;
            }
        }
    }
    let [direction, perspective] = normals_by_rule;
    assert_eq!(direction.len(), perspective.len());
    let mut differing = 0;
    for (d, p) in direction.iter().zip(&perspective) {
        let (d, p) = (f32::from_bits(*d), f32::from_bits(*p));
        assert!((d - p).abs() <= 1e-5, "normal component {d} against {p}");
        differing += usize::from(d != p);
    }
    // The two rules are different computations (else the first would not be needed).
    assert!(
        differing > 0,
        "the direction and perspective normals are identical"
    );
}
