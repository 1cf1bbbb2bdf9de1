//! The programmable stages' interface: [`Shader`] (a vertex and a fragment program), what the
//! fragment program sees of one pixel ([`Fragment`]) or of eight at once ([`FragmentLanes`]).

use glam::Vec4;

use kantele_lanes::{F32x8, Lanes, Mask8};
use kantele_rules::MAX_VARYINGS;

/// A vertex and a fragment program with their uniforms (the shader's own fields).
///
/// The vertex stage turns a user-defined vertex into a clip-space position and writes
/// `varying_count()` floats of varyings; the fragment stage receives them interpolated
/// perspective-correctly and returns a colour, or `None` to discard the fragment.
pub trait Shader: Send + Sync {
    /// The vertex type this shader reads.
    type Vertex: Sync;

    /// Number of `f32` varyings written by [`Shader::vertex`] (at most [`MAX_VARYINGS`]).
    fn varying_count(&self) -> usize;

    /// Transforms one vertex: returns its clip-space position and fills `varyings`
    /// (`varying_count()` long).
    fn vertex(&self, vertex: &Self::Vertex, varyings: &mut [f32]) -> Vec4;

    /// Shades one fragment: its colour, or `None` to discard it.
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4>;

    /// Shades up to eight fragments of one pixel row at once (the lanes of
    /// [`FragmentLanes::active`]); lanes that are not active are ignored. The default runs
    /// [`Shader::fragment`] on each active lane, so every shader works lane-wide; built-in
    /// shaders override it with arithmetic on whole lanes. Must give the same colours as
    /// `fragment` would, lane by lane.
    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        let lanes = fragments.lanes;
        let active = fragments.active.bits();
        let mut rgba = [[0.0f32; 8]; 4];
        let mut keep = 0u8;
        let mut varyings = [0.0f32; MAX_VARYINGS];
        let per_lane = fragments.per_lane();
        for k in 0..8 {
            if active & (1 << k) == 0 {
                continue;
            }
            let fragment = fragments.lane(&per_lane, k, &mut varyings);
            if let Some(c) = self.fragment(&fragment) {
                for (channel, value) in rgba.iter_mut().zip(c.to_array()) {
                    channel[k] = value;
                }
                keep |= 1 << k;
            }
        }
        ShadedLanes {
            color: [
                lanes.f32_from_array(rgba[0]),
                lanes.f32_from_array(rgba[1]),
                lanes.f32_from_array(rgba[2]),
                lanes.f32_from_array(rgba[3]),
            ],
            keep: lanes.mask_from_bits(keep),
        }
    }

    /// Runs `job` (the per-pixel work of one triangle) with the lane program this draw's
    /// fragments are shaded by. The default hands over [`Shader::fragment_lanes`] itself; a
    /// shader whose program branches on properties fixed for the whole draw (the built-in
    /// materials: lit or unlit, vertex colours, alpha mode) overrides it to choose, once per
    /// triangle, a program compiled with those branches decided, so that the per-row code holds
    /// only the arithmetic. Whatever it chooses must shade exactly as `fragment_lanes` does.
    #[inline(always)]
    fn with_lane_program<J: LaneProgramJob>(&self, job: J) -> J::Output
    where
        Self: Sized,
    {
        job.run(&ShaderLanes(self))
    }
}

/// A lane-wide fragment program, as the per-pixel kernel calls it for each row of eight pixels
/// (see [`Shader::with_lane_program`]).
pub trait LaneProgram: Sync {
    /// Whether the per-pixel kernel is compiled a second time for this program, for triangles
    /// whose varyings are all the same at the three vertices (a flat-coloured face): there
    /// [`FragmentLanes::varying`] is that value exactly, and a program that reads only varyings
    /// computes no perspective weights. A program that opts out (`false`) has one kernel, in
    /// which such triangles are interpolated like any other (`Σ weight_i · a_i`, within an ulp
    /// of the value); worth it for programs whose triangles are rarely constant and whose
    /// kernels are large (the textured ones).
    const CONSTANT_KERNELS: bool = true;

    /// Whether the per-pixel kernel may hand this program the fragments of several rows of a
    /// block packed together (where small triangles leave most lanes of a row empty, so that
    /// the program runs once for up to eight fragments instead of once per row): only for a
    /// program that computes each lane from that lane's own values alone and reads neither
    /// [`FragmentLanes::x`] nor [`FragmentLanes::y`] (for a packed group they name the block's
    /// first pixel, not lane 0's). Lanes then hold the same values as in their own row, so
    /// the picture is the same.
    const PACKED_ROWS: bool = false;

    /// Shades the active lanes of one row, as [`Shader::fragment_lanes`].
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L>;
}

