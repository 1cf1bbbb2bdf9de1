// Binning: every setup's index is appended to the bin of each 64 × 64 tile its bounding box
// touches, in submission order (`TileBins::bin_triangles`).
//
// Order without sorting: the triangle slots are cut into chunks of KANTELE_BIN_CHUNK, and one
// warp walks one chunk in order. A count pass fills a tile-major matrix `counts[tile][chunk]`;
// an exclusive scan of it gives each (tile, chunk) its place, so a tile's bin is its chunks'
// segments one after another, each in the chunk's order; the fill pass repeats the walk and
// writes. In each step of the walk the lanes share out the tiles of one triangle, so a matrix
// entry is written by one lane at a time (ordered by `__syncwarp`). Entries past
// `bin_capacity` are not written; the exact total (u64) tells the host to grow and redo.
#include "common.cuh"

#define WARP 32

template <bool FILL>
__device__ void bin_walk(const FrameUniforms& f, const TriangleSetup* setups, const SlotInfo* slots,
                         u32* matrix, u32* bins, u64* status) {
    u32 chunk = (blockIdx.x * blockDim.x + threadIdx.x) / WARP;
    u32 lane = threadIdx.x % WARP;
    if (chunk >= f.chunk_count) return;
    u32 begin = chunk * KANTELE_BIN_CHUNK;
    u32 end = min(begin + KANTELE_BIN_CHUNK, f.slot_count);
    u64 entries = 0;
    for (u32 s = begin; s < end; ++s) {
        SlotInfo info = slots[s];
        for (u32 i = 0; i < info.count; ++i) {
            u32 ref = info.first + i;
            PixelRect b = setups[ref].bbox;
            int tx0 = b.x0 >> KANTELE_TILE_LOG2, tx1 = (b.x1 - 1) >> KANTELE_TILE_LOG2;
            int ty0 = b.y0 >> KANTELE_TILE_LOG2, ty1 = (b.y1 - 1) >> KANTELE_TILE_LOG2;
            u32 nx = (u32)(tx1 - tx0 + 1);
            u32 n = nx * (u32)(ty1 - ty0 + 1);
            entries += n;
            for (u32 k = lane; k < n; k += WARP) {
                u32 tile = (u32)(ty0 + (int)(k / nx)) * f.tiles_x + (u32)tx0 + k % nx;
                u64 cell = (u64)tile * f.chunk_count + chunk;
                if (FILL) {
                    u32 at = matrix[cell];
                    matrix[cell] = at + 1;
                    if (at < f.bin_capacity) bins[at] = ref;
                } else {
                    matrix[cell] += 1;
                }
            }
            __syncwarp();
        }
    }
    if (!FILL && lane == 0 && entries > 0) atomicAdd(&status[STATUS_BIN_TOTAL], entries);
}

// Pass 1: `counts[tile * chunk_count + chunk]` (zeroed before) and the exact total.
extern "C" __global__ void kantele_bin_count(FrameUniforms f, const TriangleSetup* setups,
                                             const SlotInfo* slots, u32* counts, u64* status) {
    bin_walk<false>(f, setups, slots, counts, nullptr, status);
}

// Pass 2: `cursor` starts as the exclusive scan of `counts`; entries go to `bins`.
extern "C" __global__ void kantele_bin_fill(FrameUniforms f, const TriangleSetup* setups,
                                            const SlotInfo* slots, u32* cursor, u32* bins) {
    bin_walk<true>(f, setups, slots, cursor, bins, nullptr);
}

// Each tile's first bin entry: `tile_start[t] = offsets[t * chunk_count]` (launched before
// `kantele_bin_fill`, which advances `offsets` as its cursors), and
// `tile_start[tiles] = min(total, bin_capacity)` (the raster does not run on overflow).
extern "C" __global__ void kantele_bin_ranges(FrameUniforms f, const u32* offsets,
                                              const u64* status, u32* tile_start) {
    u32 tiles = f.tiles_x * f.tiles_y;
    u32 t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t < tiles) {
        tile_start[t] = f.chunk_count == 0 ? 0u : offsets[(u64)t * f.chunk_count];
    } else if (t == tiles) {
        u64 total = status[STATUS_BIN_TOTAL];
        tile_start[t] = (u32)min(total, (u64)f.bin_capacity);
    }
}

// Exclusive scan, level by level (the host plans the levels). Each 1024-thread block scans its
// 1024 elements of `in` into `out` (in place allowed) and writes its total to `block_sums`.
extern "C" __global__ void kantele_scan_blocks(const u32* in, u32* out, u32 n, u32* block_sums) {
    __shared__ u32 warp_sums[32];
    u32 i = blockIdx.x * blockDim.x + threadIdx.x;
    u32 lane = threadIdx.x % WARP, warp = threadIdx.x / WARP;
    u32 value = i < n ? in[i] : 0u;
    u32 x = value;
    for (u32 d = 1; d < WARP; d <<= 1) {
        u32 y = __shfl_up_sync(0xffffffffu, x, d);
        if (lane >= d) x += y;
    }
    if (lane == WARP - 1) warp_sums[warp] = x;
    __syncthreads();
    if (warp == 0) {
        u32 w = lane < blockDim.x / WARP ? warp_sums[lane] : 0u;
        for (u32 d = 1; d < WARP; d <<= 1) {
            u32 y = __shfl_up_sync(0xffffffffu, w, d);
            if (lane >= d) w += y;
        }
        warp_sums[lane] = w;  // inclusive per warp
    }
    __syncthreads();
    u32 before = warp == 0 ? 0u : warp_sums[warp - 1];
    if (i < n) out[i] = before + x - value;
    if (threadIdx.x == blockDim.x - 1 && block_sums) block_sums[blockIdx.x] = before + x;
}

// Adds each block's scanned offset to its 1024 elements.
extern "C" __global__ void kantele_scan_add(u32* out, u32 n, const u32* block_offsets) {
    u32 i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) out[i] += block_offsets[blockIdx.x];
}
