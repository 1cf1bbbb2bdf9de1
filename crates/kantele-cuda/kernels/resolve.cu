// Resolve: the frame's linear float colour to 8-bit RGBA, sRGB-encoded (alpha linear), row 0 at
// the top, as `kantele::color::encode_rgba8(c, true)` does on the host. Used for timing with an
// 8-bit target (the fair counterpart of the GL backend's RGBA8 target) and by the viewer.
#include "common.cuh"

__device__ __forceinline__ float linear_to_srgb(float c) {
    c = isnan(c) ? 0.0f : fminf(fmaxf(c, 0.0f), 1.0f);
    if (c <= 0.0031308f) return mul(c, 12.92f);
    return sub(mul(1.055f, powf(c, divide(1.0f, 2.4f))), 0.055f);
}

__device__ __forceinline__ unsigned char unorm8(float c) {
    c = isnan(c) ? 0.0f : fminf(fmaxf(c, 0.0f), 1.0f);
    return (unsigned char)(u32)add(mul(c, 255.0f), 0.5f);
}

extern "C" __global__ void kantele_resolve_rgba8(FrameUniforms f, const float4* color,
                                                 uchar4* out) {
    u32 i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= f.width * f.height) return;
    float4 c = color[i];
    out[i] = make_uchar4(unorm8(linear_to_srgb(c.x)), unorm8(linear_to_srgb(c.y)),
                         unorm8(linear_to_srgb(c.z)), unorm8(c.w));
}