/// Work that runs with a draw's [`LaneProgram`], compiled once per program type (see
/// [`Shader::with_lane_program`]). The renderer implements it; shaders only call
/// [`LaneProgramJob::run`].
pub trait LaneProgramJob {
    /// What the work returns.
    type Output;
    /// Does the work with `program` shading the fragments.
    fn run<P: LaneProgram>(self, program: &P) -> Self::Output;
}

/// A shader's own [`Shader::fragment_lanes`] as a [`LaneProgram`].
pub struct ShaderLanes<'s, S>(pub &'s S);

impl<S: Shader> LaneProgram for ShaderLanes<'_, S> {
    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        self.0.fragment_lanes(fragments)
    }
}

/// A [`Shader`] made of two closures, for quick programs:
/// `FnShader::new(n, |v, out| …, |frag| …)`.
pub struct FnShader<V, VS, FS> {
    varying_count: usize,
    vertex: VS,
    fragment: FS,
    _vertex: std::marker::PhantomData<fn(&V)>,
}

impl<V, VS, FS> FnShader<V, VS, FS>
where
    VS: Fn(&V, &mut [f32]) -> Vec4 + Send + Sync,
    FS: Fn(&Fragment<'_>) -> Option<Vec4> + Send + Sync,
{
    /// A shader writing `varying_count` varyings with the given stages.
    pub fn new(varying_count: usize, vertex: VS, fragment: FS) -> Self {
        Self {
            varying_count,
            vertex,
            fragment,
            _vertex: std::marker::PhantomData,
        }
    }
}

impl<V: Sync, VS, FS> Shader for FnShader<V, VS, FS>
where
    VS: Fn(&V, &mut [f32]) -> Vec4 + Send + Sync,
    FS: Fn(&Fragment<'_>) -> Option<Vec4> + Send + Sync,
{
    type Vertex = V;
    fn varying_count(&self) -> usize {
        self.varying_count
    }
    fn vertex(&self, vertex: &V, varyings: &mut [f32]) -> Vec4 {
        (self.vertex)(vertex, varyings)
    }
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        (self.fragment)(fragment)
    }
}

/// What the fragment stage sees of one pixel.
pub struct Fragment<'a> {
    /// Pixel column (0 = left).
    pub x: u32,
    /// Pixel row (0 = top).
    pub y: u32,
    /// Window depth in [0, 1].
    pub depth: f32,
    /// Index of the triangle within its draw (before clipping and sorting).
    pub primitive_id: u32,
    /// Whether the triangle faces the viewer.
    pub front_facing: bool,
    varyings: &'a [f32],
    interpolation: &'a Interpolation<'a>,
    /// Perspective weights of the three vertices at this pixel (sum to 1).
    weights: [f32; 3],
    /// Weights proportional to `weights` ([`Fragment::varying_direction`]).
    direction_weights: [f32; 3],
    /// `1 / Σ(λ_i / w_i)`: the pixel's clip w.
    w: f32,
}

impl Fragment<'_> {
    /// The interpolated varyings.
    #[inline]
    pub fn varyings(&self) -> &[f32] {
        self.varyings
    }

    /// One interpolated varying.
    #[inline]
    pub fn varying(&self, index: usize) -> f32 {
        self.varyings[index]
    }

    /// Varying `index` times a positive factor that is the same for every varying of this
    /// fragment, without the perspective division: for values whose direction is all that
    /// counts (a normal about to be normalised). See [`FragmentLanes::varying_direction`],
    /// whose lanes it equals bit for bit.
    #[inline]
    pub fn varying_direction(&self, index: usize) -> f32 {
        self.interpolation
            .interpolate(index, self.direction_weights)
    }

    /// Perspective-correct barycentric weights of the triangle's vertices at this pixel.
    pub fn weights(&self) -> [f32; 3] {
        self.weights
    }

    /// Screen-space derivatives `(∂v/∂x, ∂v/∂y)` of varying `index`, per pixel, computed
    /// analytically from the triangle's plane equations (thesis §2.3.3).
    pub fn derivatives(&self, index: usize) -> (f32, f32) {
        let ip = self.interpolation;
        let a = ip.attrs[index];
        let value = self.varyings[index];
        // v = N / S with S = Σ λ_i / w_i and N = Σ λ_i a_i / w_i; dv = (dN − v dS) / S = (dN − v dS)·w.
        let d = |dl: &[f32; 3]| {
            let dq = [
                dl[0] * ip.inv_w[0],
                dl[1] * ip.inv_w[1],
                dl[2] * ip.inv_w[2],
            ];
            let ds = dq[0] + dq[1] + dq[2];
            let dn = dq[0] * a[0] + dq[1] * a[1] + dq[2] * a[2];
            (dn - value * ds) * self.w
        };
        (d(&ip.dl_dx), d(&ip.dl_dy))
    }
}

