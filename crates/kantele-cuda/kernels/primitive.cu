// Primitive stage: per triangle slot (submission order: the draws in issue order, each draw's
// triangles in index order), assembly, the NaN check, trivial
// reject, near-plane / guard-band clipping, culling and fixed-point setup (`Frame::end`'s
// `run_geometry` → `DrawCall::assemble` / `emit`).
//
// A triangle that needs no clipping writes its setup into its own slot of `setups`; a clipped
// one allocates its fan (up to MAX_CLIPPED_VERTICES − 2 triangles) in the clipped-triangle area
// after the slots. That area may overflow: then the fan is dropped, the requested count still
// grows, and the host grows the area and redoes the frame. `slots[s]` says where slot s's
// setups are, so binning can walk them in submission order.
#include "common.cuh"

#define MAX_FAN (KANTELE_MAX_CLIPPED_VERTICES - 2)

// The issued draw whose slots hold `s` (issue entries are sorted by `slot_base`; a binary search
// for the last base ≤ s).
__device__ __forceinline__ DrawIssue issue_of_slot(const DrawIssue* issue, u32 count, u32 s) {
    u32 lo = 0, hi = count;
    while (hi - lo > 1) {
        u32 mid = (lo + hi) / 2;
        if (issue[mid].slot_base <= s) lo = mid; else hi = mid;
    }
    return issue[lo];
}

// Block-wide counters, added to the frame status once per block.
struct PrimitiveCounters {
    u32 in, invalid, rejected, clipped, culled, degenerate, emitted;
};

__device__ __forceinline__ void write_setup(TriangleSetup* setups, float* attrs, u32 index,
                                            const TriangleSetup& t, const float* va,
                                            const float* vb, const float* vc) {
    setups[index] = t;
    const bool swapped = (t.flags & KANTELE_TRIANGLE_SWAPPED) != 0;
    const float* order[3] = {va, swapped ? vc : vb, swapped ? vb : vc};
    float* out = attrs + (u64)index * 3 * NV;
    for (int v = 0; v < 3; ++v) {
        for (int k = 0; k < NV; ++k) out[v * NV + k] = order[v][k];
    }
}

