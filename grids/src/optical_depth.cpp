#include <haze/core/error.h>
#include <haze/core/grid_walk.h>
#include <haze/core/progress.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/sweep_cells.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <thread>

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
  GridWalk walk(grid.bounds(), grid.resolution(), Ray{origin, dir}, 0.0, t_max);
  double sum = 0.0;
  for (CellSegment s; walk.next(s);) sum += static_cast<double>(grid.values()[s.cell]) * (s.t1 - s.t0);
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
    for (int a = 0; a < 3; ++a)
      light_cell[a] = static_cast<int>(std::clamp((g.position[a] - lo[a]) / h[a], 0.0, n[static_cast<size_t>(a)] - 1.0));
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

// Short characteristics (BEYOND.md), the formulas of haze/grids/sweep_cells.h: from each cell
// centre toward the light to the cell-centre plane `layers` layers away along the dominant axis,
// walked cell by cell; beyond it, the mean density along the landing point's own path (bilinear
// in that plane) times that path's length. Interpolating the mean density rather than the depth,
// which curves near the light and kinks where the exit face changes, makes the sweep exact in a
// homogeneous medium; walking several layers between interpolations keeps the sideways blur of
// shadows small (docs/PROPAGATION.md). Cells within `layers` shells of a point light walk their
// whole path. Cells go to the kernel in runs along x (or y), in an order that computes every cell
// a landing point reads first.
class Sweeper {
 public:
  Sweeper(const DenseGrid& density, const LightGeometry& g, DenseGrid& out, int layers, bool scalar, int exact_radius,
          const int light_cell[3])
      : out_(out), mean_(density.resolution(), density.bounds()),
        kernel_(scalar ? &sweep_cells_reference : &sweep_cells) {
    const Vec3 h = density.cell_size();
    for (int e = 0; e < 3; ++e) {
      volume_.n[e] = density.resolution()[static_cast<size_t>(e)];
      volume_.lo[e] = static_cast<float>(density.bounds().lo[e]);
      volume_.h[e] = static_cast<float>(h[e]);
      volume_.light[e] = static_cast<float>(g.directional ? g.to_light[e] : g.position[e]);
      volume_.light_cell[e] = light_cell[e];
    }
    volume_.density = density.values().data();
    volume_.mean = mean_.values().data();
    volume_.directional = g.directional;
    volume_.layers = layers;
    volume_.exact_radius = exact_radius;
  }

  struct Run {
    int i, j, k, axis, count;
  };

  // The runs in parallel (each reads only cells of earlier calls).
  void sweep(const std::vector<Run>& runs, int threads) {
    long long cells = 0;
    for (const Run& r : runs) cells += r.count;
    const int workers = cells < 4096 ? 1 : threads;  // a thread hand-off costs more than small passes
    parallel_for(static_cast<long long>(runs.size()), workers, 4, [&](long long r0, long long r1) {
      std::vector<float> depth, mean;
      for (auto r = static_cast<size_t>(r0); r < static_cast<size_t>(r1); ++r) {
        const Run& run = runs[r];
        const size_t first = out_.index(run.i, run.j, run.k);
        if (run.axis == 0) {  // contiguous: straight into the volumes
          kernel_(volume_, run.i, run.j, run.k, 0, run.count, &out_.values()[first], &mean_.values()[first]);
          continue;
        }
        depth.resize(static_cast<size_t>(run.count)), mean.resize(static_cast<size_t>(run.count));
        kernel_(volume_, run.i, run.j, run.k, run.axis, run.count, depth.data(), mean.data());
        const auto stride = static_cast<size_t>(volume_.n[0]);
        for (size_t m = 0; m < depth.size(); ++m) {
          out_.values()[first + m * stride] = depth[m];
          mean_.values()[first + m * stride] = mean[m];
        }
      }
    });
  }

 private:
  DenseGrid& out_;
  DenseGrid mean_;  // depth / path length inside the grid, read by later landings
  SweepVolume volume_;
  void (*kernel_)(const SweepVolume&, int, int, int, int, int, float*, float*);
};

