// Fine raster, materials and blending: one thread block per 64 × 64 tile walks the tile's bin in
// submission order (`Frame::end`'s raster loop). Each of the 256 threads owns a 4 × 4 pixel quad
// of the tile, so no two threads ever touch the same pixel: the depth test and blending need no
// atomics and see triangles in order, and the picture is the same on every run. The tile's depth
// lives in shared memory; colour is read and written in the frame's colour buffer, which this
// block alone touches inside its tile. Coverage uses the setup's integer edge functions with the
// top-left bias, stepped exactly from the quad's first pixel centre; barycentrics, depth and
// varyings are computed from scratch per pixel, as on the CPU.
#include "common.cuh"

#define RASTER_THREADS 256
#define QUAD 4
#define QUADS_PER_ROW (TILE_SIZE / QUAD)
static_assert(QUADS_PER_ROW * QUADS_PER_ROW == RASTER_THREADS, "one quad per thread");

struct RasterCounters {
    u32 covered, shaded, discarded;
};

extern "C" __global__ void __launch_bounds__(RASTER_THREADS)
    kantele_raster(FrameUniforms f, SceneView s, const TriangleSetup* setups,
                   const float* setup_attrs, const u32* tile_start, const u32* bins, u64* status,
                   float4* color, float* depth_out) {
    // An overflowed frame is redone with larger buffers: do not draw from incomplete bins.
    if (status[STATUS_CLIP_REQUESTED] > f.clip_capacity ||
        status[STATUS_BIN_TOTAL] > f.bin_capacity) {
        return;
    }
    __shared__ float tile_depth[TILE_SIZE * TILE_SIZE];
    __shared__ u32 refs[RASTER_THREADS];
    __shared__ RasterCounters block;
    const u32 tile = blockIdx.x;
    const int tile_x = (int)(tile % f.tiles_x) * TILE_SIZE;
    const int tile_y = (int)(tile / f.tiles_x) * TILE_SIZE;
    const int qx = (int)(threadIdx.x % QUADS_PER_ROW) * QUAD;
    const int qy = (int)(threadIdx.x / QUADS_PER_ROW) * QUAD;
    const int x0 = tile_x + qx, y0 = tile_y + qy;
    const float4 clear =
        make_float4(f.clear_color[0], f.clear_color[1], f.clear_color[2], f.clear_color[3]);
    for (int j = 0; j < QUAD; ++j) {
        for (int i = 0; i < QUAD; ++i) {
            tile_depth[(qy + j) * TILE_SIZE + qx + i] = 1.0f;
            if (x0 + i < (int)f.width && y0 + j < (int)f.height) {
                color[(u64)(y0 + j) * f.width + x0 + i] = clear;
            }
        }
    }
    if (threadIdx.x == 0) block = {0, 0, 0};
    RasterCounters c = {0, 0, 0};
    const u32 begin = tile_start[tile], end = tile_start[tile + 1];
    for (u32 base = begin; base < end; base += RASTER_THREADS) {
        __syncthreads();
        if (base + threadIdx.x < end) refs[threadIdx.x] = bins[base + threadIdx.x];
        __syncthreads();
        const u32 n = min((u32)RASTER_THREADS, end - base);
        for (u32 k = 0; k < n; ++k) {
            const u32 ref = refs[k];
            const TriangleSetup& t = setups[ref];
            const PixelRect b = t.bbox;
            if (x0 + QUAD <= b.x0 || x0 >= b.x1 || y0 + QUAD <= b.y0 || y0 >= b.y1) continue;
            const float* attrs = setup_attrs + (u64)ref * 3 * NV;
            i64 row[3], step_x[3], step_y[3];
            for (int e = 0; e < 3; ++e) {
                const EdgeFunction ef = t.edges[e];
                row[e] = ef.a * pixel_center(x0) + ef.b * pixel_center(y0) + ef.c + ef.bias;
                step_x[e] = ef.a * SUBPIXEL_ONE;
                step_y[e] = ef.b * SUBPIXEL_ONE;
            }
            for (int j = 0; j < QUAD; ++j) {
                i64 e0 = row[0], e1 = row[1], e2 = row[2];
                const int y = y0 + j;
                for (int i = 0; i < QUAD; ++i) {
                    const int x = x0 + i;
                    if ((e0 | e1 | e2) >= 0 && x >= b.x0 && x < b.x1 && y >= b.y0 && y < b.y1) {
                        c.covered += 1;
                        int r = process_pixel(f, s, t, attrs, x, y,
                                              tile_depth[(qy + j) * TILE_SIZE + qx + i],
                                              color + (u64)y * f.width + x);
                        if (r != 0) c.shaded += 1;
                        if (r == 2) c.discarded += 1;
                    }
                    e0 += step_x[0];
                    e1 += step_x[1];
                    e2 += step_x[2];
                }
                row[0] += step_y[0];
                row[1] += step_y[1];
                row[2] += step_y[2];
            }
        }
    }
    for (int j = 0; j < QUAD; ++j) {
        for (int i = 0; i < QUAD; ++i) {
            if (x0 + i < (int)f.width && y0 + j < (int)f.height) {
                depth_out[(u64)(y0 + j) * f.width + x0 + i] =
                    tile_depth[(qy + j) * TILE_SIZE + qx + i];
            }
        }
    }
    __syncthreads();
    if (c.covered) atomicAdd(&block.covered, c.covered);
    if (c.shaded) atomicAdd(&block.shaded, c.shaded);
    if (c.discarded) atomicAdd(&block.discarded, c.discarded);
    __syncthreads();
    if (threadIdx.x == 0) {
        atomicAdd(&status[STATUS_COVERED], (u64)block.covered);
        atomicAdd(&status[STATUS_SHADED], (u64)block.shaded);
        atomicAdd(&status[STATUS_DISCARDED], (u64)block.discarded);
    }
}
