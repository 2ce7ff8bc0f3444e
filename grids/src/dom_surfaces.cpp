#include "dom_surfaces.h"

#include "dom_internal.h"

#include <cmath>

namespace haze::grids {

bool SurfaceTexels::Rectangle::lookup(const Vec3& p, Rgb& e) const {
  const double fu = (glm::dot(p - origin, u) - u0) / size - 0.5, fv = (glm::dot(p - origin, v) - v0) / size - 0.5;
  if (!(fu >= -0.5 && fu <= nu - 0.5 && fv >= -0.5 && fv <= nv - 0.5)) return false;
  const double cu = std::clamp(fu, 0.0, nu - 1.0), cv = std::clamp(fv, 0.0, nv - 1.0);
  const int i = std::min(static_cast<int>(cu), nu - 2), j = std::min(static_cast<int>(cv), nv - 2);
  const double a = cu - i, b = cv - j;
  auto at = [&](int di, int dj) { return values[static_cast<size_t>(j + dj) * static_cast<size_t>(nu) + static_cast<size_t>(i + di)]; };
  e = (1.0 - b) * ((1.0 - a) * at(0, 0) + a * at(1, 0)) + b * ((1.0 - a) * at(0, 1) + a * at(1, 1));
  return true;
}

Rgb SurfaceTexels::Globe::lookup(const Vec3& p) const {
  const Vec3 u = glm::normalize(p - centre);
  const double ft = std::clamp(std::acos(std::clamp(u.y, -1.0, 1.0)) / kPi * nt - 0.5, 0.0, nt - 1.0);
  const double fp = (std::atan2(u.z, u.x) + kPi) / (2.0 * kPi) * np - 0.5;
  const int t = std::min(static_cast<int>(ft), nt - 2);
  const double a = ft - t, fl = std::floor(fp), b = fp - fl;
  const int p0 = (static_cast<int>(fl) % np + np) % np, p1 = (p0 + 1) % np;
  auto at = [&](int ti, int pi) { return values[static_cast<size_t>(ti) * static_cast<size_t>(np) + static_cast<size_t>(pi)]; };
  return (1.0 - a) * ((1.0 - b) * at(t, p0) + b * at(t, p1)) + a * ((1.0 - b) * at(t + 1, p0) + b * at(t + 1, p1));
}

std::int64_t SurfaceTexels::Patches::cell_key(const Vec3& p) const {
  const Vec3 c = glm::floor(p / size);
  constexpr std::int64_t k = 1 << 20;  // 2^20 cells a side, wrapping
  auto wrap = [&](double v) { return ((static_cast<std::int64_t>(v) % k) + k) % k; };
  return (wrap(c.x) * k + wrap(c.y)) * k + wrap(c.z);
}

void SurfaceTexels::Patches::index() {
  cells.clear();
  for (size_t i = 0; i < points.size(); ++i) cells[cell_key(points[i])].push_back(static_cast<std::uint32_t>(i));
}

bool SurfaceTexels::Patches::lookup(const Vec3& p, const Vec3& n, Rgb& e) const {
  Rgb sum(0.0);
  double weights = 0.0;
  const double reach = 1.5 * size;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto it = cells.find(cell_key(p + size * Vec3(dx, dy, dz)));
        if (it == cells.end()) continue;
        for (const std::uint32_t i : it->second) {
          const double facing = glm::dot(normals[i], n);
          if (std::abs(facing) < 0.9 || std::abs(glm::dot(p - points[i], normals[i])) > 0.25 * size) continue;  // another face
          const double d = glm::length(p - points[i]);
          if (d >= reach) continue;
          const double w = 1.0 - d / reach;
          sum += w * (facing > 0.0 ? front[i] : back[i]), weights += w;
        }
      }
  if (!(weights > 0.0)) return false;
  e = sum / weights;
  return true;
}

}  // namespace haze::grids

