// Lets common.cuh compile as plain host C++ (g++/clang++ with -ffp-contract=off, SSE2 floats),
// so its device functions can be compared with the Rust core on machines without a GPU. Each
// CUDA intrinsic maps to the host operation with the same IEEE rounding: the `_rn` intrinsics
// are exactly the correctly rounded operations x86-64 does by default.
#pragma once
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <algorithm>

#define __device__
#define __host__
#define __global__
#define __forceinline__ inline
#define __noinline__

using std::isfinite;
using std::isnan;
using std::max;
using std::min;

struct float4 {
    float x, y, z, w;
};
struct uchar4 {
    unsigned char x, y, z, w;
};
inline float4 make_float4(float x, float y, float z, float w) { return {x, y, z, w}; }

inline float __fmul_rn(float a, float b) { return a * b; }
inline float __fadd_rn(float a, float b) { return a + b; }
inline float __fsub_rn(float a, float b) { return a - b; }
inline float __fdiv_rn(float a, float b) { return a / b; }
inline float __fsqrt_rn(float a) { return std::sqrt(a); }
inline float __ll2float_rn(long long v) { return (float)v; }
inline float __int2float_rn(int v) { return (float)v; }
inline float __int_as_float(unsigned int bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}
// PTX cvt.rzi.s32.f32: truncate, saturate, NaN → 0.
inline int __float2int_rz(float x) {
    if (std::isnan(x)) return 0;
    if (x >= 2147483648.0f) return INT_MAX;
    if (x <= -2147483648.0f) return INT_MIN;
    return (int)x;
}
