// Optical-depth error of seed 003's gathering (`paper`) and the short-characteristics sweep
// against the exact DDA, for docs/PROPAGATION.md: relative error per cell (mean, 95th percentile,
// max) over cells whose exact depth is at least 0.1, and the mean error over the mean depth, in a
// homogeneous and a heterogeneous 64^3 medium, lights inside and outside and directional.
// Not a Google Benchmark: it measures error, not speed. Run: build/release/bench/haze_propagation_accuracy
#include <haze/grids/optical_depth.h>
#include <haze/core/stopwatch.h>
#include <haze/grids/rbf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenes/lumpy_cloud.h"

using namespace haze;
using namespace haze::grids;

namespace {

DenseGrid medium(int n, bool heterogeneous) {
  if (heterogeneous) return lumpy_cloud(n);
  DenseGrid g({n, n, n}, {Vec3(-1), Vec3(1)});
  std::fill(g.values().begin(), g.values().end(), 1.0f);
  return g;
}

struct Row {
  double mean, p95, max, mean_abs_over_mean, seconds;
};

Row measure(const DenseGrid& density, const Light& light, const DepthOptions& options, const DenseGrid& exact) {
  Stopwatch start;
  DenseGrid approx = optical_depth(density, light, options);
  double seconds = start.seconds();
  std::vector<double> rel;
  double sum_abs = 0.0, sum = 0.0;
  for (size_t c = 0; c < exact.values().size(); ++c) {
    double e = exact.values()[c], err = std::abs(static_cast<double>(approx.values()[c]) - e);
    sum_abs += err, sum += e;
    if (e >= 0.1) rel.push_back(err / e);
  }
  std::sort(rel.begin(), rel.end());
  double mean = 0.0;
  for (double r : rel) mean += r;
  return {mean / static_cast<double>(rel.size()), rel[rel.size() * 95 / 100], rel.back(), sum_abs / sum, seconds};
}

}  // namespace

int main() {
  const int n = 64;
  struct NamedLight {
    const char* name;
    Light light;
  };
  const NamedLight lights[] = {{"point inside", PointLight{Vec3(0.05, 0.1, -0.02)}},
                               {"point outside", PointLight{Vec3(1.8, 1.1, 0.6)}},
                               {"directional", DirectionalLight{glm::normalize(Vec3(0.4, -1.0, 0.3))}}};
  std::printf("| medium | light | scheme | mean | 95th pct | max | mean abs / mean depth | seconds (2 threads) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (bool heterogeneous : {false, true}) {
    const DenseGrid density = medium(n, heterogeneous);
    for (const auto& [light_name, light] : lights) {
      Stopwatch start;
      const DenseGrid exact = optical_depth(density, light, {DepthScheme::exact});
      double exact_seconds = start.seconds();
      struct Config {
        const char* label;
        DepthOptions options;
      };
      const Config configs[] = {{"paper", {DepthScheme::paper, 1, 0}},
                                {"sweep, 1 layer", {DepthScheme::sweep, 1, 0}},
                                {"sweep, 4 layers (default)", {DepthScheme::sweep, 4, 0}},
                                {"sweep, 8 layers", {DepthScheme::sweep, 8, 0}}};
      for (const auto& [label, options] : configs) {
        Row r = measure(density, light, options, exact);
        std::printf("| %s | %s | %s | %.2e | %.2e | %.2e | %.2e | %.3f |\n", heterogeneous ? "heterogeneous" : "homogeneous", light_name,
                    label, r.mean, r.p95, r.max, r.mean_abs_over_mean, r.seconds);
      }
      std::printf("| %s | %s | exact (DDA) | 0 | 0 | 0 | 0 | %.3f |\n", heterogeneous ? "heterogeneous" : "homogeneous", light_name, exact_seconds);
    }
  }
}
