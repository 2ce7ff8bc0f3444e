// Deep shadow maps of the particles' continuous density (light_depth.h).
#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/particles/light_depth.h>

#include "erf_table.h"

#include <algorithm>
#include <cmath>

namespace haze::particles {

namespace {
constexpr double kMaxValues = 16e6;        // floats per map (64 MB): texels are widened beyond it

// The depth nodes s0 + k ds, k < count, within `reach` of depth t: [first, past the last).
std::pair<size_t, size_t> nodes_within(double t, double reach, double s0, double ds, size_t count) {
  const double first = std::max(0.0, std::ceil((t - reach - s0) / ds));
  const double last = std::min(static_cast<double>(count) - 1.0, std::floor((t + reach - s0) / ds));
  return {static_cast<size_t>(first), static_cast<size_t>(std::max(0.0, last + 1.0))};
}

// One Gaussian on the texel ray whose nodes start at depth[base]: nodes [k0, k1) take amplitude
// times node(k), the nodes past them its whole integral, amplitude (1 + before): into `tail` at
// the first of them (the running sum carries it on), else into each.
template <class Node>
void add_gaussian(float* depth, size_t base, size_t k0, size_t k1, size_t count, double amplitude, double before, const Node& node, float* tail) {
  for (size_t k = k0; k < k1; ++k) depth[base + k] += static_cast<float>(amplitude * node(k));
  const auto whole = static_cast<float>(amplitude * (1.0 + before));
  const size_t after = std::max(k0, k1);
  if (tail) {
    if (after < count) tail[base + after] += whole;
  } else {
    for (size_t k = after; k < count; ++k) depth[base + k] += whole;
  }
}

}  // namespace

LightDepthMap::LightDepthMap(const ParticleField& field, const Light& light, int threads) : light_(light) {
  if (std::holds_alternative<SkyLight>(light)) throw Error("light", "sky", "a point, spot or directional light for a depth map");
  // The sphere holding every particle's support.
  const Vec3 centre = field.centre();
  const double mean_h = field.size() ? field.mean_h() : 1.0;
  const double radius = std::max(field.radius() + kCut * field.max_h(), 1e-9);
  double spacing = 0.5 * mean_h;
  int face_count = 1;
  double width = 2.0 * radius;  // the window's width where texels are `spacing` wide
  if (const auto* d = std::get_if<DirectionalLight>(&light)) {
    directional_ = true;
    origin_ = centre, extent_ = radius;
    faces_.resize(1);
    faces_[0].axis = glm::normalize(d->direction);
    s0_ = 0.0;
  } else {
    origin_ = std::holds_alternative<PointLight>(light) ? std::get<PointLight>(light).position : std::get<SpotLight>(light).position;
    const double distance = glm::length(centre - origin_);
    if (distance > 1.01 * radius) {  // outside: one face looking at the support
      faces_.resize(1);
      faces_[0].axis = (centre - origin_) / distance;
      extent_ = radius / std::sqrt(distance * distance - radius * radius);
      width = 2.0 * distance * extent_;
      s0_ = distance - radius;
    } else {  // inside: a cube map
      face_count = 6;
      faces_.resize(6);
      for (int a = 0; a < 3; ++a)
        for (int sign = 0; sign < 2; ++sign) {
          Vec3 axis(0.0);
          axis[a] = sign ? -1.0 : 1.0;
          faces_[static_cast<size_t>(2 * a + sign)].axis = axis;
        }
      extent_ = 1.0;
      width = 2.0 * radius;
      s0_ = 0.0;
    }
  }
  const double depth_range = directional_ || face_count == 1 ? 2.0 * radius : glm::length(centre - origin_) + radius;
  for (;;) {
    resolution_ = std::clamp(static_cast<int>(std::ceil(width / spacing)), 2, 1024);
    nodes_ = std::clamp(static_cast<int>(std::ceil(depth_range / spacing)) + 1, 2, 4096);
    if (static_cast<double>(resolution_) * resolution_ * nodes_ * face_count <= kMaxValues) break;
    spacing *= 1.25;
  }
  ds_ = depth_range / (nodes_ - 1);
  centre_ = centre, radius_ = radius;
  std::vector<Gaussian> gaussians(field.size());
  for (size_t p = 0; p < field.size(); ++p) gaussians[p] = {field.position(p), field.h(p), field.weight(p)};
  for (Face& f : faces_) {
    const Frame frame = Frame::from_z(f.axis);
    f.t1 = frame.s, f.t2 = frame.t;
    f.depth.assign(static_cast<size_t>(resolution_) * static_cast<size_t>(resolution_) * static_cast<size_t>(nodes_), 0.0f);
    splat(f, gaussians, true, threads);
  }
}

bool LightDepthMap::update(std::span<const Gaussian> before, std::span<const Gaussian> after, int threads) {
  if (before.size() != after.size()) throw Error("after", to_text(after.size()) + " Gaussians", "one for each of the " + to_text(before.size()) + " before");
  for (const Gaussian& g : after)
    if (glm::length(g.x - centre_) + kCut * g.h > radius_) return false;
  std::vector<Gaussian> change;
  change.reserve(2 * before.size());
  for (const Gaussian& g : before) change.push_back({g.x, g.h, -g.w});
  change.insert(change.end(), after.begin(), after.end());
  for (Face& f : faces_) {
    f.touched.assign(static_cast<size_t>(resolution_) * static_cast<size_t>(resolution_), 0);
    splat(f, change, false, threads);
  }
  return true;
}

bool LightDepthMap::touched(const Vec3& x) const {
  double u, v, s;
  const int face = locate(x, u, v, s);
  if (face < 0 || !(u > -1.0 && u < resolution_ && v > -1.0 && v < resolution_)) return false;
  const auto& touched = faces_[static_cast<size_t>(face)].touched;
  if (touched.empty()) return false;
  const int m = resolution_;
  const int i = std::min(static_cast<int>(std::clamp(u, 0.0, m - 1.0)), m - 2), j = std::min(static_cast<int>(std::clamp(v, 0.0, m - 1.0)), m - 2);
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di)
      if (touched[static_cast<size_t>(j + dj) * static_cast<size_t>(m) + static_cast<size_t>(i + di)]) return true;
  return false;
}

