#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/grids/optical_depth.h>

#include "trilinear.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

namespace haze::grids {

namespace {

// Where the light is: a position, or (directional) the unit direction toward it.
struct LightGeometry {
  bool directional = false;
  Vec3 position{0.0};
  Vec3 to_light{0.0};
};

LightGeometry geometry(const Light& light) {
  LightGeometry g;
  if (const auto* p = std::get_if<PointLight>(&light)) {
    g.position = p->position;
  } else if (const auto* s = std::get_if<SpotLight>(&light)) {
    g.position = s->position;
  } else if (const auto* d = std::get_if<DirectionalLight>(&light)) {
    g.directional = true;
    g.to_light = -glm::normalize(d->direction);
    if (!std::isfinite(g.to_light.x + g.to_light.y + g.to_light.z)) throw Error("light.direction", "not a finite non-zero vector", "a direction");
    return g;
  } else {
    throw Error("light.type", "sky", "a point, spot or directional light for optical-depth volumes");
  }
  if (!std::isfinite(g.position.x + g.position.y + g.position.z)) throw Error("light.position", "not finite", "a finite position");
  return g;
}

// integral of the piecewise-constant density from `origin` along unit `dir` over [0, t_max]
// (Amanatides-Woo traversal of the cells the ray crosses inside the grid).
double integrate_ray(const DenseGrid& grid, const Vec3& origin, const Vec3& dir, double t_max) {
  double t0 = 0.0, t1 = t_max;
  if (!grid.bounds().clip(Ray{origin, dir}, t0, t1) || !(t1 > t0)) return 0.0;
  const Vec3 h = grid.cell_size(), lo = grid.bounds().lo;
  const auto& n = grid.resolution();
  const Vec3 start = origin + dir * t0;
  int cell[3], step[3];
  double t_next[3], t_delta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(static_cast<int>(std::floor((start[a] - lo[a]) / h[a])), 0, n[static_cast<size_t>(a)] - 1);
    if (dir[a] > 0.0) {
      step[a] = 1, t_delta[a] = h[a] / dir[a];
      t_next[a] = t0 + (lo[a] + (cell[a] + 1) * h[a] - start[a]) / dir[a];
    } else if (dir[a] < 0.0) {
      step[a] = -1, t_delta[a] = -h[a] / dir[a];
      t_next[a] = t0 + (lo[a] + cell[a] * h[a] - start[a]) / dir[a];
    } else {
      step[a] = 0, t_delta[a] = kInfinity, t_next[a] = kInfinity;
    }
  }
  double sum = 0.0, t = t0;
  while (t < t1) {
    int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    double t_end = std::min(t_next[a], t1);
    sum += static_cast<double>(grid.at(cell[0], cell[1], cell[2])) * (t_end - t);
    t = t_end;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= n[static_cast<size_t>(a)]) break;
    t_next[a] += t_delta[a];
  }
  return sum;
}

// Toward the light from a point: unit direction and distance (infinite for directional lights).
void toward(const LightGeometry& g, const Vec3& x, Vec3& dir, double& distance) {
  if (g.directional) {
    dir = g.to_light, distance = kInfinity;
    return;
  }
  Vec3 v = g.position - x;
  distance = glm::length(v);
  dir = distance > 0.0 ? v / distance : Vec3(0.0, 0.0, 1.0);
}

double exact_depth(const DenseGrid& grid, const LightGeometry& g, const Vec3& x) {
  Vec3 dir;
  double distance;
  toward(g, x, dir, distance);
  return integrate_ray(grid, x, dir, distance);
}

// The axis along which a direction, in cell units q = |dir| / h, crosses cell layers fastest.
int dominant_axis(const Vec3& q) { return q.x >= q.y ? (q.x >= q.z ? 0 : 2) : (q.y >= q.z ? 1 : 2); }

void compute_exact(const DenseGrid& density, const LightGeometry& g, DenseGrid& out, int threads) {
  const auto& n = density.resolution();
  parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {
    for (auto k = static_cast<int>(k0); k < k1; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) out.at(i, j, k) = static_cast<float>(exact_depth(density, g, density.cell_center(i, j, k)));
  });
}

