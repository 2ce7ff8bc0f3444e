#include <haze/core/surface.h>

#include <algorithm>
#include <cmath>

namespace haze {

bool Surface::intersect(const Ray& ray, double t_min, double t_max, double& t, Vec3& normal) const {
  if (auto* plane = std::get_if<Plane>(&shape)) {
    double denom = glm::dot(plane->normal, ray.direction);
    if (std::abs(denom) < 1e-12) return false;
    double th = glm::dot(plane->point - ray.origin, plane->normal) / denom;
    if (!(th > t_min && th < t_max)) return false;
    t = th;
    normal = denom < 0.0 ? plane->normal : -plane->normal;
    return true;
  }
  if (auto* mesh = std::get_if<Mesh>(&shape)) return mesh->triangles->intersect(ray, t_min, t_max, t, normal);
  const auto& sphere = std::get<Sphere>(shape);
  Vec3 oc = ray.origin - sphere.center;
  double b = glm::dot(oc, ray.direction);
  double c = glm::dot(oc, oc) - sphere.radius * sphere.radius;
  double disc = b * b - c;
  if (disc < 0.0) return false;
  double root = std::sqrt(disc);
  double th = -b - root;
  if (!(th > t_min)) th = -b + root;
  if (!(th > t_min && th < t_max)) return false;
  t = th;
  normal = (ray.at(t) - sphere.center) / sphere.radius;
  if (glm::dot(normal, ray.direction) > 0.0) normal = -normal;
  return true;
}

Rgb Surface::brdf(const Vec3& wi, const Vec3& wo, const Vec3& n) const {
  Rgb f = kd / kPi;
  if (ks != Rgb(0.0)) {
    Vec3 mirrored = 2.0 * glm::dot(wi, n) * n - wi;
    double cos_alpha = std::max(0.0, glm::dot(mirrored, wo));
    f += ks * ((shininess + 2.0) / (2.0 * kPi) * std::pow(cos_alpha, shininess));
  }
  return f;
}

const Surface* nearest_surface(const std::vector<Surface>& surfaces, const Ray& ray, double t_max, double& t, Vec3& normal) {
  const Surface* hit = nullptr;
  t = t_max;
  for (const auto& s : surfaces) {
    double ts;
    Vec3 n;
    if (s.intersect(ray, kSurfaceOffset, t, ts, n)) t = ts, normal = n, hit = &s;
  }
  return hit;
}

bool occluded(const std::vector<Surface>& surfaces, const Vec3& x, const Vec3& dir, double distance) {
  const Ray ray{x, dir};
  const double t_max = distance * (1.0 - 1e-9);
  for (const auto& s : surfaces) {
    double t;
    Vec3 n;
    const auto* mesh = std::get_if<Mesh>(&s.shape);
    if (mesh ? mesh->triangles->occluded(ray, kSurfaceOffset, t_max) : s.intersect(ray, kSurfaceOffset, t_max, t, n)) return true;
  }
  return false;
}

namespace {

// The roots of a t^2 + b t + c = 0 (a may be 0) into r; how many.
int solve(double a, double b, double c, double r[2]) {
  if (std::abs(a) < 1e-300) {
    if (b == 0.0) return 0;
    r[0] = -c / b;
    return 1;
  }
  const double d = b * b - 4.0 * a * c;
  if (d < 0.0) return 0;
  const double q = -0.5 * (b + std::copysign(std::sqrt(d), b));  // stable form
  r[0] = q / a;
  if (q == 0.0) return 1;
  r[1] = c / q;
  return 2;
}

// The roots, appended.
void roots(double a, double b, double c, std::vector<double>& out) {
  double r[2];
  out.insert(out.end(), r, r + solve(a, b, c, r));
}

// Where `lit` changes along [t0, t1]: 64 points (u / (1 - u) past t0 for an infinite t1), each
// change bisected to 1e-6 of the stretch between its two points.
template <class Lit>
void mesh_shadow_edges(double t0, double t1, const Lit& lit, std::vector<double>& cuts) {
  constexpr int kPoints = 64;
  const bool infinite = !std::isfinite(t1);
  auto at = [&](double u) { return infinite ? t0 + (1.0 + std::abs(t0)) * u / (1.0 - u) : t0 + u * (t1 - t0); };
  double u_prev = 0.5 / kPoints;
  bool prev = lit(at(u_prev));
  for (int k = 1; k < kPoints; ++k) {
    const double u = (k + 0.5) / kPoints;
    const bool now = lit(at(u));
    if (now != prev) {
      double lo = u_prev, hi = u;
      while (hi - lo > 1e-6) {
        const double mid = 0.5 * (lo + hi);
        (lit(at(mid)) == prev ? lo : hi) = mid;
      }
      cuts.push_back(at(0.5 * (lo + hi)));
    }
    u_prev = u, prev = now;
  }
}

}  // namespace

void lit_stretches(const std::vector<Surface>& surfaces, const Ray& ray, double t0, double t1, const Vec3& light,
                   std::vector<std::pair<double, double>>& out) {
  if (!(t1 > t0)) return;
  thread_local std::vector<double> kept;  // a frame allocates nothing
  std::vector<double>& cuts = kept;
  cuts.clear();
  const Vec3& o = ray.origin;
  const Vec3& d = ray.direction;
  auto lit = [&](double t) {
    const Vec3 x = ray.at(t), to = light - x;
    const double length = glm::length(to);
    return length > 0.0 && !occluded(surfaces, x, to / length, length);
  };
  bool meshes = false;
  for (const Surface& s : surfaces) {
    if (std::holds_alternative<Mesh>(s.shape)) {
      meshes = true;
      continue;
    }
    if (const auto* plane = std::get_if<Plane>(&s.shape)) {
      roots(0.0, glm::dot(d, plane->normal), glm::dot(o - plane->point, plane->normal), cuts);
      continue;
    }
    const auto& sphere = std::get<Sphere>(s.shape);
    const Vec3 oc = o - sphere.center;
    const double r2 = sphere.radius * sphere.radius;
    roots(glm::dot(d, d), 2.0 * glm::dot(oc, d), glm::dot(oc, oc) - r2, cuts);
    // The tangent cone: points x with (v . (x - L))^2 = cos^2(alpha) |x - L|^2, sin(alpha) = r / |c - L|.
    const Vec3 lc = sphere.center - light;
    const double dist2 = glm::dot(lc, lc);
    if (dist2 <= r2) continue;  // the light inside: the sphere's surface is the only edge
    const Vec3 v = lc / std::sqrt(dist2), w = o - light;
    const double cos2 = 1.0 - r2 / dist2, dv = glm::dot(d, v), wv = glm::dot(w, v);
    roots(dv * dv - cos2 * glm::dot(d, d), 2.0 * (wv * dv - cos2 * glm::dot(w, d)), wv * wv - cos2 * glm::dot(w, w), cuts);
  }
  if (meshes) mesh_shadow_edges(t0, t1, lit, cuts);
  cuts.push_back(t0), cuts.push_back(t1);
  std::sort(cuts.begin(), cuts.end());
  double start = t0;
  bool open = false;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = std::max(cuts[i], t0), b = std::min(cuts[i + 1], t1);
    if (!(b > a)) continue;
    const double mid = std::isfinite(b) ? 0.5 * (a + b) : a + 1.0 + std::abs(a);
    const bool is_lit = lit(mid);
    if (is_lit && !open) start = a, open = true;
    if (!is_lit && open) out.emplace_back(start, a), open = false;
  }
  if (open) out.emplace_back(start, t1);
}

