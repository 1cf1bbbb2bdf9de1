// Reads triangles (clip-space positions and varyings as f32 bit patterns) and prints what the
// CUDA kernels' device functions (common.cuh) make of them: classification, clipping, setup,
// barycentrics and depth at sample pixels. `tests/cuda/host_reference.rs` prints the same from the
// Rust core and compares.
#include "host_shim.h"
#include "../../kernels/common.cuh"

#include <cstdio>
#include <cstdlib>

static float from_bits(unsigned int b) { return __int_as_float(b); }
static unsigned int bits(float f) {
    unsigned int b;
    std::memcpy(&b, &f, 4);
    return b;
}

static void print_setup(int code, const TriangleSetup& t) {
    if (code != SETUP_OK) {
        std::printf("S %d\n", code);
        return;
    }
    std::printf("S 0 area %lld bbox %d %d %d %d ff %d sw %d", t.area2, t.bbox.x0, t.bbox.y0, t.bbox.x1,
                t.bbox.y1, (t.flags & KANTELE_TRIANGLE_FRONT_FACING) ? 1 : 0,
                (t.flags & KANTELE_TRIANGLE_SWAPPED) ? 1 : 0);
    for (int e = 0; e < 3; ++e)
        std::printf(" e %lld %lld %lld %lld", t.edges[e].a, t.edges[e].b, t.edges[e].c, t.edges[e].bias);
    for (int i = 0; i < 3; ++i)
        std::printf(" v %lld %lld %08x %08x", t.pos_subpixel[i][0], t.pos_subpixel[i][1], bits(t.depth[i]),
                    bits(t.inv_w[i]));
    std::printf(" r %08x %08x g %08x %08x %08x %08x\n", bits(t.depth_range[0]), bits(t.depth_range[1]),
                bits(t.bary_gradient[0][0]), bits(t.bary_gradient[0][1]), bits(t.bary_gradient[1][0]),
                bits(t.bary_gradient[1][1]));
    // Sample pixels: the bbox corners and centre.
    int xs[3] = {t.bbox.x0, t.bbox.x1 - 1, (t.bbox.x0 + t.bbox.x1) / 2};
    int ys[3] = {t.bbox.y0, t.bbox.y1 - 1, (t.bbox.y0 + t.bbox.y1) / 2};
    for (int k = 0; k < 3; ++k) {
        float b[3];
        barycentrics(t, xs[k], ys[k], b);
        bool covered = true;
        for (int e = 0; e < 3; ++e) {
            const EdgeFunction& ef = t.edges[e];
            if (ef.a * pixel_center(xs[k]) + ef.b * pixel_center(ys[k]) + ef.c + ef.bias < 0) covered = false;
        }
        std::printf("P %d %d %d %08x %08x %08x %08x\n", xs[k], ys[k], covered ? 1 : 0, bits(b[0]), bits(b[1]),
                    bits(b[2]), bits(depth_at(t, b)));
    }
}

static float read_float() {
    unsigned int b = 0;
    if (std::scanf("%x", &b) != 1) std::exit(1);
    return from_bits(b);
}

// "M": view_projection (16), model (16), position (3) → MVP (16) and the clip position (4), as
// kantele_draw_matrices and kantele_vertex compute them.
static void matrices() {
    float vp[16], model[16], mvp[16], pos[3];
    for (float& v : vp) v = read_float();
    for (float& v : model) v = read_float();
    for (float& v : pos) v = read_float();
    for (int c = 0; c < 4; ++c) {
        V4 col = mat4_mul_v4(vp, v4_load(model + 4 * c));
        mvp[4 * c] = col.x;
        mvp[4 * c + 1] = col.y;
        mvp[4 * c + 2] = col.z;
        mvp[4 * c + 3] = col.w;
    }
    V4 p = mat4_mul_v4(mvp, {pos[0], pos[1], pos[2], 1.0f});
    std::printf("M");
    for (float v : mvp) std::printf(" %08x", bits(v));
    std::printf(" %08x %08x %08x %08x\n", bits(p.x), bits(p.y), bits(p.z), bits(p.w));
}