void compute_sweep(const DenseGrid& density, const LightGeometry& g, DenseGrid& out, int layers, bool scalar, int threads) {
  const auto& n = density.resolution();
  const Vec3 h = density.cell_size(), lo = density.bounds().lo;
  // The point light's cell (perhaps outside the grid). A light farther than 2^28 cells from the
  // grid's centre is moved toward it along the same line (its rings keep their order, and int
  // arithmetic on them stays in range: a light 1e9 away was 8e9 cells, past int).
  int lc[3] = {0, 0, 0};
  if (!g.directional) {
    const Vec3 centre = 0.5 * Vec3(n[0], n[1], n[2]);
    Vec3 cell = (g.position - lo) / h - centre;
    if (const double far = max_abs(cell); far > 0x1p28) cell *= 0x1p28 / far;
    for (int a = 0; a < 3; ++a) lc[a] = static_cast<int>(std::floor(centre[a] + cell[a]));
  }
  Sweeper sweeper(density, g, out, layers, scalar, g.directional ? -1 : layers, lc);
  std::vector<Sweeper::Run> runs;
  if (g.directional) {
    // Layers along the dominant axis from the face toward the light; each depends on earlier ones.
    const int a = dominant_axis(glm::abs(g.to_light) / h);
    const int na = n[static_cast<size_t>(a)];
    for (int layer = 0; layer < na; ++layer) {
      const int l = g.to_light[a] > 0.0 ? na - 1 - layer : layer;
      runs.clear();
      if (a == 0) {
        for (int k = 0; k < n[2]; ++k) runs.push_back({l, 0, k, 1, n[1]});
      } else {
        for (int c = 0; c < n[static_cast<size_t>(3 - a)]; ++c) runs.push_back(a == 1 ? Sweeper::Run{0, l, c, 0, n[0]} : Sweeper::Run{0, c, l, 0, n[0]});
      }
      sweeper.sweep(runs, threads);
    }
    return;
  }
  // Point lights: shells of cells at Chebyshev distance r from the light's cell, outward. In a
  // shell, face cells (one coordinate at distance r) depend only on inner shells, edge cells (two)
  // also on face cells, corners (three) also on edges: three passes per shell keep every
  // dependency computed first. Runs go along x, except on the x faces (along y).
  int r_min = 0, r_max = 0;
  for (int a = 0; a < 3; ++a) {
    const int last = n[static_cast<size_t>(a)] - 1;
    r_min = std::max({r_min, -lc[a], lc[a] - last});
    r_max = std::max({r_max, std::abs(lc[a]), std::abs(lc[a] - last)});
  }
  // [c - r + 1, c + r - 1] (the shell's inside along an axis) and the shell's two sides, in the grid.
  auto inside = [&](int a, int r, int& first, int& last) {
    first = std::max(lc[a] - r + 1, 0), last = std::min(lc[a] + r - 1, n[static_cast<size_t>(a)] - 1);
  };
  auto sides = [&](int a, int r) {
    std::vector<int> s;
    for (int v : {lc[a] - r, lc[a] + r})
      if (v >= 0 && v < n[static_cast<size_t>(a)] && (s.empty() || s.back() != v)) s.push_back(v);
    return s;
  };
  for (int r = r_min; r <= r_max; ++r) {
    int x0, x1, y0, y1, z0, z1;
    inside(0, r, x0, x1), inside(1, r, y0, y1), inside(2, r, z0, z1);
    const auto xs = sides(0, r), ys = sides(1, r), zs = sides(2, r);
    for (int pass = 1; pass <= 3; ++pass) {
      runs.clear();
      // A run along x at (j, k) where `at_r` coordinates (of y, z) sit on the shell: the inside
      // cells have at_r of them, the two ends at_r + 1.
      auto row = [&](int j, int k, int at_r) {
        if (at_r == pass && x1 >= x0) runs.push_back({x0, j, k, 0, x1 - x0 + 1});
        if (at_r + 1 == pass)
          for (int i : xs) runs.push_back({i, j, k, 0, 1});
      };
      for (int k : zs) {
        for (int j = y0; j <= y1; ++j) row(j, k, 1);
        for (int j : ys) row(j, k, 2);
      }
      for (int j : ys)
        for (int k = z0; k <= z1; ++k) row(j, k, 1);
      if (pass == 1 && y1 >= y0)
        for (int i : xs)
          for (int k = z0; k <= z1; ++k) runs.push_back({i, y0, k, 1, y1 - y0 + 1});
      sweeper.sweep(runs, threads);
    }
  }
}

}  // namespace

DepthScheme depth_scheme_from_name(const std::string& scheme) { return from_name<DepthScheme>(kDepthSchemes, scheme, "optical_depth"); }
const char* name(DepthScheme scheme) { return name_of<DepthScheme>(kDepthSchemes, scheme); }

DenseGrid optical_depth(const DenseGrid& density, const Light& light, const DepthOptions& options, DepthStats* stats) {
  if (options.sweep_layers < 1 || options.sweep_layers > 64)
    throw Error("sweep_layers", to_text(options.sweep_layers), "an integer in [1, 64]");
  const LightGeometry g = geometry(light);
  DenseGrid out(density.resolution(), density.bounds());
  int iterations = 1;
  switch (options.scheme) {
    case DepthScheme::exact: compute_exact(density, g, out, options.threads); break;
    case DepthScheme::paper: iterations = compute_paper(density, g, out, options.threads); break;
    case DepthScheme::sweep: compute_sweep(density, g, out, options.sweep_layers, options.scalar_kernel, options.threads); break;
  }
  if (stats) stats->iterations = std::max(stats->iterations, iterations);
  return out;
}

