// Layout probe: writes the byte offset of every record field the host and the kernels share, in
// the order of `kantele_cuda::layout::FIELDS`. Run once at start-up: the backend refuses to
// draw if any offset differs from Rust's (sizes are already `static_assert`ed in common.cuh).
#include "common.cuh"

#define OFFSET(base, field) ((u64)((const char*)&(base)->field - (const char*)(base)))

extern "C" __global__ void kantele_layout_probe(const TriangleSetup* t, const DrawRecord* d,
                                                const FrameUniforms* f, const LevelRecord* l,
                                                u64* out) {
    if (threadIdx.x != 0 || blockIdx.x != 0) return;
    int i = 0;
    out[i++] = OFFSET(t, area2);
    out[i++] = OFFSET(t, bbox);
    out[i++] = OFFSET(t, pos_subpixel);
    out[i++] = OFFSET(t, depth);
    out[i++] = OFFSET(t, depth_range);
    out[i++] = OFFSET(t, inv_w);
    out[i++] = OFFSET(t, bary_gradient);
    out[i++] = OFFSET(t, draw);
    out[i++] = OFFSET(t, primitive_id);
    out[i++] = OFFSET(t, flags);
    out[i++] = OFFSET(t, reserved);
    out[i++] = OFFSET(d, normal_matrix);
    out[i++] = OFFSET(d, base_color_factor);
    out[i++] = OFFSET(d, emissive);
    out[i++] = OFFSET(d, alpha_cutoff);
    out[i++] = OFFSET(d, flags);
    out[i++] = OFFSET(d, texture);
    out[i++] = OFFSET(d, sampler);
    out[i++] = OFFSET(d, emissive_texture);
    out[i++] = OFFSET(d, emissive_sampler);
    out[i++] = OFFSET(d, node_id);
    out[i++] = OFFSET(d, vertex_base);
    out[i++] = OFFSET(d, shaded_base);
    out[i++] = OFFSET(f, to_light);
    out[i++] = OFFSET(f, ambient);
    out[i++] = OFFSET(f, guard_kx);
    out[i++] = OFFSET(f, clear_color);
    out[i++] = OFFSET(f, width);
    out[i++] = OFFSET(f, pass);
    out[i++] = OFFSET(f, chunk_count);
    out[i++] = OFFSET(l, width);
}
