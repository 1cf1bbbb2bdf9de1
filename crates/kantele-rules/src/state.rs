//! Render state, limits and the id encoding: the rules every stage and every backend share,
//! in one module that imports no stage.
//!
//! The CPU pipeline, the OpenGL backend and the CUDA backend all read these types; a stage never
//! defines its own copy of a limit or an encoding.

use glam::Vec4;

use kantele_lanes::{F32x8, Lanes};

/// Largest render target side in pixels.
pub const MAX_TARGET_SIZE: u32 = 16384;
/// Largest texture side accepted (texels).
pub const MAX_TEXTURE_SIZE: u32 = 16384;
/// Most `f32` varyings a vertex can carry to the fragment stage.
pub const MAX_VARYINGS: usize = 16;
/// Most primitive-stage batches one frame may hold (2^19): a binned triangle's reference packs
/// its batch and its index within the batch into 32 bits.
pub const MAX_FRAME_BATCHES: usize = 1 << 19;

/// Which faces are removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CullMode {
    /// Draw both faces.
    None,
    /// Remove back faces.
    #[default]
    Back,
    /// Remove front faces.
    Front,
}

/// Which winding (in normalized device coordinates, y up) is the front face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrontFace {
    /// Counter-clockwise is front (OpenGL's and glTF's default).
    #[default]
    Ccw,
    /// Clockwise is front.
    Cw,
}

/// Depth comparison: a fragment passes when `fragment_depth OP stored_depth` holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DepthFunc {
    /// Never passes.
    Never,
    /// Passes when closer.
    #[default]
    Less,
    /// Passes when equal.
    Equal,
    /// Passes when closer or equal.
    LessEqual,
    /// Passes when farther.
    Greater,
    /// Passes when different.
    NotEqual,
    /// Passes when farther or equal.
    GreaterEqual,
    /// Always passes.
    Always,
}

impl DepthFunc {
    /// Whether a fragment at depth `fragment` passes against `stored`.
    #[inline]
    pub fn passes(self, fragment: f32, stored: f32) -> bool {
        match self {
            DepthFunc::Never => false,
            DepthFunc::Less => fragment < stored,
            DepthFunc::Equal => fragment == stored,
            DepthFunc::LessEqual => fragment <= stored,
            DepthFunc::Greater => fragment > stored,
            DepthFunc::NotEqual => fragment != stored,
            DepthFunc::GreaterEqual => fragment >= stored,
            DepthFunc::Always => true,
        }
    }

    /// [`DepthFunc::passes`] on eight lanes at once (same comparisons, NaN included).
    #[inline(always)]
    pub fn passes_lanes<L: Lanes>(self, lanes: L, fragment: L::F32, stored: L::F32) -> L::Mask {
        match self {
            DepthFunc::Never => lanes.mask_all(false),
            DepthFunc::Less => fragment.simd_lt(stored),
            DepthFunc::Equal => fragment.simd_eq(stored),
            DepthFunc::LessEqual => fragment.simd_le(stored),
            DepthFunc::Greater => fragment.simd_gt(stored),
            DepthFunc::NotEqual => fragment.simd_ne(stored),
            DepthFunc::GreaterEqual => fragment.simd_ge(stored),
            DepthFunc::Always => lanes.mask_all(true),
        }
    }
}

/// How a fragment's colour combines with the stored one (all in linear space).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BlendMode {
    /// `dst = src`.
    #[default]
    Replace,
    /// Porter–Duff "over" with premultiplied colours: `dst = src + dst × (1 − src.a)`.
    PremultipliedOver,
    /// Classic alpha blending: `dst.rgb = src.rgb × src.a + dst.rgb × (1 − src.a)`,
    /// `dst.a = src.a + dst.a × (1 − src.a)`.
    Alpha,
    /// `dst = src + dst`.
    Additive,
}

impl BlendMode {
    /// The blended colour.
    #[inline]
    pub fn blend(self, src: Vec4, dst: Vec4) -> Vec4 {
        match self {
            BlendMode::Replace => src,
            BlendMode::PremultipliedOver => src + dst * (1.0 - src.w),
            BlendMode::Alpha => {
                let a = src.w;
                let rgb = src.truncate() * a + dst.truncate() * (1.0 - a);
                rgb.extend(a + dst.w * (1.0 - a))
            }
            BlendMode::Additive => src + dst,
        }
    }