LightShadows::LightShadows(const std::vector<Surface>& surfaces, const Vec3& light) : light_(light) {
  for (const Surface& s : surfaces) {
    if (std::holds_alternative<Mesh>(s.shape)) meshes_.push_back(&s);
    if (const auto* plane = std::get_if<Plane>(&s.shape)) planes_.push_back({&s, plane->point, plane->normal});
    if (const auto* sphere = std::get_if<Sphere>(&s.shape)) {
      const Vec3 lc = sphere->center - light;
      const double dist2 = glm::dot(lc, lc), r2 = sphere->radius * sphere->radius;
      spheres_.push_back({&s, sphere->center, dist2 > 0.0 ? lc / std::sqrt(dist2) : Vec3(0.0), r2, dist2 > r2 ? 1.0 - r2 / dist2 : 0.0});
    }
  }
}

bool LightShadows::hidden(const Vec3& x, const Surface* self) const {
  const Vec3 e = light_ - x;  // s in (0, 1) runs from x to the light
  const double length2 = glm::dot(e, e);
  if (!(length2 > 0.0)) return false;
  const double length = std::sqrt(length2), s_min = kSurfaceOffset / length, s_max = 1.0 - 1e-9;  // occluded()'s bounds
  for (const Face& p : planes_) {
    if (p.surface == self) continue;
    // Surface::intersect's root along x -> light: where the plane separates them.
    const double denom = glm::dot(e, p.normal);
    if (std::abs(denom) < 1e-12 * length) continue;
    const double s = glm::dot(p.point - x, p.normal) / denom;
    if (s > s_min && s < s_max) return true;
  }
  for (const Cone& c : spheres_) {
    if (c.surface == self) continue;
    const Vec3 oc = x - c.center;
    const double b = glm::dot(oc, e), cc = glm::dot(oc, oc) - c.r2, disc = b * b - length2 * cc;
    if (disc < 0.0) continue;
    const double root = std::sqrt(disc), s1 = (-b - root) / length2, s2 = (-b + root) / length2;
    if ((s1 > s_min && s1 < s_max) || (s2 > s_min && s2 < s_max)) return true;
  }
  for (const Surface* m : meshes_)
    if (std::get<Mesh>(m->shape).triangles->occluded(Ray{x, e / length}, kSurfaceOffset, length * s_max)) return true;
  return false;
}