void check_depth_memory(const DenseGrid& density, const std::vector<Light>& lights, std::size_t max_memory) {
  const auto volumes = static_cast<std::size_t>(std::count_if(lights.begin(), lights.end(), [](const Light& l) { return !std::holds_alternative<SkyLight>(l); }));
  const auto r = density.resolution();
  check_memory(volumes * density.cell_count() * sizeof(float), max_memory, "lights",
               to_text(volumes) + " optical-depth volumes of " + to_text(r[0]) + " x " + to_text(r[1]) + " x " + to_text(r[2]) + " cells",
               "fewer lights or a lower resolution");
}

std::vector<DenseGrid> optical_depths(const DenseGrid& density, const std::vector<Light>& lights, const DepthOptions& options,
                                      DepthStats* stats) {
  for (const auto& light : lights) geometry(light);  // errors before any work
  std::vector<std::optional<DenseGrid>> volumes(lights.size());
  std::vector<DepthStats> per_light(lights.size());
  // As many lights as threads: one thread per light, none handed work inside a light.
  const auto workers = options.threads > 0 ? static_cast<unsigned>(options.threads) : std::thread::hardware_concurrency();
  DepthOptions per_light_options = options;
  if (lights.size() >= workers) per_light_options.threads = 1;
  parallel_for(static_cast<long long>(lights.size()), options.threads, 1, [&](long long l0, long long l1) {
    for (auto l = static_cast<size_t>(l0); l < static_cast<size_t>(l1); ++l)
      volumes[l] = optical_depth(density, lights[l], per_light_options, &per_light[l]);
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
  return static_cast<float>(TrilinearStencil(grid.bounds(), grid.resolution(), p).apply(grid.values().data()));
}

std::vector<DenseGrid> surface_visibility(const DenseGrid& grid, const std::vector<Light>& lights, const std::vector<Surface>& surfaces,
                                          int threads) {
  std::vector<DenseGrid> out;
  if (surfaces.empty()) return out;
  const auto& n = grid.resolution();
  for (const Light& light : lights) {
    DenseGrid v(n, grid.bounds());
    parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {
      LightArrival a;
      for (auto k = static_cast<int>(k0); k < k1; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i) {
            const Vec3 x = grid.cell_center(i, j, k);
            // The sky, or a light at x: nothing to block.
            const bool blocked = arrival(light, x, a) && a.distance > 0.0 && occluded(surfaces, x, a.to_light, a.distance);
            v.at(i, j, k) = blocked ? 0.0f : 1.0f;
          }
    });
    out.push_back(std::move(v));
  }
  return out;
}

std::vector<DenseGrid> shadowed_depths(std::vector<DenseGrid> depths, const std::vector<DenseGrid>& visibility) {
  for (size_t l = 0; l < depths.size() && l < visibility.size(); ++l)
    for (size_t c = 0; c < depths[l].values().size(); ++c)
      if (visibility[l].values()[c] == 0.0f) depths[l].values()[c] += kShadowDepth;
  return depths;
}

Rgb surface_direct(const std::vector<Light>& lights, const std::vector<Surface>& surfaces, const DenseGrid& density,
                   const std::vector<DenseGrid>& depths, const Rgb& sigma_t, const Surface& surface, const Vec3& p, const Vec3& n,
                   const Vec3& wo) {
  Rgb sum(0.0);
  LightArrival a;
  for (size_t l = 0; l < lights.size(); ++l) {
    if (!arrival(lights[l], p, a)) continue;
    const double cos_i = glm::dot(n, a.to_light);
    if (cos_i <= 0.0 || occluded(surfaces, p, a.to_light, a.distance)) continue;
    const double reach = std::isfinite(a.distance) ? a.distance : 1e30;
    // The depth volume only strictly inside the grid, the exact walk on its faces: a floor on the
    // grid's bottom face was in or out by rounding (and in, read at the face; out, as 0 when the
    // volume's own bounds refused it), pixel by pixel, up to 2x apart.
    const bool inside = density.bounds().contains(off_surface(p, -n)) && density.bounds().contains(off_surface(p, n));
    const double depth = inside ? static_cast<double>(sample_trilinear(depths[l], p)) : density_integral_dda(density, p, p + a.to_light * reach);
    sum += surface.brdf(a.to_light, wo, n) * a.irradiance * cos_i * glm::exp(-sigma_t * depth);
  }
  return sum;
}

}  // namespace haze::grids