// Seed 003 eq. 6-7: T(X) = K(X) + sum_i W_i T(X - d_i) / sum_i W_i with W_i = max(<SX, d_i>, 0)
// over the six axis directions d_i ((1 - K_t(X)) in eq. 7 is common to all W_i and cancels).
// K(X) is the cell's density times the W-weighted cell length (the paper's grid has unit cells).
// Jacobi iterations from zero until nothing changes (the dependencies run upwind only, so that
// happens after at most the longest upwind path) or nx + ny + nz + 1 iterations.
int compute_paper(const DenseGrid& density, const LightGeometry& g, DenseGrid& out, int threads) {
  const auto& n = density.resolution();
  const Vec3 h = density.cell_size(), lo = density.bounds().lo;
  // The light's own cell, when it is inside: the exact distance from its centre.
  int light_cell[3] = {-1, -1, -1};
  if (!g.directional && density.bounds().contains(g.position))
    for (int a = 0; a < 3; ++a) light_cell[a] = std::clamp(static_cast<int>((g.position[a] - lo[a]) / h[a]), 0, n[static_cast<size_t>(a)] - 1);
  DenseGrid next = out;
  int iterations = 0;
  const int max_iterations = n[0] + n[1] + n[2] + 1;
  for (bool changed = true; changed && iterations < max_iterations; ++iterations) {
    std::atomic<bool> any{false};
    parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {
      bool local = false;
      for (auto k = static_cast<int>(k0); k < k1; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i) {
            const Vec3 x = density.cell_center(i, j, k);
            const double rho = static_cast<double>(density.at(i, j, k));
            double value;
            if (i == light_cell[0] && j == light_cell[1] && k == light_cell[2]) {
              value = rho * glm::length(g.position - x);
            } else {
              const Vec3 sx = g.directional ? -g.to_light : glm::normalize(x - g.position);
              const int idx[3] = {i, j, k};
              double weights = 0.0, gathered = 0.0, length = 0.0;
              for (int a = 0; a < 3; ++a) {
                // d_i = +e_a or -e_a: the neighbour X - d_i lies against the light's direction.
                double w = std::abs(sx[a]);
                if (w == 0.0) continue;
                int nb[3] = {idx[0], idx[1], idx[2]};
                nb[a] -= sx[a] > 0.0 ? 1 : -1;
                double t = nb[a] >= 0 && nb[a] < n[static_cast<size_t>(a)] ? static_cast<double>(out.at(nb[0], nb[1], nb[2])) : 0.0;
                weights += w, gathered += w * t, length += w * h[a];
              }
              value = rho * length / weights + gathered / weights;
            }
            float v = static_cast<float>(value);
            if (v != next.at(i, j, k)) local = true;
            next.at(i, j, k) = v;
          }
      if (local) any = true;
    });
    changed = any.load();
    std::swap(out.values(), next.values());
  }
  return iterations;
}

// Short characteristics (BEYOND.md): from the cell centre toward the light to the plane `layers`
// cell layers away along the dominant axis, walked exactly (DDA); beyond it, the depth is
// interpolated from that layer's four nearest cells. What is interpolated is the mean density
// along each cell's path to the light (its depth over the length of that path inside the grid),
// then multiplied by the landing point's own path length: depth itself curves near the light and
// kinks where the exit face changes, the mean density does neither in a homogeneous medium, where
// the sweep is then exact. Cells whose step would leave the grid or pass the light take the exact
// DDA all the way.
struct Sweeper {
  const DenseGrid& density;
  const LightGeometry& g;
  DenseGrid& out;
  DenseGrid mean;  // depth / path length inside the grid
  int layers;
  Vec3 h, lo;
  std::array<int, 3> n;

  Sweeper(const DenseGrid& d, const LightGeometry& geo, DenseGrid& o, int step_layers)
      : density(d), g(geo), out(o), mean(d.resolution(), d.bounds()), layers(step_layers), h(d.cell_size()), lo(d.bounds().lo),
        n(d.resolution()) {}

  // Length of the path from x toward the light inside the grid.
  double inside_length(const Vec3& x, const Vec3& dir, double distance) const {
    double t0 = 0.0, t1 = distance;
    return density.bounds().clip(Ray{x, dir}, t0, t1) && t1 > t0 ? t1 - t0 : 0.0;
  }

  void store(int i, int j, int k, double depth, double length) {
    out.at(i, j, k) = static_cast<float>(depth);
    mean.at(i, j, k) = static_cast<float>(length > 0.0 ? depth / length : static_cast<double>(density.at(i, j, k)));
  }

