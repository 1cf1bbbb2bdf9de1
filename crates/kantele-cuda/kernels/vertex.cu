// Vertex stage: the model-view-projection matrix of every draw, then every vertex of every draw
// transformed and its varyings written (`MaterialShader::vertex`: world normal, texcoord, colour).
#include "common.cuh"

// `view_projection * model` per draw, as glam multiplies matrices (column by column).
extern "C" __global__ void kantele_draw_matrices(FrameUniforms f, const DrawRecord* draws,
                                                 float* mvp) {
    u32 d = blockIdx.x * blockDim.x + threadIdx.x;
    if (d >= f.draw_count) return;
    for (int c = 0; c < 4; ++c) {
        V4 col = mat4_mul_v4(f.view_projection, v4_load(draws[d].model + 4 * c));
        mvp[16 * d + 4 * c + 0] = col.x;
        mvp[16 * d + 4 * c + 1] = col.y;
        mvp[16 * d + 4 * c + 2] = col.z;
        mvp[16 * d + 4 * c + 3] = col.w;
    }
}

// The draw whose `[shaded_base, shaded_base + vertex_count)` holds slot `g` (draws are sorted by
// `shaded_base`; a binary search for the last base ≤ g).
__device__ __forceinline__ u32 draw_of_vertex(const DrawRecord* draws, u32 count, u32 g) {
    u32 lo = 0, hi = count;
    while (hi - lo > 1) {
        u32 mid = (lo + hi) / 2;
        if (draws[mid].shaded_base <= g) lo = mid; else hi = mid;
    }
    return lo;
}

// One thread per shaded vertex: `pos_clip[g]` and `varyings[g * NV ..]`.
extern "C" __global__ void kantele_vertex(FrameUniforms f, const DrawRecord* draws,
                                          const float* mvp, const StandardVertex* vertices,
                                          float4* pos_clip, float* varyings) {
    u32 g = blockIdx.x * blockDim.x + threadIdx.x;
    if (g >= f.shaded_count) return;
    u32 d = draw_of_vertex(draws, f.draw_count, g);
    const DrawRecord& draw = draws[d];
    const StandardVertex v = vertices[draw.vertex_base + (g - draw.shaded_base)];
    V4 p = mat4_mul_v4(mvp + 16 * d, {v.position[0], v.position[1], v.position[2], 1.0f});
    pos_clip[g] = make_float4(p.x, p.y, p.z, p.w);
    V3 n = mat3_mul_v3(draw.normal_matrix, {v.normal[0], v.normal[1], v.normal[2]});
    float* out = varyings + (u64)g * NV;
    out[0] = n.x;
    out[1] = n.y;
    out[2] = n.z;
    out[3] = v.texcoord[0];
    out[4] = v.texcoord[1];
    out[5] = v.color[0];
    out[6] = v.color[1];
    out[7] = v.color[2];
    out[8] = v.color[3];
}
