// The moments' scattered light toward one eye per cell (dom_toward_eye.h).
#include "dom_toward_eye.h"

#include <haze/grids/eye_cells.h>

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

TowardEye::TowardEye(const DomSolution& solution)
    : solution_(solution), separable_(solution.separable), stride_((solution.terms() + 15) / 16 * 16) {
  const auto terms = static_cast<size_t>(solution.terms()), stride = static_cast<size_t>(stride_);
  table_.assign(static_cast<size_t>(kSide) * kSide * stride, 0.0f);
  Eigen::VectorXd row, c;
  for (int t = 0; t < kSide; ++t)
    for (int s = 0; s < kSide; ++s) {
      const Vec3 w = decode((s + 0.5) / kSide * 2.0 - 1.0, (t + 0.5) / kSide * 2.0 - 1.0);
      inscatter_weights(solution, -w, row, c);
      float* to = table_.data() + (static_cast<size_t>(t) * kSide + static_cast<size_t>(s)) * stride;
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
  const float scales[3] = {static_cast<float>(scale[0]), static_cast<float>(scale[1]), static_cast<float>(scale[2])};
  const auto planes = [&](long long z0, long long z1) {
    for (auto z = static_cast<int>(z0); z < z1; ++z)
      for (int y = 0; y < ny; ++y) {
        const size_t first = static_cast<size_t>(z) * plane + static_cast<size_t>(y) * static_cast<size_t>(nx);
        const float* moments[3];
        float* to[3];
        for (size_t ch = 0; ch < channels; ++ch) moments[ch] = solution_.moments[ch].data() + first * terms, to[ch] = out.data() + ch * cells + first;
        EyeCellsRow row;
        row.table = table_.data(), row.side = kSide, row.terms = static_cast<int>(terms), row.stride = stride_;
        row.moments = moments, row.readable = (cells - first) * terms, row.scale = scales, row.channels = static_cast<int>(channels);
        row.x0 = static_cast<float>(lo.x + 0.5 * h.x - eye.x), row.dx = static_cast<float>(h.x);
        row.dy = static_cast<float>(lo.y + (y + 0.5) * h.y - eye.y), row.dz = static_cast<float>(lo.z + (z + 0.5) * h.z - eye.z);
        row.count = nx, row.out = to;
        eye_cells_row(row);
      }
  };
  // A body of one reference: std::function keeps it without allocating.
  parallel_for(nz, threads, 1, [&planes](long long z0, long long z1) { planes(z0, z1); });
}

}  // namespace haze::grids::dom
