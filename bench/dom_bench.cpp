// Method "dom" (seed 000) on this machine: one transport sweep (SIMD kernel against its scalar
// reference), a converged solution at albedo 0.9 (GMRES against plain source iteration), and the
// default scheme against the paper's with the full matrix, to the same tolerance.
// Run: build/release/bench/haze_bench_dom --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// Counters: sweep_ms (per transport sweep), grind_ns (per cell, direction and sweep), GBps (moment
// traffic: each octant pass reads m_in and reads and writes m_out, 12 N bytes per cell), MB (the
// solver's memory estimate, dom_memory_bytes).
#include <haze/core/rng.h>
#include <haze/grids/dom.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/rbf.h>

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

using namespace haze;
using namespace haze::grids;

// A grey cloud of 64 blobs in [-1, 1]^3 (optical depth through its middle about 10), HG g = 0.5,
// lit by a point light and a sun.
struct Problem {
  ExtinctionVolume volume;
  std::vector<Light> lights{PointLight{Vec3(0.9, 0.8, 0.3), Rgb(4.0)}, DirectionalLight{glm::normalize(Vec3(0.3, -1.0, 0.2)), Rgb(1.0)}};
  std::vector<DenseGrid> depths;

  Problem(int n, double albedo)
      : volume{DenseGrid({n, n, n}, {Vec3(-1.0), Vec3(1.0)}), Rgb(5.0), Rgb(albedo), PhaseFunction::henyey_greenstein(0.5)} {
    Rng rng(5);
    std::vector<RbfBlob> blobs;
    for (int i = 0; i < 64; ++i) {
      const Vec3 c(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
      blobs.push_back({1.2 * c, 0.4 + 0.6 * rng.uniform(), 3.0 + 2.0 * rng.uniform()});
    }
    inject_rbf(blobs, volume.density);
    for (const Light& l : lights) depths.push_back(optical_depth(volume.density, l, {DepthScheme::exact}));
  }
};

void report(benchmark::State& state, const DomSolution& s, size_t cells, int directions) {
  const double per_sweep = s.sweep_seconds / s.iterations;
  state.counters["sweeps"] = s.iterations;
  state.counters["sweep_ms"] = 1e3 * per_sweep;
  state.counters["grind_ns"] = 1e9 * per_sweep / (static_cast<double>(cells) * directions);
  state.counters["GBps"] = 8.0 * 12.0 * s.terms() * static_cast<double>(cells) / per_sweep / 1e9;
  state.counters["solve_ms"] = 1e3 * s.seconds;
  state.counters["MB"] = static_cast<double>(s.bytes) / 1e6;
}

// Args: cells per side, directions, terms, scalar kernel, spatial scheme (0 step, 1 diamond).
// Four source iterations.
void BM_Sweep(benchmark::State& state) {
  const Problem p(static_cast<int>(state.range(0)), 0.9);
  DomSettings settings;
  settings.directions = static_cast<int>(state.range(1));
  settings.terms = static_cast<int>(state.range(2));
  settings.scalar_kernel = state.range(3) != 0;
  settings.spatial = state.range(4) ? DomSpatial::diamond : DomSpatial::step;
  settings.accelerator = DomAccelerator::none;
  settings.max_iterations = 4;
  settings.tolerance = 1e-12;
  DomSolution s;
  for (auto _ : state) s = solve_dom(p.volume, p.lights, p.depths, settings);
  report(state, s, p.volume.density.cell_count(), settings.directions);
}
BENCHMARK(BM_Sweep)->Name("dom/sweep/cells,directions,terms,scalar,diamond")->Args({64, 128, 24, 0, 1})->Args({64, 128, 24, 1, 1})
    ->Args({64, 128, 24, 0, 0})->Args({64, 128, 24, 1, 0})->Args({64, 256, 24, 0, 1})->Args({64, 128, 48, 0, 1})->Args({32, 128, 24, 0, 1})
    ->UseRealTime()->Unit(benchmark::kMillisecond);

// Args: cells per side, albedo in percent, accelerator (0 none, 1 gmres), storage (0 float32, 1
// float16). To a change below 1e-3.
void BM_Converge(benchmark::State& state) {
  const Problem p(static_cast<int>(state.range(0)), state.range(1) / 100.0);
  DomSettings settings;
  settings.accelerator = state.range(2) ? DomAccelerator::gmres : DomAccelerator::none;
  settings.storage = state.range(3) ? DomStorage::float16 : DomStorage::float32;
  DomSolution s;
  for (auto _ : state) s = solve_dom(p.volume, p.lights, p.depths, settings);
  report(state, s, p.volume.density.cell_count(), settings.directions);
  state.counters["converged"] = s.converged;
}
BENCHMARK(BM_Converge)->Name("dom/converge/cells,albedo%,gmres,float16")->Args({64, 90, 1, 0})->Args({64, 90, 1, 1})->Args({64, 90, 0, 0})
    ->Args({64, 99, 1, 0})->Args({64, 99, 1, 1})->Args({64, 99, 0, 0})->Args({64, 50, 1, 0})->Iterations(1)->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// The default iteration (sweep, GMRES, N = 25, delta-M) against the paper's (Jacobi, full matrix) on
// 32^3 with 128 directions at albedo 0.9, to a change below 10^-tolerance_exp; `error` is the
// relative L2 distance of the scalar flux (moment 0, unaffected by delta-M's phase split only up
// to its f) from a tight (1e-7) full-matrix solution. All with the step spatial scheme, the
// paper's only one.
void BM_Schemes(benchmark::State& state) {
  static const Problem p(32, 0.9);
  static const DomSolution truth = [] {
    DomSettings s;
    s.spatial = DomSpatial::step;
    s.terms = 0;
    s.tolerance = 1e-7;
    return solve_dom(p.volume, p.lights, p.depths, s);
  }();
  DomSettings settings;
  settings.spatial = DomSpatial::step;
  const bool paper = state.range(0) != 0;
  settings.tolerance = std::pow(10.0, -static_cast<double>(state.range(1)));
  if (paper) settings.scheme = DomScheme::paper, settings.terms = 0, settings.max_iterations = 5000;
  DomSolution s;
  for (auto _ : state) s = solve_dom(p.volume, p.lights, p.depths, settings);
  double diff = 0.0, ref = 0.0;
  const auto nt = static_cast<size_t>(truth.terms()), ns = static_cast<size_t>(s.terms());
  for (size_t c = 0; c < p.volume.density.cell_count(); ++c) {
    const double a = s.moments[0][c * ns], b = truth.moments[0][c * nt];
    diff += (a - b) * (a - b), ref += b * b;
  }
  report(state, s, p.volume.density.cell_count(), settings.directions);
  state.counters["error"] = std::sqrt(diff / ref);
}
BENCHMARK(BM_Schemes)->Name("dom/schemes/paper_full_matrix,tolerance_exp")->Args({0, 3})->Args({1, 3})->Args({1, 4})->Args({1, 5})->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
