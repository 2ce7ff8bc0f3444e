// Dispatch for the batched shadow tests (Highway skeleton layout); their scalar references are
// LightShadows::classify and hidden (core/surface.h), and a scene with a mesh takes them.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "shadow_batch.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "shadow_batch-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <algorithm>
#include <cmath>

namespace haze::analytic {

HWY_EXPORT(ClassifyStretches);
HWY_EXPORT(LightVisible);

void classify_stretches(const LightShadows& shadows, const ShadowRays& rays, float* stretch) {
  if (!shadows.meshes()) return HWY_DYNAMIC_DISPATCH(ClassifyStretches)(shadows, rays, stretch);
  for (size_t i = 0; i < rays.count; ++i) {
    const Ray ray{Vec3(rays.o[0][i], rays.o[1][i], rays.o[2][i]), Vec3(rays.d[0][i], rays.d[1][i], rays.d[2][i])};
    stretch[i] = static_cast<float>(static_cast<int>(shadows.classify(ray, rays.t0[i], rays.t1[i])));
  }
}

void light_visible(const LightShadows& shadows, const double* const x[3], size_t count, const Surface* self, float* visible) {
  if (!shadows.meshes()) return HWY_DYNAMIC_DISPATCH(LightVisible)(shadows, x, count, self, visible);
  for (size_t i = 0; i < count; ++i) visible[i] = shadows.hidden(Vec3(x[0][i], x[1][i], x[2][i]), self) ? 0.0f : 1.0f;
}

namespace {

// The roots of a t^2 + b t + c = 0 (a may be 0) that keep(t) takes, appended.
template <class Keep>
void add_roots(double a, double b, double c, const Keep& keep, std::vector<double>& out) {
  if (std::abs(a) < 1e-300) {
    if (b != 0.0 && keep(-c / b)) out.push_back(-c / b);
    return;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  if (keep(q / a)) out.push_back(q / a);
  if (q != 0.0 && keep(c / q)) out.push_back(c / q);
}

}  // namespace

void lit_pieces(const LightShadows& shadows, const Ray& ray, double t0, double t1, std::vector<std::pair<double, double>>& out) {
  if (!(t1 > t0)) return;
  thread_local std::vector<double> kept;
  std::vector<double>& cuts = kept;
  cuts.clear();
  const Vec3 &o = ray.origin, &d = ray.direction, w = o - shadows.light();
  const auto inside = [&](double t) { return t > t0 && t < t1; };
  for (const LightShadows::Face& p : shadows.planes()) add_roots(0.0, glm::dot(d, p.normal), glm::dot(o - p.point, p.normal), inside, cuts);
  const double dd = glm::dot(d, d);
  for (const LightShadows::Cone& s : shadows.spheres()) {
    const Vec3 oc = o - s.center;
    add_roots(dd, 2.0 * glm::dot(oc, d), glm::dot(oc, oc) - s.r2, inside, cuts);
    if (s.cos2 == 0.0) continue;
    const double dv = glm::dot(d, s.axis), wv = glm::dot(w, s.axis), circle = std::sqrt(s.r2 / (1.0 - s.cos2)) * s.cos2;
    add_roots(dv * dv - s.cos2 * dd, 2.0 * (wv * dv - s.cos2 * glm::dot(w, d)), wv * wv - s.cos2 * glm::dot(w, w),
              [&](double t) { return inside(t) && wv + t * dv > circle; }, cuts);
  }
  cuts.push_back(t0), cuts.push_back(t1);
  std::sort(cuts.begin(), cuts.end());
  double start = t0;
  bool open = false;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (!(b > a)) continue;
    const bool lit = !shadows.hidden(ray.at(std::isfinite(b) ? 0.5 * (a + b) : a + 1.0 + std::abs(a)));
    if (lit && !open) start = a, open = true;
    if (!lit && open) out.emplace_back(start, a), open = false;
  }
  if (open) out.emplace_back(start, t1);
}

}  // namespace haze::analytic
#endif  // HWY_ONCE
