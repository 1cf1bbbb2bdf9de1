// The thesis' two CUDA schemes, kept as baselines beside the tiled pipeline. Both reuse the
// vertex and primitive stages and the same per-pixel path, on a framebuffer in global memory.
// - "one call, one triangle" (ocot): one launch per triangle over its bounding box in 16 × 16
//   thread blocks. Launches on one stream run one after another, so triangles stay in order and
//   no two threads of a launch share a pixel.
// - "one call, many triangles" (ocmt): one launch per batch of triangles over the whole target
//   in 16 × 16 blocks; each thread owns one pixel and walks the batch in order.
// Unlike the thesis, neither has a depth race: a pixel is only ever touched by one thread of
// one launch at a time.
#include "common.cuh"

#define BASELINE_BLOCK 16

// Clears colour and depth (one thread per pixel).
extern "C" __global__ void kantele_clear(FrameUniforms f, float4* color, float* depth) {
    u32 x = blockIdx.x * blockDim.x + threadIdx.x;
    u32 y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= f.width || y >= f.height) return;
    u64 i = (u64)y * f.width + x;
    color[i] = make_float4(f.clear_color[0], f.clear_color[1], f.clear_color[2], f.clear_color[3]);
    depth[i] = 1.0f;
}

// ocot: the grid covers `setups[ref].bbox` from its top-left corner.
extern "C" __global__ void kantele_ocot_triangle(FrameUniforms f, SceneView s,
                                                 const TriangleSetup* setups,
                                                 const float* setup_attrs, u32 ref, float4* color,
                                                 float* depth) {
    const TriangleSetup& t = setups[ref];
    int x = t.bbox.x0 + (int)(blockIdx.x * blockDim.x + threadIdx.x);
    int y = t.bbox.y0 + (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= t.bbox.x1 || y >= t.bbox.y1 || !covers(t, x, y)) return;
    u64 i = (u64)y * f.width + x;
    process_pixel(f, s, t, setup_attrs + (u64)ref * 3 * NV, x, y, depth[i], color + i);
}

// ocmt: `refs[first .. first + count)` in order, the grid covering the whole target.
extern "C" __global__ void kantele_ocmt_batch(FrameUniforms f, SceneView s,
                                              const TriangleSetup* setups,
                                              const float* setup_attrs, const u32* refs, u32 first,
                                              u32 count, float4* color, float* depth) {
    int x = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    int y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= (int)f.width || y >= (int)f.height) return;
    u64 i = (u64)y * f.width + x;
    float d = depth[i];
    for (u32 k = first; k < first + count; ++k) {
        const TriangleSetup& t = setups[refs[k]];
        if (x < t.bbox.x0 || x >= t.bbox.x1 || y < t.bbox.y0 || y >= t.bbox.y1) continue;
        if (!covers(t, x, y)) continue;
        process_pixel(f, s, t, setup_attrs + (u64)refs[k] * 3 * NV, x, y, d, color + i);
    }
    depth[i] = d;
}
