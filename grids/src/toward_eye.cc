// march_toward_eye (haze/grids/march_rays.h): dispatch over planes of cells, and its float64
// reference.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "toward_eye.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "toward_eye-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/core/error.h>
#include <haze/core/progress.h>

#include <cmath>
#include <vector>

namespace haze::grids {

HWY_EXPORT(TowardEye);

namespace {

void check(const MarchLight* lights, int count) {
  for (int l = 0; l < count; ++l)
    if (lights[l].type == MarchLight::spot) throw Error("lights[" + std::to_string(l) + "].type", "spot", "point or directional lights (a spot's cone edge stays in the march)");
}

}  // namespace

void march_toward_eye(const MarchVolume& v, const PhaseFunction& phase, const float eye[3], const MarchLight* lights, int count, uint32_t* out,
                      int threads) {
  simd::PhaseParams p;
  if (!simd::params_for(phase, p)) throw Error("phase", phase.name(), "an analytic phase function for the SIMD marcher");
  check(lights, count);
  // The ghosted grid's rows (n + 2 cells), a pad to each side and a vector (of any target, 256
  // bytes at most) past the end.
  const size_t row_stride = static_cast<size_t>(v.n[0]) + 4 + 64;
  const size_t window = (3 * static_cast<size_t>(v.n[1] + 2) * static_cast<size_t>(v.channels) + 1) * row_stride;
  // Chunks of planes, each recomputing one raw plane to either side; enough of them for the threads.
  const long long grain = std::max(2, (v.n[2] + 2) / (4 * std::max(threads, 1)));
  parallel_for(v.n[2] + 2, threads, grain, [&](long long z0, long long z1) {
    thread_local std::vector<float> kept;  // this worker's, frame after frame
    std::vector<float>& raw = kept;
    if (raw.size() < window) raw.resize(window);
    HWY_DYNAMIC_DISPATCH(TowardEye)(v, p, eye, lights, count, static_cast<int>(z0), static_cast<int>(z1), out, raw.data(), row_stride);
  });
}

void march_toward_eye_reference(const MarchVolume& v, const PhaseFunction& phase, const double eye[3], const MarchLight* lights, int count,
                                std::vector<double>& out) {
  check(lights, count);
  const int nx = v.n[0] + 2, ny = v.n[1] + 2, nz = v.n[2] + 2, channels = v.channels;  // the ghosted grid
  const size_t cells = static_cast<size_t>(nx) * static_cast<size_t>(ny) * static_cast<size_t>(nz);
  const int stride = v.depth_stride > 0 ? v.depth_stride : v.light_count;
  std::vector<double> raw(cells * static_cast<size_t>(channels), 0.0);
  const auto index = [&](int x, int y, int z) { return (static_cast<size_t>(z) * static_cast<size_t>(ny) + static_cast<size_t>(y)) * static_cast<size_t>(nx) + static_cast<size_t>(x); };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        // Ghosted cell (x, y, z) is the volume's (x - 1, y - 1, z - 1); its depths the nearest cell's.
        const auto at_centre = [&](int e, int i) { return static_cast<double>(v.lo[e]) + (i - 0.5) * static_cast<double>(v.h[e]); };
        const Vec3 p(at_centre(0, x), at_centre(1, y), at_centre(2, z));
        const auto clamped = [&](int i, int e) { return static_cast<size_t>(std::clamp(i - 1, 0, v.n[e] - 1)); };
        const size_t cell = (clamped(z, 2) * static_cast<size_t>(v.n[1]) + clamped(y, 1)) * static_cast<size_t>(v.n[0]) + clamped(x, 0);
        const Vec3 w = glm::normalize(p - Vec3(eye[0], eye[1], eye[2]));
        for (int l = 0; l < count; ++l) {
          const MarchLight& light = lights[l];
          Vec3 to(static_cast<double>(light.to_light[0]), static_cast<double>(light.to_light[1]), static_cast<double>(light.to_light[2]));
          double falloff = 1.0;
          if (light.type != MarchLight::directional) {
            to = Vec3(static_cast<double>(light.position[0]), static_cast<double>(light.position[1]), static_cast<double>(light.position[2])) - p;
            falloff = 1.0 / glm::dot(to, to), to = glm::normalize(to);
          }
          const size_t at = cell * static_cast<size_t>(stride) + static_cast<size_t>(light.slot);
          if (v.visibility) falloff *= static_cast<double>(v.visibility[at]);
          const double depth = std::max(0.0, static_cast<double>(v.depths[at])), weight = phase.eval(glm::dot(to, w)) * falloff;
          for (int c = 0; c < channels; ++c)
            raw[static_cast<size_t>(c) * cells + index(x, y, z)] +=
                weight * static_cast<double>(light.intensity[c]) * std::exp(-static_cast<double>(v.sigma_t[c]) * static_cast<double>(v.depth_scale[c]) * depth);
        }
      }
  const size_t floats = static_cast<size_t>(channels) + 1;  // a cell's: the channels, then the density
  out.assign(cells * floats, 0.0);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        const size_t i = index(x, y, z);
        for (int c = 0; c < channels; ++c) {
          const double* f = raw.data() + static_cast<size_t>(c) * cells;
          double second = 0.0;
          if (x > 0 && x + 1 < nx) second += f[index(x - 1, y, z)] + f[index(x + 1, y, z)] - 2.0 * f[i];
          if (y > 0 && y + 1 < ny) second += f[index(x, y - 1, z)] + f[index(x, y + 1, z)] - 2.0 * f[i];
          if (z > 0 && z + 1 < nz) second += f[index(x, y, z - 1)] + f[index(x, y, z + 1)] - 2.0 * f[i];
          out[i * floats + static_cast<size_t>(c)] = std::max(0.0, f[i] - second / 12.0);
        }
        const auto clamped = [&](int j, int e) { return std::clamp(j - 1, 0, v.n[e] - 1); };
        const size_t cell = (static_cast<size_t>(clamped(z, 2)) * static_cast<size_t>(v.n[1]) + static_cast<size_t>(clamped(y, 1))) * static_cast<size_t>(v.n[0]) +
                            static_cast<size_t>(clamped(x, 0));
        out[i * floats + static_cast<size_t>(channels)] = static_cast<double>(v.density[cell]);
      }
}

}  // namespace haze::grids
#endif  // HWY_ONCE
