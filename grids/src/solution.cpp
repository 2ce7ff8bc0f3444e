// The grid methods' fields at world points (grids/solution.h).
#include <haze/grids/solution.h>

#include <haze/core/error.h>
#include <haze/core/grid_walk.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/rbf.h>

#include <algorithm>

namespace haze::grids {

namespace {

double sample(const DenseGrid& grid, const Vec3& x) {
  return TrilinearStencil(grid.bounds(), grid.resolution(), x).apply(grid.values().data());
}

// The N moments of one channel at x, trilinear.
Eigen::VectorXd moments_at(const DomSolution& s, int channel, const TrilinearStencil& stencil) {
  const auto n = static_cast<size_t>(s.terms());
  Eigen::VectorXd m = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  const float* moments = s.moments[static_cast<size_t>(channel)].data();
  for (int e = 0; e < 8; ++e)
    for (size_t k = 0; k < n; ++k) m(static_cast<Eigen::Index>(k)) += stencil.weight[e] * static_cast<double>(moments[stencil.offset[e] * n + k]);
  return m;
}

// sum_k c_k m_k(x) per channel (one channel when the solve was grey).
Rgb project(const DomSolution& s, const DenseGrid& grid, const Vec3& x, const Eigen::VectorXd& c) {
  if (!grid.bounds().contains(x)) return Rgb(0.0);
  const TrilinearStencil stencil(grid.bounds(), grid.resolution(), x);
  Rgb out(0.0);
  for (int ch = 0; ch < s.channels; ++ch) out[ch] = c.dot(moments_at(s, ch, stencil));
  return s.channels == 1 ? Rgb(out[0]) : out;
}

}  // namespace

std::string GridSolution::replace_volume(const Scene& scene, const SceneChange& change, const CellCount& cells, double cutoff, int threads) {
  const MediumDesc& next = *change.medium;
  const auto* old_rbf = std::get_if<RbfDensity>(&scene_.medium->density);
  const auto* rbf = std::get_if<RbfDensity>(&next.density);
  std::string redone = "extinction volume";
  if (old_rbf && rbf && change.region && medium_bounds(next) == medium_bounds(*scene_.medium) &&
      injection_cutoff(rbf->blobs, cutoff) == injection_cutoff(old_rbf->blobs, cutoff)) {
    const size_t injected = reinject_region(rbf->blobs, volume_.density, *change.region, injection_cutoff(rbf->blobs, cutoff), 8, threads);
    redone += ": " + to_text(injected) + " of " + to_text(volume_.density.cell_count()) + " cells re-injected";
  } else {
    volume_.density = make_extinction_volume(scene, cells, cutoff, threads).density;
  }
  volume_.sigma_t_scale = next.sigma_t, volume_.albedo = next.albedo, volume_.phase = next.phase;
  return redone;
}

void GridSolution::update_depths(const Scene& scene, bool all, const DepthOptions& depth, UpdateReport& report) {
  std::vector<const Light*> before;
  for (const Light& l : scene_.lights)
    if (!std::holds_alternative<SkyLight>(l)) before.push_back(&l);
  size_t d = 0;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    if (std::holds_alternative<SkyLight>(light)) continue;
    if (d == depths_.size()) depths_.emplace_back(volume_.density.resolution(), volume_.density.bounds());
    if (all || d >= before.size() || !(light == *before[d])) {
      depths_[d] = optical_depth(volume_.density, light, depth);
      report.redone.push_back("optical depth of lights[" + std::to_string(i) + "]");
    }
    ++d;
  }
  depths_.resize(d, DenseGrid(volume_.density.resolution(), volume_.density.bounds()));
}

size_t GridSolution::depth_index(size_t light) const {
  if (light >= scene_.lights.size()) throw Error("light", to_text(light), "an index into the " + to_text(scene_.lights.size()) + " lights");
  if (std::holds_alternative<SkyLight>(scene_.lights[light]))
    throw Error("light", to_text(light), "a point, spot or directional light (the sky has no transmittance volume)");
  size_t index = 0;
  for (size_t i = 0; i < light; ++i) index += std::holds_alternative<SkyLight>(scene_.lights[i]) ? 0 : 1;
  return index;
}

Rgb GridSolution::transmittance(size_t light, const Vec3& x) const {
  const DenseGrid& depth = depths_[depth_index(light)];
  LightArrival a;
  arrival(scene_.lights[light], x, a);
  double t0 = 0.0, t1 = a.distance;
  const Ray ray{x, a.to_light};
  if (!depth.bounds().clip(ray, t0, t1) || !(t1 > t0)) return Rgb(1.0);
  if (depth.bounds().contains(x)) return glm::exp(-volume_.sigma_t_scale * sample(depth, x));
  // From outside: the stored depth half a cell past the entry point (where trilinear no longer
  // clamps to the edge cells), plus that half cell's density by the midpoint rule.
  const Vec3 h = depth.cell_size();
  const double step = std::min(0.5 * std::min({h.x, h.y, h.z}), t1 - t0);
  const double tau = sample(depth, ray.at(t0 + step)) + step * sample(volume_.density, ray.at(t0 + 0.5 * step));
  return glm::exp(-volume_.sigma_t_scale * tau);
}

Rgb GridSolution::unscattered(size_t light, const Vec3& x, LightArrival& a) const {
  if (!arrival(scene_.lights[light], x, a)) return Rgb(0.0);
  if (a.distance > 0.0 && occluded(scene_.surfaces, x, a.to_light, a.distance)) return Rgb(0.0);
  return a.irradiance * transmittance(light, x);
}

Rgb GridSolution::fluence(const Vec3& x) const {
  Rgb phi(0.0);
  LightArrival a;
  for (size_t l = 0; l < scene_.lights.size(); ++l)
    if (!std::holds_alternative<SkyLight>(scene_.lights[l])) phi += unscattered(l, x, a);
  if (const DomSolution* s = dom()) {
    Eigen::VectorXd w(s->directions->size());
    for (int d = 0; d < s->directions->size(); ++d) w(d) = s->directions->weight(d);
    phi += project(*s, volume_.density, x, s->separable->basis().transpose() * w);
  }
  return phi;
}

Rgb GridSolution::inscattered(const Vec3& x, const Vec3& w) const {
  Rgb source(0.0);
  LightArrival a;
  for (size_t l = 0; l < scene_.lights.size(); ++l) {
    if (std::holds_alternative<SkyLight>(scene_.lights[l])) continue;
    const Rgb e = unscattered(l, x, a);
    if (e != Rgb(0.0)) source += volume_.phase.eval(-a.to_light, w) * e;
  }
  if (const DomSolution* s = dom()) source += (1.0 - s->delta_m_fraction) * project(*s, volume_.density, x, inscatter_weights(*s, w));
  return source;
}

}  // namespace haze::grids
