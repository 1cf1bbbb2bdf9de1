// Reads triangles (clip-space positions and varyings as f32 bit patterns) and prints what the
// CUDA kernels' device functions (common.cuh) make of them: classification, clipping, setup,
// barycentrics and depth at sample pixels. `tests/host_reference.rs` prints the same from the
// Rust core and compares.
#include "host_shim.h"
#include "../../kernels/common.cuh"

#include <cstdio>

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
                t.bbox.y1, t.front_facing, t.swapped);
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

int main() {
    unsigned int w, h, cull_back, front_cw;
    while (std::scanf("%u %u %u %u", &w, &h, &cull_back, &front_cw) == 4) {
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