/// The varyings of a triangle's three (oriented) vertices, varying-major (entry `i` holds
/// varying `i` of vertices 0, 1 and 2), in an array of fixed size (entries past the varying
/// count are 0): a shader's constant index into it needs no bounds check and no arithmetic in
/// the per-pixel loop, whatever the draw's varying count.
pub(crate) type VertexVaryings = [[f32; 3]; MAX_VARYINGS];

/// `attrs` (the three vertices' varyings, vertex-major, `3 × varying_count` values with
/// `varying_count` at most `MAX_VARYINGS`) as [`VertexVaryings`].
#[inline(always)]
pub(crate) fn vertex_varyings(attrs: &[f32]) -> VertexVaryings {
    let mut out = [[0.0; 3]; MAX_VARYINGS];
    let n = (attrs.len() / 3).min(MAX_VARYINGS);
    for (i, values) in out[..n].iter_mut().enumerate() {
        *values = [attrs[i], attrs[n + i], attrs[2 * n + i]];
    }
    out
}

/// Whether every varying has the same bits at the three vertices ([`Interpolation::constant`]);
/// `attrs` is vertex-major, as [`vertex_varyings`] reads it.
#[inline]
pub(crate) fn constant_varyings(attrs: &[f32]) -> bool {
    let n = attrs.len() / 3;
    let (v0, rest) = attrs.split_at(n);
    let (v1, v2) = rest.split_at(n);
    v0.iter()
        .zip(v1)
        .zip(v2)
        .all(|((a, b), c)| a.to_bits() == b.to_bits() && b.to_bits() == c.to_bits())
}

/// Per-triangle data for interpolation and derivatives, shared by [`Fragment`] and
/// [`FragmentLanes`] so that both evaluate the same formulas.
pub(crate) struct Interpolation<'a> {
    /// Varyings of the three (oriented) vertices, varying-major.
    pub(crate) attrs: &'a VertexVaryings,
    pub(crate) varying_count: usize,
    pub(crate) inv_w: [f32; 3],
    pub(crate) dl_dx: [f32; 3],
    pub(crate) dl_dy: [f32; 3],
    /// Every varying has the same bits at the three vertices (a flat-coloured face, a face
    /// normal, no varyings at all): each is then that value at every pixel, exactly, and
    /// nothing is interpolated (no perspective weights, no division).
    pub(crate) constant: bool,
}

impl Interpolation<'_> {
    /// Varying `index` from `weights` (perspective-correct, or proportional to them):
    /// `Σ weight_i · a_i`, or the vertices' common value where every varying is
    /// [`Interpolation::constant`].
    #[inline(always)]
    fn interpolate(&self, index: usize, weights: [f32; 3]) -> f32 {
        let a = self.attrs[index];
        if self.constant {
            return a[0];
        }
        weights[0] * a[0] + weights[1] * a[1] + weights[2] * a[2]
    }
}

/// What the fragment stage sees of up to eight horizontally adjacent pixels of one row: lane `k`
/// is pixel `(x + k, y)`. Values of lanes outside [`FragmentLanes::active`] are unspecified.
pub struct FragmentLanes<'a, L: Lanes> {
    /// The instruction set's token (makes lane values).
    pub lanes: L,
    /// Column of lane 0 (a multiple of 8).
    pub x: u32,
    /// Pixel row (0 = top).
    pub y: u32,
    /// The lanes that hold a fragment (covered, inside the depth range, passing the depth test).
    pub active: L::Mask,
    /// Window depth in [0, 1].
    pub depth: L::F32,
    /// Index of the triangle within its draw (before clipping and sorting).
    pub primitive_id: u32,
    /// Whether the triangle faces the viewer.
    pub front_facing: bool,
    /// Perspective-correct weights of the three vertices and the lanes' clip `w`. A kernel for
    /// constant triangles computes them too; where its program reads only varyings, the
    /// compiler removes them (and their division) as unused.
    pub(crate) weights: [L::F32; 3],
    /// Screen-space barycentrics times each vertex's `1/w` over the largest of the three: the
    /// perspective-correct weights times the positive factor `w_min / w`, with no division
    /// (see [`FragmentLanes::varying_direction`]).
    pub(crate) direction_weights: [L::F32; 3],
    pub(crate) w: L::F32,
    pub(crate) interpolation: &'a Interpolation<'a>,
}

/// The per-lane values [`FragmentLanes::lane`] reads, extracted once per row.
pub(crate) struct PerLane {
    weights: [[f32; 8]; 3],
    direction_weights: [[f32; 8]; 3],
    w: [f32; 8],
    depth: [f32; 8],
}