size_t LightDepthMap::bytes() const {
  size_t b = 0;
  for (const Face& f : faces_) b += f.depth.size() * sizeof(float);
  return b;
}

void LightDepthMap::texel_ray(const Face& f, int i, int j, Vec3& o, Vec3& d) const {
  const double a = ((i + 0.5) / resolution_ * 2.0 - 1.0) * extent_, b = ((j + 0.5) / resolution_ * 2.0 - 1.0) * extent_;
  if (directional_) {
    o = origin_ + a * f.t1 + b * f.t2 - extent_ * f.axis;
    d = f.axis;
  } else {
    o = origin_;
    d = glm::normalize(f.axis + a * f.t1 + b * f.t2);
  }
}

int LightDepthMap::locate(const Vec3& x, double& u, double& v, double& s) const {
  const Vec3 local = x - origin_;
  int face = 0;
  if (faces_.size() == 6) {
    const Vec3 m = glm::abs(local);
    const int a = m.x >= m.y && m.x >= m.z ? 0 : (m.y >= m.z ? 1 : 2);
    face = 2 * a + (local[a] < 0.0 ? 1 : 0);
  }
  const Face& f = faces_[static_cast<size_t>(face)];
  double a, b;
  if (directional_) {
    a = glm::dot(local, f.t1), b = glm::dot(local, f.t2);
    s = glm::dot(local, f.axis) + extent_;
  } else {
    const double z = glm::dot(local, f.axis);
    if (!(z > 0.0)) return -1;
    a = glm::dot(local, f.t1) / z, b = glm::dot(local, f.t2) / z;
    s = glm::length(local);
  }
  u = (a / extent_ + 1.0) * 0.5 * resolution_ - 0.5;
  v = (b / extent_ + 1.0) * 0.5 * resolution_ - 0.5;
  return face;
}

double LightDepthMap::depth(const Vec3& x) const {
  double u, v, s;
  const int face = locate(x, u, v, s);
  if (face < 0 || !(u > -1.0 && u < resolution_ && v > -1.0 && v < resolution_)) return 0.0;
  const double k = (s - s0_) / ds_;
  if (!(k > 0.0)) return 0.0;
  const auto& depth = faces_[static_cast<size_t>(face)].depth;
  const int m = resolution_;
  const double uc = std::clamp(u, 0.0, m - 1.0), vc = std::clamp(v, 0.0, m - 1.0), kc = std::min(k, nodes_ - 1.0);
  const int i = std::min(static_cast<int>(uc), m - 2), j = std::min(static_cast<int>(vc), m - 2), n = std::min(static_cast<int>(kc), nodes_ - 2);
  const double fu = uc - i, fv = vc - j, fk = kc - n;
  double sum = 0.0;
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const size_t at = (static_cast<size_t>(j + dj) * static_cast<size_t>(m) + static_cast<size_t>(i + di)) * static_cast<size_t>(nodes_) + static_cast<size_t>(n);
      const double along = (1.0 - fk) * static_cast<double>(depth[at]) + fk * static_cast<double>(depth[at + 1]);
      sum += (di ? fu : 1.0 - fu) * (dj ? fv : 1.0 - fv) * along;
    }
  return sum;
}