// "X": a texture's levels (count, then width height texels... each), the sampler codes
// (wrap_s wrap_t mag min), uv and λ → the sample (`Texture::sample_lod`).
static void texture() {
    unsigned int count;
    if (std::scanf("%u", &count) != 1 || count == 0 || count > 16) std::exit(1);
    LevelRecord levels[16];
    static float4 texels[1 << 16];
    u64 at = 0;
    for (unsigned int i = 0; i < count; ++i) {
        if (std::scanf("%u %u", &levels[i].width, &levels[i].height) != 2) std::exit(1);
        levels[i].offset = at;
        u64 n = (u64)levels[i].width * levels[i].height;
        if (at + n > (1u << 16)) std::exit(1);
        for (u64 k = 0; k < n; ++k) {
            float r = read_float(), g = read_float(), b = read_float(), a = read_float();
            texels[at + k] = make_float4(r, g, b, a);
        }
        at += n;
    }
    TextureRecord tex = {0, count, levels[0].width, levels[0].height};
    SamplerCodes d = {};
    if (std::scanf("%u %u %u %u", &d.wrap_s, &d.wrap_t, &d.mag_filter, &d.min_filter) != 4) std::exit(1);
    float u = read_float(), v = read_float(), lod = read_float();
    V4 c = sample_lod(texels, tex, levels, d, u, v, lod);
    std::printf("X %08x %08x %08x %08x\n", bits(c.x), bits(c.y), bits(c.z), bits(c.w));
}

int main() {
    unsigned int w, h, cull_back, front_cw;
    char kind[2];
    while (std::scanf("%1s", kind) == 1) {
        if (kind[0] == 'M') {
            matrices();
            continue;
        }
        if (kind[0] == 'X') {
            texture();
            continue;
        }
        if (std::scanf("%u %u %u %u", &w, &h, &cull_back, &front_cw) != 4) return 1;
        FrameUniforms f = {};
        unsigned int kx, ky, hw, hh;
        if (std::scanf("%x %x %x %x", &kx, &ky, &hw, &hh) != 4) return 1;
        f.width = w;
        f.height = h;
        f.guard_kx = from_bits(kx);
        f.guard_ky = from_bits(ky);
        f.half_width = from_bits(hw);
        f.half_height = from_bits(hh);
        V4 p[3];
        float vary[3][NV];
        for (int i = 0; i < 3; ++i) {
            unsigned int c[4];
            if (std::scanf("%x %x %x %x", &c[0], &c[1], &c[2], &c[3]) != 4) return 1;
            p[i] = {from_bits(c[0]), from_bits(c[1]), from_bits(c[2]), from_bits(c[3])};
            for (int k = 0; k < NV; ++k) {
                unsigned int v;
                if (std::scanf("%x", &v) != 1) return 1;
                vary[i][k] = from_bits(v);
            }
        }
        int test = classify(p, f.guard_kx, f.guard_ky);
        std::printf("C %d\n", test);
        if (test == CLIP_ACCEPT) {
            TriangleSetup t = {};
            int code = setup_triangle(f, p, cull_back != 0, front_cw != 0, t);
            print_setup(code, t);
        } else if (test == CLIP_CLIP) {
            ClipPolygon poly;
            poly.len = 3;
            for (int i = 0; i < 3; ++i) {
                poly.v[i].pos = p[i];
                for (int k = 0; k < NV; ++k) poly.v[i].varyings[k] = vary[i][k];
            }
            clip_polygon(poly, f.guard_kx, f.guard_ky);
            std::printf("N %d\n", poly.len);
            bool finite = true;
            for (int i = 0; i < poly.len; ++i) {
                finite = finite && v4_finite(poly.v[i].pos);
                std::printf("V %08x %08x %08x %08x", bits(poly.v[i].pos.x), bits(poly.v[i].pos.y),
                            bits(poly.v[i].pos.z), bits(poly.v[i].pos.w));
                for (int k = 0; k < NV; ++k) std::printf(" %08x", bits(poly.v[i].varyings[k]));
                std::printf("\n");
            }
            if (!finite) continue;
            for (int k = 1; k + 1 < poly.len; ++k) {
                V4 q[3] = {poly.v[0].pos, poly.v[k].pos, poly.v[k + 1].pos};
                TriangleSetup t = {};
                int code = setup_triangle(f, q, cull_back != 0, front_cw != 0, t);
                print_setup(code, t);
            }
        }
    }
    return 0;
}