    /// [`BlendMode::blend`] on eight lanes at once, channel planes `[r, g, b, a]`, with the same
    /// operations per channel.
    #[inline(always)]
    pub fn blend_lanes<L: Lanes>(
        self,
        lanes: L,
        src: [L::F32; 4],
        dst: [L::F32; 4],
    ) -> [L::F32; 4] {
        let one = lanes.splat_f32(1.0);
        match self {
            BlendMode::Replace => src,
            BlendMode::PremultipliedOver => {
                let keep = one - src[3];
                [
                    src[0] + dst[0] * keep,
                    src[1] + dst[1] * keep,
                    src[2] + dst[2] * keep,
                    src[3] + dst[3] * keep,
                ]
            }
            BlendMode::Alpha => {
                let a = src[3];
                let keep = one - a;
                [
                    src[0] * a + dst[0] * keep,
                    src[1] * a + dst[1] * keep,
                    src[2] * a + dst[2] * keep,
                    a + dst[3] * keep,
                ]
            }
            BlendMode::Additive => [
                src[0] + dst[0],
                src[1] + dst[1],
                src[2] + dst[2],
                src[3] + dst[3],
            ],
        }
    }
}

/// What a draw's indices describe: OpenGL's primitive modes after strips, fans and loops are
/// unrolled into lists (glTF `TRIANGLES`, `LINES`, `POINTS`; OBJ `f`, `l`, `p`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub enum Topology {
    /// Three indices per triangle.
    #[default]
    Triangles,
    /// Two indices per line segment, drawn 1 pixel wide by OpenGL's rules.
    Lines,
    /// One index per point, drawn as the 1 × 1 pixel square centred on it.
    Points,
}

impl Topology {
    /// Indices per primitive: 3, 2 or 1.
    #[inline]
    pub fn vertices_per_primitive(self) -> usize {
        match self {
            Topology::Triangles => 3,
            Topology::Lines => 2,
            Topology::Points => 1,
        }
    }

    /// The lower-case name (`triangles`, `lines`, `points`).
    pub fn name(self) -> &'static str {
        match self {
            Topology::Triangles => "triangles",
            Topology::Lines => "lines",
            Topology::Points => "points",
        }
    }
}

/// Fixed-function state of a draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderState {
    /// Which faces are removed.
    pub cull: CullMode,
    /// Which winding is front.
    pub front_face: FrontFace,
    /// Whether fragments are tested against the depth buffer.
    pub depth_test: bool,
    /// The depth comparison when testing.
    pub depth_func: DepthFunc,
    /// Whether passing fragments write their depth.
    pub depth_write: bool,
    /// How colours are combined.
    pub blend: BlendMode,
    /// Sort the draw's triangles back to front by the clip-space w of their centroid (the eye
    /// distance for perspective projections) before rasterizing; the user's buffers stay as
    /// they are. For transparency (the lecture exercise's step e).
    pub sort_back_to_front: bool,
}

impl Default for RenderState {
    fn default() -> Self {
        Self {
            cull: CullMode::Back,
            front_face: FrontFace::Ccw,
            depth_test: true,
            depth_func: DepthFunc::Less,
            depth_write: true,
            blend: BlendMode::Replace,
            sort_back_to_front: false,
        }
    }
}

/// How the ids pass encodes a pixel's ids (the same in every backend): the colour is
/// `(instance, primitive, draw, 1)`, each id as an exact `f32` integer, and 0 means background
/// (nothing drawn). Ids are stored in `f32`, so they are exact up to [`ids::MAX_EXACT_ID`].
pub mod ids {
    /// Largest id an `f32` channel holds exactly (2^24).
    pub const MAX_EXACT_ID: u32 = 1 << 24;
    /// The id of the background (no geometry).
    pub const BACKGROUND: u32 = 0;

    /// Instance id of a scene draw made from the node with index `node_index`.
    #[inline]
    pub fn instance(node_index: usize) -> u32 {
        (node_index as u32).saturating_add(1)
    }

    /// Draw id of the `draw_index`-th draw of a scene.
    #[inline]
    pub fn draw(draw_index: usize) -> u32 {
        (draw_index as u32).saturating_add(1)
    }

    /// Primitive id of triangle `primitive` of its draw.
    #[inline]
    pub fn primitive(primitive: u32) -> u32 {
        primitive.saturating_add(1)
    }

    /// The colour the ids pass writes.
    #[inline]
    pub fn encode(instance: u32, primitive: u32, draw: u32) -> glam::Vec4 {
        glam::Vec4::new(instance as f32, primitive as f32, draw as f32, 1.0)
    }
}