namespace haze::grids::dom {

namespace {
constexpr int kMostTexels = 48;
constexpr size_t kMostMeshTexels = 4096;

// Texels on a mesh's triangles within `region`, each triangle cut into k^2 similar ones (k from
// its longest edge over `size`, at most 1024), one texel at each small triangle's centroid; `size`
// grows until at most kMostMeshTexels fit.
SurfaceTexels::Patches mesh_patches(const TriangleMesh& mesh, const Aabb& region, double size) {
  SurfaceTexels::Patches out;
  for (;; size *= 1.5) {
    out.points.clear(), out.normals.clear();
    auto add = [&](const Vec3& p, const Vec3& n) {
      if (region.contains(p)) out.points.push_back(p), out.normals.push_back(n);
    };
    for (size_t tri = 0; tri < mesh.triangle_count() && out.points.size() <= kMostMeshTexels; ++tri) {
      const Vec3 a = mesh.vertex(tri, 0), ab = mesh.vertex(tri, 1) - a, ac = mesh.vertex(tri, 2) - a;
      const Vec3 c = glm::cross(ab, ac);
      if (!(glm::length(c) > 0.0)) continue;
      const Vec3 n = glm::normalize(c);
      const double longest = std::max({glm::length(ab), glm::length(ac), glm::length(ac - ab)});
      const int k = std::clamp(static_cast<int>(std::ceil(longest / size)), 1, 1024);
      for (int i = 0; i < k; ++i)
        for (int j = 0; i + j < k; ++j) {
          add(a + ((i + 1.0 / 3.0) * ab + (j + 1.0 / 3.0) * ac) / double(k), n);
          if (i + j + 1 < k) add(a + ((i + 2.0 / 3.0) * ab + (j + 2.0 / 3.0) * ac) / double(k), n);
        }
    }
    if (out.points.size() <= kMostMeshTexels) break;
  }
  out.size = size;
  out.index();
  return out;
}

}  // namespace

SurfaceTexels surface_texels(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                             const DomSolution& solution, const Rgb& sky, double step_cells, int threads,
                             const SurfaceLight* surfaces) {
  const Aabb& bounds = volume.density.bounds();
  const Vec3 h = volume.density.cell_size(), extent = bounds.extent(), centre = 0.5 * (bounds.lo + bounds.hi);
  const Gather gather(delta, volume, depths, solution, step_cells, threads, surfaces);
  SurfaceTexels out;
  out.planes.resize(delta.surfaces.size());
  out.spheres.resize(delta.surfaces.size());
  out.meshes.resize(delta.surfaces.size());
  for (size_t s = 0; s < delta.surfaces.size(); ++s) {
    // A surface that reflects nothing (a host's, "shaded": false) needs no texels: 31 copies of a
    // room's mesh took 50 s here.
    if (delta.surfaces[s].kd == Rgb(0.0) && delta.surfaces[s].ks == Rgb(0.0)) continue;
    if (const auto* mesh = std::get_if<Mesh>(&delta.surfaces[s].shape)) {
      // Texels about two cells apart over the grid's bounds widened by their extent, as on planes
      // (past them, pi sky); E_s on both sides (a mesh's winding need not say which side the
      // medium is on).
      SurfaceTexels::Patches& m = out.meshes[s];
      m = mesh_patches(*mesh->triangles, {bounds.lo - extent, bounds.hi + extent}, 2.0 * std::max({h.x, h.y, h.z}));
      m.front.resize(m.points.size()), m.back.resize(m.points.size());
      parallel_for(static_cast<long long>(m.points.size()), threads, 16, [&](long long i0, long long i1) {
        for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i)
          for (const double side : {1.0, -1.0}) {
            // Off the face by twice the mesh's self-hit skip: the gather's rays then leave it.
            const Vec3 n = side * m.normals[i], p = m.points[i] + 2.0 * TriangleMesh::kSelfHit * (1.0 + glm::length(m.points[i])) * n;
            (side > 0.0 ? m.front : m.back)[i] = gather.around(p, n, sky, [](const Vec3&) { return Rgb(1.0); });
          }
      });
      continue;
    }
    if (const auto* sphere = std::get_if<Sphere>(&delta.surfaces[s].shape)) {
      SurfaceTexels::Globe& g = out.spheres[s];
      // Texels about a cell apart along a meridian, 8 to 16 of them (and twice as many around).
      g.centre = sphere->center, g.radius = sphere->radius;
      g.nt = std::clamp(static_cast<int>(std::ceil(kPi * sphere->radius / std::min({h.x, h.y, h.z}))), 8, 16), g.np = 2 * g.nt;
      g.values.assign(static_cast<size_t>(g.nt) * static_cast<size_t>(g.np), Rgb(0.0));
      parallel_for(g.nt, threads, 1, [&](long long t0, long long t1) {
        for (auto t = static_cast<int>(t0); t < t1; ++t)
          for (int p = 0; p < g.np; ++p) {
            const double theta = (t + 0.5) * kPi / g.nt, phi = (p + 0.5) * 2.0 * kPi / g.np - kPi;
            const Vec3 u(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            g.values[static_cast<size_t>(t) * static_cast<size_t>(g.np) + static_cast<size_t>(p)] =
                gather.around(g.centre + (g.radius * (1.0 + 1e-9)) * u, u, sky, [](const Vec3&) { return Rgb(1.0); });
          }
      });
      continue;
    }
    const auto* plane = std::get_if<Plane>(&delta.surfaces[s].shape);
    SurfaceTexels::Rectangle& t = out.planes[s];
    const Vec3 n = glm::dot(centre - plane->point, plane->normal) >= 0.0 ? plane->normal : -plane->normal;
    t.origin = plane->point;
    t.u = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9 ? Vec3(1.0, 0.0, 0.0) : Vec3(0.0, 1.0, 0.0)));
    t.v = glm::cross(n, t.u);
    double u1 = -kInfinity, v1 = -kInfinity;
    t.u0 = t.v0 = kInfinity;
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner(c & 1 ? bounds.hi.x + extent.x : bounds.lo.x - extent.x, c & 2 ? bounds.hi.y + extent.y : bounds.lo.y - extent.y,
                        c & 4 ? bounds.hi.z + extent.z : bounds.lo.z - extent.z);
      const double cu = glm::dot(corner - t.origin, t.u), cv = glm::dot(corner - t.origin, t.v);
      t.u0 = std::min(t.u0, cu), t.v0 = std::min(t.v0, cv), u1 = std::max(u1, cu), v1 = std::max(v1, cv);
    }
    t.size = std::max(2.0 * std::max({h.x, h.y, h.z}), std::max(u1 - t.u0, v1 - t.v0) / kMostTexels);
    t.nu = std::max(2, static_cast<int>(std::ceil((u1 - t.u0) / t.size)));
    t.nv = std::max(2, static_cast<int>(std::ceil((v1 - t.v0) / t.size)));
    t.values.assign(static_cast<size_t>(t.nu) * static_cast<size_t>(t.nv), Rgb(0.0));
    parallel_for(t.nv, threads, 1, [&](long long j0, long long j1) {
      for (auto j = static_cast<int>(j0); j < j1; ++j)
        for (int i = 0; i < t.nu; ++i) {
          const Vec3 p = t.origin + (t.u0 + (i + 0.5) * t.size) * t.u + (t.v0 + (j + 0.5) * t.size) * t.v;
          t.values[static_cast<size_t>(j) * static_cast<size_t>(t.nu) + static_cast<size_t>(i)] =
              gather.around(p, n, sky, [](const Vec3&) { return Rgb(1.0); });
        }
    });
  }
  return out;
}