extern "C" __global__ void kantele_primitive(FrameUniforms f, const DrawRecord* draws,
                                             const DrawIssue* issue, const u32* indices, const float4* pos_clip,
                                             const float* varyings, TriangleSetup* setups,
                                             float* setup_attrs, SlotInfo* slots, u64* status) {
    __shared__ PrimitiveCounters block;
    if (threadIdx.x == 0) block = {0, 0, 0, 0, 0, 0, 0};
    __syncthreads();
    u32 s = blockIdx.x * blockDim.x + threadIdx.x;
    PrimitiveCounters c = {0, 0, 0, 0, 0, 0, 0};
    if (s < f.slot_count) {
        SlotInfo info = {s, 0};
        const DrawIssue is = issue_of_slot(issue, f.draw_count, s);
        const u32 d = is.draw;
        const DrawRecord& draw = draws[d];
        const u32 t = s - is.slot_base;
        bool cull_back = !(draw.flags & KANTELE_DRAW_DOUBLE_SIDED);
        bool front_cw = (draw.flags & KANTELE_DRAW_FRONT_CW) != 0;
        c.in = 1;
        u32 ix[3];
        bool in_range = true;
        for (int k = 0; k < 3; ++k) {
            ix[k] = indices[draw.index_base + 3 * t + k];
            if (ix[k] >= draw.vertex_count) in_range = false;  // validated at load; never read past
        }
        V4 pos[3];
        bool finite = in_range;
        for (int k = 0; k < 3 && in_range; ++k) {
            float4 p = pos_clip[draw.shaded_base + ix[k]];
            pos[k] = {p.x, p.y, p.z, p.w};
            finite = finite && v4_finite(pos[k]);
        }
        if (!finite) {
            c.invalid = 1;
        } else {
            const float* vary[3];
            for (int k = 0; k < 3; ++k) vary[k] = varyings + (u64)(draw.shaded_base + ix[k]) * NV;
            int test = classify(pos, f.guard_kx, f.guard_ky);
            if (test == CLIP_REJECT) {
                c.rejected = 1;
            } else if (test == CLIP_ACCEPT) {
                TriangleSetup tri;
                int r = setup_triangle(f, pos, cull_back, front_cw, tri);
                if (r == SETUP_OK) {
                    tri.draw = d;
                    tri.primitive_id = t;
                    write_setup(setups, setup_attrs, s, tri, vary[0], vary[1], vary[2]);
                    info.count = 1;
                    c.emitted = 1;
                } else if (r == SETUP_CULLED) {
                    c.culled = 1;
                } else {
                    c.degenerate = 1;
                }
            } else {
                c.clipped = 1;
                ClipPolygon poly;
                poly.len = 3;
                for (int k = 0; k < 3; ++k) {
                    poly.v[k].pos = pos[k];
                    for (int j = 0; j < NV; ++j) poly.v[k].varyings[j] = vary[k][j];
                }
                clip_polygon(poly, f.guard_kx, f.guard_ky);
                bool ok = true;
                for (int k = 0; k < poly.len; ++k) ok = ok && v4_finite(poly.v[k].pos);
                if (!ok) {
                    c.invalid = 1;
                } else {
                    // Set up the fan first, then allocate exactly the surviving triangles.
                    TriangleSetup fan[MAX_FAN];
                    unsigned char fan_vertex[MAX_FAN];
                    u32 n = 0;
                    for (int k = 1; k + 1 < poly.len; ++k) {
                        V4 p[3] = {poly.v[0].pos, poly.v[k].pos, poly.v[k + 1].pos};
                        int r = setup_triangle(f, p, cull_back, front_cw, fan[n]);
                        if (r == SETUP_OK) {
                            fan[n].draw = d;
                            fan[n].primitive_id = t;
                            fan_vertex[n] = (unsigned char)k;
                            n += 1;
                        } else if (r == SETUP_CULLED) {
                            c.culled += 1;
                        } else {
                            c.degenerate += 1;
                        }
                    }
                    if (n > 0) {
                        u64 first = atomicAdd(&status[STATUS_CLIP_REQUESTED], (u64)n);
                        if (first + n <= (u64)f.clip_capacity) {
                            for (u32 i = 0; i < n; ++i) {
                                int k = fan_vertex[i];
                                write_setup(setups, setup_attrs, f.slot_count + (u32)first + i, fan[i],
                                            poly.v[0].varyings, poly.v[k].varyings,
                                            poly.v[k + 1].varyings);
                            }
                            info.first = f.slot_count + (u32)first;
                            info.count = n;
                            c.emitted = n;
                        }
                    }
                }
            }
        }
        slots[s] = info;
    }
    atomicAdd(&block.in, c.in);
    if (c.invalid) atomicAdd(&block.invalid, c.invalid);
    if (c.rejected) atomicAdd(&block.rejected, c.rejected);
    if (c.clipped) atomicAdd(&block.clipped, c.clipped);
    if (c.culled) atomicAdd(&block.culled, c.culled);
    if (c.degenerate) atomicAdd(&block.degenerate, c.degenerate);
    if (c.emitted) atomicAdd(&block.emitted, c.emitted);
    __syncthreads();
    if (threadIdx.x == 0) {
        atomicAdd(&status[STATUS_TRIANGLES_IN], (u64)block.in);
        atomicAdd(&status[STATUS_INVALID], (u64)block.invalid);
        atomicAdd(&status[STATUS_REJECTED], (u64)block.rejected);
        atomicAdd(&status[STATUS_CLIPPED], (u64)block.clipped);
        atomicAdd(&status[STATUS_CULLED], (u64)block.culled);
        atomicAdd(&status[STATUS_DEGENERATE], (u64)block.degenerate);
        atomicAdd(&status[STATUS_BINNED], (u64)block.emitted);
    }
}
