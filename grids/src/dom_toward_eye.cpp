// The moments' scattered light toward one eye per cell (dom_toward_eye.h).
#include "dom_toward_eye.h"

#include <haze/core/progress.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace haze::grids::dom {

namespace {

// The octahedral map's direction at (u, v) in [-1, 1]^2 (the lower hemisphere folded out; fill
// maps back).
Vec3 decode(double u, double v) {
  Vec3 w(u, v, 1.0 - std::abs(u) - std::abs(v));
  if (w.z < 0.0) w = Vec3((1.0 - std::abs(v)) * (u >= 0.0 ? 1.0 : -1.0), (1.0 - std::abs(u)) * (v >= 0.0 ? 1.0 : -1.0), w.z);
  return glm::normalize(w);
}

}  // namespace

TowardEye::TowardEye(const DomSolution& solution) : solution_(solution), separable_(solution.separable) {
  const auto terms = static_cast<size_t>(solution.terms());
  table_.resize(static_cast<size_t>(kSide) * kSide * terms);
  Eigen::VectorXd row, c;
  for (int t = 0; t < kSide; ++t)
    for (int s = 0; s < kSide; ++s) {
      const Vec3 w = decode((s + 0.5) / kSide * 2.0 - 1.0, (t + 0.5) / kSide * 2.0 - 1.0);
      inscatter_weights(solution, -w, row, c);
      float* to = table_.data() + (static_cast<size_t>(t) * kSide + static_cast<size_t>(s)) * terms;
      for (size_t k = 0; k < terms; ++k) to[k] = static_cast<float>(c(static_cast<Eigen::Index>(k)));
    }
}

void TowardEye::fill(const DenseGrid& density, const Vec3& eye, const Rgb& scale, std::vector<float>& out, int threads) const {
  const std::array<int, 3> n = density.resolution();
  const int nx = n[0], ny = n[1], nz = n[2];  // named, not bound: the lambda below takes them
  const auto terms = static_cast<size_t>(solution_.terms()), channels = static_cast<size_t>(solution_.channels);
  const size_t plane = static_cast<size_t>(nx) * static_cast<size_t>(ny);
  const size_t cells = plane * static_cast<size_t>(nz);
  out.resize(cells * channels);
  const Vec3 lo = density.bounds().lo, h = density.cell_size();
  const float half = 0.5f * kSide;
  const auto planes = [&](long long z0, long long z1) {
    std::array<float, 64> c;  // a cell's weights (terms <= 64: the caller's condition)
    for (auto z = static_cast<int>(z0); z < z1; ++z)
      for (int y = 0; y < ny; ++y) {
        // The cells' directions from the eye along the row, unnormalized: the map divides by |x| + |y| + |z|.
        const auto dy = static_cast<float>(lo.y + (y + 0.5) * h.y - eye.y), dz = static_cast<float>(lo.z + (z + 0.5) * h.z - eye.z);
        const auto ay = std::abs(dy), az = std::abs(dz);
        for (int x = 0; x < nx; ++x) {
          const auto dx = static_cast<float>(lo.x + (x + 0.5) * h.x - eye.x);
          const float n = std::abs(dx) + ay + az;
          float u = dx / n, v = dy / n;
          if (dz < 0.0f) {  // the lower hemisphere folded out
            const float fu = std::copysign(1.0f - std::abs(v), u), fv = std::copysign(1.0f - std::abs(u), v);
            u = fu, v = fv;
          }
          // Bilinear between texel centres, clamped at the map's edge.
          const float fs = std::clamp((u + 1.0f) * half - 0.5f, 0.0f, kSide - 1.0f), ft = std::clamp((v + 1.0f) * half - 0.5f, 0.0f, kSide - 1.0f);
          const int s0 = std::min(static_cast<int>(fs), kSide - 2), t0 = std::min(static_cast<int>(ft), kSide - 2);
          const float a = fs - static_cast<float>(s0), b = ft - static_cast<float>(t0);
          const float w00 = (1.0f - a) * (1.0f - b), w10 = a * (1.0f - b), w01 = (1.0f - a) * b, w11 = a * b;
          const float* p00 = table_.data() + (static_cast<size_t>(t0) * kSide + static_cast<size_t>(s0)) * terms;
          const float* p10 = p00 + terms;
          const float* p01 = p00 + static_cast<size_t>(kSide) * terms;
          const float* p11 = p01 + terms;
          for (size_t k = 0; k < terms; ++k) c[k] = w00 * p00[k] + w10 * p10[k] + w01 * p01[k] + w11 * p11[k];
          const size_t cell = static_cast<size_t>(z) * plane + static_cast<size_t>(y) * static_cast<size_t>(nx) + static_cast<size_t>(x);
          for (size_t ch = 0; ch < channels; ++ch) {
            const float* m = solution_.moments[ch].data() + cell * terms;
            float j = 0.0f;
            for (size_t k = 0; k < terms; ++k) j += c[k] * m[k];
            out[ch * cells + cell] = static_cast<float>(scale[static_cast<int>(ch)]) * std::max(0.0f, j);
          }
        }
      }
  };
  // A body of one reference: std::function keeps it without allocating.
  parallel_for(nz, threads, 1, [&planes](long long z0, long long z1) { planes(z0, z1); });
}

}  // namespace haze::grids::dom