impl<'a, L: Lanes> FragmentLanes<'a, L> {
    /// Interpolated varying `index` (perspective-correct): `Σ weight_i · a_i`; on a triangle
    /// whose every varying has the same bits at its three vertices, exactly that value.
    #[inline(always)]
    pub fn varying(&self, index: usize) -> L::F32 {
        self.interpolate(index, self.weights)
    }

    /// Varying `index` times a positive factor per lane that is the same for every varying of
    /// the lane (`w_min / w`, the triangle's smallest vertex `w` over the lane's clip `w`; 1 on
    /// a constant triangle, where it is the value exactly), for values whose direction is all
    /// that counts: a normal about to be normalised. It needs no perspective division, so a
    /// program that reads nothing else has none per row.
    #[inline(always)]
    pub fn varying_direction(&self, index: usize) -> L::F32 {
        self.interpolate(index, self.direction_weights)
    }

    /// `Σ weight_i · a_i` for varying `index`, or the vertices' common value on a constant
    /// triangle (as [`Interpolation::interpolate`] per lane).
    #[inline(always)]
    fn interpolate(&self, index: usize, weights: [L::F32; 3]) -> L::F32 {
        let a = self.interpolation.attrs[index];
        let lanes = self.lanes;
        // A compile-time constant in the 1× kernel (compiled once more for constant triangles).
        if self.interpolation.constant {
            return lanes.splat_f32(a[0]);
        }
        weights[0] * lanes.splat_f32(a[0])
            + weights[1] * lanes.splat_f32(a[1])
            + weights[2] * lanes.splat_f32(a[2])
    }

    /// Perspective-correct barycentric weights of the triangle's vertices (sum to 1).
    #[inline(always)]
    pub fn weights(&self) -> [L::F32; 3] {
        self.weights
    }

    /// Screen-space derivatives `(∂v/∂x, ∂v/∂y)` of varying `index`, per pixel, as
    /// [`Fragment::derivatives`] computes them.
    #[inline(always)]
    pub fn derivatives(&self, index: usize) -> (L::F32, L::F32) {
        let ip = self.interpolation;
        let lanes = self.lanes;
        let value = self.varying(index);
        let a = ip.attrs[index];
        let d = |dl: &[f32; 3]| {
            let dq = [
                dl[0] * ip.inv_w[0],
                dl[1] * ip.inv_w[1],
                dl[2] * ip.inv_w[2],
            ];
            let ds = dq[0] + dq[1] + dq[2];
            let dn = dq[0] * a[0] + dq[1] * a[1] + dq[2] * a[2];
            (lanes.splat_f32(dn) - value * lanes.splat_f32(ds)) * self.w
        };
        (d(&ip.dl_dx), d(&ip.dl_dy))
    }

    /// The lane values [`FragmentLanes::lane`] needs, extracted once.
    #[inline(always)]
    pub(crate) fn per_lane(&self) -> PerLane {
        PerLane {
            weights: [
                self.weights[0].to_array(),
                self.weights[1].to_array(),
                self.weights[2].to_array(),
            ],
            direction_weights: [
                self.direction_weights[0].to_array(),
                self.direction_weights[1].to_array(),
                self.direction_weights[2].to_array(),
            ],
            w: self.w.to_array(),
            depth: self.depth.to_array(),
        }
    }

    /// The scalar fragment of lane `k`, its varyings written to `varyings` with the same
    /// operations as [`FragmentLanes::varying`].
    #[inline(always)]
    pub(crate) fn lane<'v>(
        &'v self,
        per_lane: &PerLane,
        k: usize,
        varyings: &'v mut [f32; MAX_VARYINGS],
    ) -> Fragment<'v> {
        let ip = self.interpolation;
        let n = ip.varying_count;
        let weights = [
            per_lane.weights[0][k],
            per_lane.weights[1][k],
            per_lane.weights[2][k],
        ];
        for (index, v) in varyings[..n].iter_mut().enumerate() {
            *v = ip.interpolate(index, weights);
        }
        Fragment {
            x: self.x + k as u32,
            y: self.y,
            depth: per_lane.depth[k],
            primitive_id: self.primitive_id,
            front_facing: self.front_facing,
            varyings: &varyings[..n],
            interpolation: ip,
            weights,
            direction_weights: [
                per_lane.direction_weights[0][k],
                per_lane.direction_weights[1][k],
                per_lane.direction_weights[2][k],
            ],
            w: per_lane.w[k],
        }
    }
}

/// What a lane-wide fragment program returns: a colour per lane (linear RGBA, one lane value per
/// channel) and which lanes are kept (the others are discarded).
pub struct ShadedLanes<L: Lanes> {
    /// Red, green, blue and alpha.
    pub color: [L::F32; 4],
    /// Lanes whose fragment is written; the rest are discarded.
    pub keep: L::Mask,
}