SurfaceLight::SurfaceLight(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                           const SurfaceTexels& texels, const Rgb& sky, double delta_m_fraction)
    : delta_(delta),
      volume_(volume),
      depths_(depths),
      texels_(texels),
      sky_(sky),
      sigma_t_(delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, delta_m_fraction)) {
  const Vec3 h = volume.density.cell_size();
  // Past nearest_surface's 1e-7, and past a mesh's self-hit skip anywhere in the grid.
  const double far = std::max(glm::length(volume.density.bounds().lo), glm::length(volume.density.bounds().hi));
  offset_ = std::max({1e-4 * std::min({h.x, h.y, h.z}), 1e-6, 3.0 * TriangleMesh::kSelfHit * (1.0 + far)});
}

Rgb SurfaceLight::reflected(const Surface& surface, const Vec3& p, const Vec3& n, const Vec3& wo, bool glossy) const {
  Surface lambert = surface;
  if (!glossy) lambert.ks = Rgb(0.0);
  return surface_direct(delta_.lights, delta_.surfaces, volume_.density, depths_, sigma_t_, lambert, p, n, wo) +
         surface.kd / kPi * irradiance(surface, p, n);
}

Rgb SurfaceLight::irradiance(const Surface& surface, const Vec3& p, const Vec3& n) const {
  Rgb e_s = kPi * sky_;
  const auto index = static_cast<size_t>(&surface - delta_.surfaces.data());
  if (const SurfaceTexels::Patches& patches = texels_.meshes[index]; !patches.points.empty()) patches.lookup(p, n, e_s);
  if (const SurfaceTexels::Rectangle& rectangle = texels_.planes[index]; !rectangle.values.empty()) rectangle.lookup(p, e_s);
  if (const SurfaceTexels::Globe& globe = texels_.spheres[index]; !globe.values.empty()) e_s = globe.lookup(p);
  return e_s;
}

Rgb SurfaceLight::entering(const Vec3& point, const Vec3& w) const {
  const Ray back{point + offset_ * w, -w};
  double t = kInfinity;
  Vec3 n;
  const Surface* surface = nearest_surface(delta_.surfaces, back, kInfinity, t, n);
  return surface ? reflected(*surface, back.at(t), n, w) : sky_;
}

DomBoundary SurfaceLight::boundary() const {
  bool grey = is_grey(sky_);
  for (const Surface& s : delta_.surfaces) grey = grey && is_grey(s.kd) && is_grey(s.ks);
  return DomBoundary{[this](const Vec3& point, const Vec3& w) { return entering(point, w); }, grey};
}

}  // namespace haze::grids::dom