bool LightDepthMap::arrival(const Vec3& x, const Rgb& sigma_t, double nearest, LightArrival& out) const {
  if (!haze::arrival(light_, x, out)) return false;
  if (std::isfinite(out.distance) && out.distance < nearest) out.irradiance *= (out.distance / nearest) * (out.distance / nearest);
  out.irradiance *= glm::exp(-sigma_t * depth(x));
  return true;
}

// splat() for a directional light's parallel texel rays: the particle's depth t along them is the
// same for every texel, so the depth nodes' erf terms are taken once, and exp(-perp^2 / h^2) is the
// product of one factor per texel column and one per row.
void LightDepthMap::splat_parallel(Face& f, const Vec3& x, double h, double w, int i0, int i1, int j0, int j1, float* tail) const {
  const Vec3 local = x - origin_;
  const double t = glm::dot(local, f.axis) + extent_, a = glm::dot(local, f.t1), b = glm::dot(local, f.t2);
  if (t < -kCut * h || i0 > i1 || j0 > j1) return;
  const ErfTable& erf = ErfTable::instance();
  const auto k_count = static_cast<size_t>(nodes_);
  const std::pair<size_t, size_t> range = nodes_within(t, kCut * h, s0_, ds_, k_count);
  const size_t k0 = range.first, k1 = range.second;
  const double before = erf(t / h);
  // Per texel column u and row v (over h): u^2 and exp(-u^2), v^2 and exp(-v^2).
  struct Axis {
    double square, factor;
  };
  thread_local std::vector<float> kept_nodes;
  thread_local std::vector<Axis> kept_columns, kept_rows;
  std::vector<float>& nodes = kept_nodes;
  std::vector<Axis>& column = kept_columns;
  std::vector<Axis>& row = kept_rows;
  nodes.clear(), column.clear(), row.clear();
  for (size_t k = k0; k < k1; ++k) nodes.push_back(static_cast<float>(erf((s0_ + static_cast<double>(k) * ds_ - t) / h) + before));
  const double texel = 2.0 * extent_ / resolution_;
  const auto axis = [&](int i, double centre) {
    const double u = (-extent_ + (i + 0.5) * texel - centre) / h;
    return Axis{u * u, std::exp(-u * u)};
  };
  for (int i = i0; i <= i1; ++i) column.push_back(axis(i, a));
  for (int j = j0; j <= j1; ++j) row.push_back(axis(j, b));
  const double scale = w * h * 0.5 * std::sqrt(kPi);
  const auto m = static_cast<size_t>(resolution_);
  for (int j = j0; j <= j1; ++j) {
    const Axis v = row[static_cast<size_t>(j - j0)];
    for (int i = i0; i <= i1; ++i) {
      const Axis u = column[static_cast<size_t>(i - i0)];
      if (u.square + v.square >= kCut * kCut) continue;
      const size_t texel_index = static_cast<size_t>(j) * m + static_cast<size_t>(i);
      // add_gaussian in float32 over the nodes the particle spans (a loop the compiler vectorizes).
      const double amplitude = scale * u.factor * v.factor;
      float* const depth = f.depth.data() + texel_index * k_count;
      const auto a = static_cast<float>(amplitude);
      for (size_t k = 0; k < nodes.size(); ++k) depth[k0 + k] += a * nodes[k];
      const auto whole = static_cast<float>(amplitude * (1.0 + before));
      const size_t after = std::max(k0, k1);
      if (tail) {
        if (after < k_count) tail[texel_index * k_count + after] += whole;
      } else {
        for (size_t k = after; k < k_count; ++k) depth[k] += whole;
      }
      if (!tail) f.touched[texel_index] = 1;
    }
  }
}