  void cell(int i, int j, int k, bool near_light) {
    const Vec3 x = density.cell_center(i, j, k);
    Vec3 dir;
    double distance;
    toward(g, x, dir, distance);
    const double length = inside_length(x, dir, distance);
    // The step to the plane `layers` cell layers toward the light along the dominant axis.
    const Vec3 q = glm::abs(dir) / h;
    const int a = dominant_axis(q);
    const double s = layers / q[a];
    if (near_light || length <= s || distance <= s) {
      store(i, j, k, integrate_ray(density, x, dir, distance), length);
      return;
    }
    const Vec3 p = x + s * dir;
    int base[3] = {i, j, k};
    base[a] += dir[a] > 0.0 ? layers : -layers;
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    // Where the landing point lies past the outermost cell centres the ray is on its way out of
    // the grid sideways: no neighbours to interpolate between, so take the exact (short) walk.
    bool outside = false;
    auto split = [&](int axis, int& i0, int& i1, double& f) {
      double u = (p[axis] - lo[axis]) / h[axis] - 0.5;
      const int last = n[static_cast<size_t>(axis)] - 1;
      outside |= u < 0.0 || u > last;
      double fl = std::floor(u);
      f = u - fl;
      i0 = std::clamp(static_cast<int>(fl), 0, last), i1 = std::clamp(static_cast<int>(fl) + 1, 0, last);
    };
    int b0, b1, c0, c1;
    double fb, fc;
    split(b, b0, b1, fb);
    split(c, c0, c1, fc);
    if (outside) {
      store(i, j, k, integrate_ray(density, x, dir, distance), length);
      return;
    }
    double mean_land = 0.0;
    const double w[4] = {(1 - fb) * (1 - fc), fb * (1 - fc), (1 - fb) * fc, fb * fc};
    const int ib[4] = {b0, b1, b0, b1}, ic[4] = {c0, c0, c1, c1};
    for (int m = 0; m < 4; ++m) {
      if (w[m] == 0.0) continue;
      int idx[3];
      idx[a] = base[a], idx[b] = ib[m], idx[c] = ic[m];
      mean_land += w[m] * static_cast<double>(mean.at(idx[0], idx[1], idx[2]));
    }
    // The step itself is walked exactly (DDA); only the depth beyond it is interpolated.
    const double depth = (length - s) * mean_land + integrate_ray(density, x, dir, s);
    store(i, j, k, depth, length);
  }
};

void compute_sweep(const DenseGrid& density, const LightGeometry& g, DenseGrid& out, int layers, int threads) {
  Sweeper sweeper(density, g, out, layers);
  const auto& n = density.resolution();
  if (g.directional) {
    // Layers along the dominant axis from the face toward the light; each depends on the last.
    const int a = dominant_axis(glm::abs(g.to_light) / sweeper.h);
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const int na = n[static_cast<size_t>(a)];
    for (int layer = 0; layer < na; ++layer) {
      const int l = g.to_light[a] > 0.0 ? na - 1 - layer : layer;
      parallel_for(n[static_cast<size_t>(c)], threads, 8, [&](long long c0, long long c1) {
        int idx[3];
        idx[a] = l;
        for (auto ic = static_cast<int>(c0); ic < c1; ++ic)
          for (int ib = 0; ib < n[static_cast<size_t>(b)]; ++ib) {
            idx[b] = ib, idx[c] = ic;
            sweeper.cell(idx[0], idx[1], idx[2], false);
          }
      });
    }
    return;
  }
  // Point lights: shells of cells at Chebyshev distance r from the light's cell, outward. In a
  // shell, face cells (one coordinate at distance r) depend only on inner shells, edge cells (two)
  // also on face cells, corners (three) also on edges: three passes per shell keep every
  // dependency computed first (with steps of several layers too). Shells up to the step (the
  // light's neighbourhood) are exact.
  int lc[3];
  for (int a = 0; a < 3; ++a) lc[a] = static_cast<int>(std::floor((g.position[a] - sweeper.lo[a]) / sweeper.h[a]));
  int r_min = 0, r_max = 0;
  for (int a = 0; a < 3; ++a) {
    const int last = n[static_cast<size_t>(a)] - 1;
    r_min = std::max({r_min, -lc[a], lc[a] - last});
    r_max = std::max({r_max, std::abs(lc[a]), std::abs(lc[a] - last)});
  }
  for (int r = r_min; r <= r_max; ++r) {
    const int z0 = std::max(lc[2] - r, 0), z1 = std::min(lc[2] + r, n[2] - 1);
    const int y0 = std::max(lc[1] - r, 0), y1 = std::min(lc[1] + r, n[1] - 1);
    for (int pass = 1; pass <= 3; ++pass) {
      parallel_for(z1 - z0 + 1, threads, 8, [&](long long k0, long long k1) {
        for (int k = z0 + static_cast<int>(k0); k < z0 + k1; ++k)
          for (int j = y0; j <= y1; ++j) {
            const bool on_z = std::abs(k - lc[2]) == r, on_y = std::abs(j - lc[1]) == r;
            auto visit = [&](int i) {
              if (i < 0 || i >= n[0]) return;
              const int at_r = (std::abs(i - lc[0]) == r) + on_y + on_z;
              if (at_r == pass) sweeper.cell(i, j, k, r <= layers);
            };
            if (on_z || on_y) {
              for (int i = std::max(lc[0] - r, 0); i <= std::min(lc[0] + r, n[0] - 1); ++i) visit(i);
            } else {
              visit(lc[0] - r);
              if (r > 0) visit(lc[0] + r);
            }
          }
      });
    }
  }
}

}  // namespace