LightShadows::Stretch LightShadows::classify(const Ray& ray, double t0, double t1) const {
  if (!(t1 > t0)) return Stretch::lit;
  if (!meshes_.empty()) return Stretch::partial;
  const Vec3& o = ray.origin;
  const Vec3& d = ray.direction;
  const double dd = glm::dot(d, d);
  // An edge inside (t0, t1), a root of a t^2 + b t + c there that `keep` takes: short of the ends
  // by 1e-6 of the stretch (a ray ending on a surface has that surface's root at its end, in or out
  // by rounding; a sliver that thin is decided with the rest).
  const double margin = 1e-6 * (std::isfinite(t1) ? t1 - t0 : 1.0 + std::abs(t0));
  const auto crosses = [&](double a, double b, double c, auto&& keep) {
    double r[2];
    const int n = solve(a, b, c, r);
    for (int k = 0; k < n; ++k)
      if (r[k] > t0 + margin && r[k] < t1 - margin && keep(r[k])) return true;
    return false;
  };
  const auto any = [](double) { return true; };
  for (const Face& p : planes_)
    if (crosses(0.0, glm::dot(d, p.normal), glm::dot(o - p.point, p.normal), any)) return Stretch::partial;
  const Vec3 w = o - light_;
  for (const Cone& s : spheres_) {
    const Vec3 oc = o - s.center;
    if (crosses(dd, 2.0 * glm::dot(oc, d), glm::dot(oc, oc) - s.r2, any)) return Stretch::partial;
    if (s.cos2 == 0.0) continue;  // the light inside: the sphere's surface is the only edge
    const double dv = glm::dot(d, s.axis), wv = glm::dot(w, s.axis);
    // The cone is an edge only past the tangent circle, |c - L| cos^2 along the axis from the light.
    const double circle = std::sqrt(s.r2 / (1.0 - s.cos2)) * s.cos2;
    if (crosses(dv * dv - s.cos2 * dd, 2.0 * (wv * dv - s.cos2 * glm::dot(w, d)), wv * wv - s.cos2 * glm::dot(w, w),
                [&](double t) { return wv + t * dv > circle; }))
      return Stretch::partial;
  }
  const double mid = std::isfinite(t1) ? 0.5 * (t0 + t1) : t0 + 1.0 + std::abs(t0);
  return hidden(ray.at(mid)) ? Stretch::dark : Stretch::lit;
}

}  // namespace haze