// Each particle adds, to every texel ray passing within 3 h of it, the integral of its Gaussian
// from the ray's origin to each depth node: A (erf((s_k - t) / h) + erf(t / h)) with t the
// particle's depth along the ray and A = w_p exp(-perp^2 / h^2) h sqrt(pi) / 2. Nodes past t + 3 h
// take the whole A (1 + erf(t / h)) through a running sum. Threaded over bands of texel rows.
void LightDepthMap::splat(Face& f, std::span<const Gaussian> gaussians, bool running, int threads) {
  const int m = resolution_;
  const auto k_count = static_cast<size_t>(nodes_);
  std::vector<float> tail(running ? f.depth.size() : 0, 0.0f);
  // Each particle's footprint in texels, [i0, i1] x [j0, j1]; i0 > i1 when it misses the face.
  struct Footprint {
    int i0, i1, j0, j1;
  };
  std::vector<Footprint> footprint(gaussians.size());
  const double texel = 2.0 * extent_ / m;  // in the face's image-plane units
  const auto texels = [&](double a0, double a1, int& lo, int& hi) {
    lo = static_cast<int>(std::floor((a0 + extent_) / texel - 0.5)), hi = static_cast<int>(std::ceil((a1 + extent_) / texel - 0.5));
  };
  for (size_t p = 0; p < gaussians.size(); ++p) {
    const double reach = kCut * gaussians[p].h;
    Footprint& fp = footprint[p];
    fp = {0, m - 1, 0, m - 1};
    const Vec3 local = gaussians[p].x - origin_;
    if (directional_) {
      const double a = glm::dot(local, f.t1), b = glm::dot(local, f.t2);
      texels(a - reach, a + reach, fp.i0, fp.i1);
      texels(b - reach, b + reach, fp.j0, fp.j1);
    } else {
      const double z = glm::dot(local, f.axis);
      if (z < -reach) {
        fp = {1, 0, 1, 0};
        continue;
      }
      if (z > reach) {  // the box around the sphere, projected: X / Z over its corners bounds the footprint
        const auto range = [&](double c, int& lo, int& hi) {
          texels(std::min((c - reach) / (z - reach), (c - reach) / (z + reach)), std::max((c + reach) / (z - reach), (c + reach) / (z + reach)), lo, hi);
        };
        range(glm::dot(local, f.t1), fp.i0, fp.i1);
        range(glm::dot(local, f.t2), fp.j0, fp.j1);
      }
    }
    fp.i0 = std::max(fp.i0, 0), fp.i1 = std::min(fp.i1, m - 1), fp.j0 = std::max(fp.j0, 0), fp.j1 = std::min(fp.j1, m - 1);
  }
  const double sqrt_pi = std::sqrt(kPi);
  const ErfTable& erf = ErfTable::instance();
  parallel_for(m, threads, 2, [&](long long r0, long long r1) {
    for (size_t p = 0; p < gaussians.size(); ++p) {
      const Footprint& fp = footprint[p];
      if (fp.i0 > fp.i1 || fp.j1 < r0 || fp.j0 >= r1) continue;
      const auto [x, h, w] = gaussians[p];
      const int j_lo = std::max(fp.j0, static_cast<int>(r0)), j_hi = std::min(fp.j1, static_cast<int>(r1) - 1);
      if (directional_) {
        splat_parallel(f, x, h, w, fp.i0, fp.i1, j_lo, j_hi, running ? tail.data() : nullptr);
        continue;
      }
      for (int j = j_lo; j <= j_hi; ++j)
        for (int i = fp.i0; i <= fp.i1; ++i) {
          Vec3 o, d;
          texel_ray(f, i, j, o, d);
          const Vec3 to = x - o;
          const double t = glm::dot(to, d), perp2 = glm::dot(to, to) - t * t;
          if (perp2 >= kCut * kCut * h * h || t < -kCut * h) continue;
          const double amplitude = w * std::exp(-perp2 / (h * h)) * h * 0.5 * sqrt_pi, before = erf(t / h);
          const size_t texel_index = static_cast<size_t>(j) * static_cast<size_t>(m) + static_cast<size_t>(i);
          const auto [k0, k1] = nodes_within(t, kCut * h, s0_, ds_, k_count);
          const double width = h;  // a plain variable: lambdas capture no structured bindings (clang)
          add_gaussian(f.depth.data(), texel_index * k_count, k0, k1, k_count, amplitude, before,
                       [&](size_t k) { return erf((s0_ + static_cast<double>(k) * ds_ - t) / width) + before; }, running ? tail.data() : nullptr);
          if (!running) f.touched[texel_index] = 1;
        }
    }
  });
  if (!running) return;
  parallel_for(static_cast<long long>(m) * m, threads, 64, [&](long long t0, long long t1) {
    for (auto t = static_cast<size_t>(t0); t < static_cast<size_t>(t1); ++t) {
      float run = 0.0f;
      for (size_t k = 0; k < k_count; ++k) {
        run += tail[t * k_count + k];
        f.depth[t * k_count + k] += run;
      }
    }
  });
}

}  // namespace haze::particles