DepthScheme depth_scheme_from_name(const std::string& scheme) {
  if (scheme == "exact") return DepthScheme::exact;
  if (scheme == "paper") return DepthScheme::paper;
  if (scheme == "sweep") return DepthScheme::sweep;
  throw Error("optical_depth", "\"" + scheme + "\"", "\"exact\", \"paper\" or \"sweep\"");
}

const char* name(DepthScheme scheme) {
  switch (scheme) {
    case DepthScheme::exact: return "exact";
    case DepthScheme::paper: return "paper";
    case DepthScheme::sweep: return "sweep";
  }
  return "?";
}

DenseGrid optical_depth(const DenseGrid& density, const Light& light, const DepthOptions& options, DepthStats* stats) {
  if (options.sweep_layers < 1 || options.sweep_layers > 64)
    throw Error("sweep_layers", to_text(options.sweep_layers), "an integer in [1, 64]");
  const LightGeometry g = geometry(light);
  DenseGrid out(density.resolution(), density.bounds());
  int iterations = 1;
  switch (options.scheme) {
    case DepthScheme::exact: compute_exact(density, g, out, options.threads); break;
    case DepthScheme::paper: iterations = compute_paper(density, g, out, options.threads); break;
    case DepthScheme::sweep: compute_sweep(density, g, out, options.sweep_layers, options.threads); break;
  }
  if (stats) stats->iterations = std::max(stats->iterations, iterations);
  return out;
}

std::vector<DenseGrid> optical_depths(const DenseGrid& density, const std::vector<Light>& lights, const DepthOptions& options,
                                      DepthStats* stats) {
  for (const auto& light : lights) geometry(light);  // errors before any work
  std::vector<std::optional<DenseGrid>> volumes(lights.size());
  std::vector<DepthStats> per_light(lights.size());
  parallel_for(static_cast<long long>(lights.size()), options.threads, 1, [&](long long l0, long long l1) {
    for (auto l = static_cast<size_t>(l0); l < static_cast<size_t>(l1); ++l) volumes[l] = optical_depth(density, lights[l], options, &per_light[l]);
  });
  std::vector<DenseGrid> out;
  for (size_t l = 0; l < lights.size(); ++l) {
    out.push_back(std::move(*volumes[l]));
    if (stats) stats->iterations = std::max(stats->iterations, per_light[l].iterations);
  }
  return out;
}

double density_integral_dda(const DenseGrid& density, const Vec3& a, const Vec3& b) {
  const Vec3 v = b - a;
  const double length = glm::length(v);
  return length > 0.0 ? integrate_ray(density, a, v / length, length) : 0.0;
}

float sample_trilinear(const DenseGrid& grid, const Vec3& p) {
  if (!grid.bounds().contains(p)) return 0.0f;
  const TrilinearStencil stencil(grid, p);
  double v = 0.0;
  for (int m = 0; m < 8; ++m) v += stencil.weight[m] * static_cast<double>(grid.values()[stencil.offset[m]]);
  return static_cast<float>(v);
}

}  // namespace haze::grids
