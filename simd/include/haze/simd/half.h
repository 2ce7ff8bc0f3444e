// float32 <-> float16 (IEEE binary16) conversion of arrays, with Highway runtime dispatch: the
// storage format of the discrete-ordinate solver's float16 option (grids/dom.h, DomStorage).
// ISA-free header: per-target code in src/half-inl.h.
//
// AVX2 and AVX3 convert with F16C and SSE4 and SSSE3 with Eigen's scalar code, both rounding to
// nearest even (Highway 1.0.3's emulation for x86 without F16C flushes some subnormals to zero);
// the scalar target uses Highway's emulation, which truncates the mantissa. So the error is below
// 2^-10 relative for normal values (|x| in [6.1e-5, 65504]) and 2^-23 (1.2e-7) absolute for
// subnormal ones; -0 may become +0.
// Values above 65504 are not representable: callers scale their data into range first.
#pragma once

#include <Eigen/Core>

#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::simd {

using Half = Eigen::half;  // 2 bytes, IEEE binary16

void to_half(const float* from, Half* to, size_t count);
void to_float(const Half* from, float* to, size_t count);
// The scalar references: Eigen's conversions (round to nearest even).
void to_half_reference(const float* from, Half* to, size_t count);
void to_float_reference(const Half* from, float* to, size_t count);

}  // namespace haze::simd

#pragma GCC visibility pop
