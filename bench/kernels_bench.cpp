// Every SIMD kernel on every Highway target this build carries, beside its scalar reference, and a
// STREAM-like copy and triad that measure the machine's memory bandwidth in the same run (1 and 2
// threads). With --markdown FILE it writes docs/PERFORMANCE.md's tables (scripts/perf).
// Run: build/dev/bench/haze_bench_kernels --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <haze/core/phase.h>
#include <haze/grids/dom.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>
#include <haze/grids/dom_sweep.h>
#include <haze/simd/half.h>
#include <haze/grids/march_rays.h>
#include <haze/simd/phase_batch.h>
#include <haze/grids/sweep_cells.h>

#include <benchmark/benchmark.h>
#include <hwy/targets.h>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace haze;

// ---- STREAM (McCalpin): copy a[i] = b[i] and triad a[i] = b[i] + s c[i] over 3 x 128 MB arrays.
constexpr size_t kStream = size_t{32} << 20;  // floats per array

void BM_Stream(benchmark::State& state) {
  const bool triad = state.range(0) == 1;
  const int threads = static_cast<int>(state.range(1));
  static std::vector<float> a(kStream, 1.0f), b(kStream, 2.0f), c(kStream, 3.0f);
  tbb::task_arena arena(threads);
  const size_t chunk = kStream / 64;
  for (auto _ : state) {
    arena.execute([&] {
      tbb::parallel_for(size_t{0}, size_t{64}, [&](size_t part) {
        float* __restrict out = a.data() + part * chunk;
        const float* __restrict x = b.data() + part * chunk;
        const float* __restrict y = c.data() + part * chunk;
        if (triad) {
          for (size_t i = 0; i < chunk; ++i) out[i] = x[i] + 3.0f * y[i];
        } else {
          std::memcpy(out, x, chunk * sizeof(float));
        }
      });
    });
    benchmark::DoNotOptimize(a.data());
  }
  // STREAM's convention: copy moves 2 arrays, triad 3 (read, read, write).
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * kStream * sizeof(float) * (triad ? 3 : 2)));
  state.SetLabel(std::to_string(threads) + " thread" + (threads > 1 ? "s" : ""));
}
BENCHMARK(BM_Stream)->Name("stream/copy")->Args({0, 1})->Args({0, 2})->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Stream)->Name("stream/triad")->Args({1, 1})->Args({1, 2})->UseRealTime()->Unit(benchmark::kMillisecond);

// ---- FMA peak: 12 independent chains of 8-lane AVX2 FMAs per thread (2 pipes x 4 cycles of
// latency need 8), on 1 and 2 threads (items: floating-point operations, 2 per lane and FMA). The
// yardstick for the DOM sweep's share of peak arithmetic (write_markdown's grind-time table).
#if defined(__x86_64__)
constexpr size_t kFmaRounds = size_t{1} << 22;

__attribute__((target("avx2,fma"))) float fma_chains(float seed) {
  const __m256 b = _mm256_set1_ps(0.999999f), c = _mm256_set1_ps(1e-7f);
  // Twelve different starting values: equal ones would let the compiler fold the chains into one.
  const __m256 step = _mm256_set1_ps(0.01f);
  __m256 a0 = _mm256_set1_ps(seed), a1 = _mm256_add_ps(a0, step), a2 = _mm256_add_ps(a1, step), a3 = _mm256_add_ps(a2, step);
  __m256 a4 = _mm256_add_ps(a3, step), a5 = _mm256_add_ps(a4, step), a6 = _mm256_add_ps(a5, step), a7 = _mm256_add_ps(a6, step);
  __m256 a8 = _mm256_add_ps(a7, step), a9 = _mm256_add_ps(a8, step), a10 = _mm256_add_ps(a9, step), a11 = _mm256_add_ps(a10, step);
  for (size_t r = 0; r < kFmaRounds; ++r) {
    a0 = _mm256_fmadd_ps(a0, b, c), a1 = _mm256_fmadd_ps(a1, b, c), a2 = _mm256_fmadd_ps(a2, b, c), a3 = _mm256_fmadd_ps(a3, b, c);
    a4 = _mm256_fmadd_ps(a4, b, c), a5 = _mm256_fmadd_ps(a5, b, c), a6 = _mm256_fmadd_ps(a6, b, c), a7 = _mm256_fmadd_ps(a7, b, c);
    a8 = _mm256_fmadd_ps(a8, b, c), a9 = _mm256_fmadd_ps(a9, b, c), a10 = _mm256_fmadd_ps(a10, b, c), a11 = _mm256_fmadd_ps(a11, b, c);
  }
  const __m256 s = _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(a0, a1), _mm256_add_ps(a2, a3)),
                                 _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(a4, a5), _mm256_add_ps(a6, a7)),
                                               _mm256_add_ps(_mm256_add_ps(a8, a9), _mm256_add_ps(a10, a11))));
  return _mm_cvtss_f32(_mm256_castps256_ps128(s));
}

void BM_FmaPeak(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  tbb::task_arena arena(threads);
  std::vector<float> out(static_cast<size_t>(threads));
  for (auto _ : state) {
    arena.execute([&] { tbb::parallel_for(0, threads, [&](int t) { out[static_cast<size_t>(t)] = fma_chains(1.0f + 0.01f * static_cast<float>(t)); }); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * threads * static_cast<int64_t>(kFmaRounds) * 12 * 8 * 2);
  state.SetLabel(std::to_string(threads) + " thread" + (threads > 1 ? "s" : ""));
}
#endif

// ---- Kernels. Each is registered once per compiled target (the dispatch forced to it) and once
// as its scalar reference. The kernel reports its own items and bytes per call.
struct Work {
  std::function<void()> run;
  double items = 0.0, bytes = 0.0;  // per call; bytes only for memory-bound kernels
  std::vector<std::shared_ptr<void>> keep = {};  // buffers the kernel's views point into
};

std::string target_name(int64_t target) { return hwy::TargetName(target); }

void register_kernel(const std::string& name, const std::function<Work(bool scalar)>& make, bool has_scalar = true) {
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  auto body = [make](benchmark::State& state, int64_t target) {
    if (target != 0) {
      hwy::SetSupportedTargetsForTest(target);
      hwy::GetChosenTarget().Update(hwy::SupportedTargets());
    }
    Work work = make(target == 0);
    for (auto _ : state) work.run();
    hwy::SetSupportedTargetsForTest(0);
    hwy::GetChosenTarget().Update(hwy::SupportedTargets());
    state.SetItemsProcessed(static_cast<int64_t>(static_cast<double>(state.iterations()) * work.items));
    if (work.bytes > 0.0) state.SetBytesProcessed(static_cast<int64_t>(static_cast<double>(state.iterations()) * work.bytes));
    state.SetLabel(target == 0 ? "scalar reference" : target_name(target));
  };
  for (int64_t t : targets) benchmark::RegisterBenchmark((name + "/" + target_name(t)).c_str(), body, t)->UseRealTime();
  if (has_scalar) benchmark::RegisterBenchmark((name + "/scalar").c_str(), body, int64_t{0})->UseRealTime();
}

// HG phase at 4096 cosines (compute-bound: a division, a square root per value).
Work phase_work(bool scalar) {
  auto mu = std::make_shared<std::vector<float>>(4096), out = std::make_shared<std::vector<float>>(4096);
  for (size_t i = 0; i < mu->size(); ++i) (*mu)[i] = -1.0f + 2.0f * static_cast<float>(i) / 4095.0f;
  const PhaseFunction phase = PhaseFunction::henyey_greenstein(0.7);
  return {[=] {
            scalar ? simd::eval_phase_reference(phase, mu->data(), out->data(), mu->size()) : simd::eval_phase(phase, mu->data(), out->data(), mu->size());
            benchmark::DoNotOptimize(out->data());
          },
          4096.0, 0.0};
}

// float32 -> float16 over 16M values (memory-bound: 4 bytes read, 2 written per value).
Work half_work(bool scalar) {
  const size_t n = size_t{16} << 20;
  auto from = std::make_shared<std::vector<float>>(n, 0.37f);
  auto to = std::make_shared<std::vector<simd::Half>>(n);
  return {[=] {
            scalar ? simd::to_half_reference(from->data(), to->data(), n) : simd::to_half(from->data(), to->data(), n);
            benchmark::DoNotOptimize(to->data());
          },
          static_cast<double>(n), 6.0 * static_cast<double>(n)};
}

// A 64^3 cloud-like density.
std::shared_ptr<std::vector<float>> density64() {
  auto d = std::make_shared<std::vector<float>>(64 * 64 * 64);
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        const double x = (i - 31.5) / 32.0, y = (j - 31.5) / 32.0, z = (k - 31.5) / 32.0;
        (*d)[static_cast<size_t>((k * 64 + j) * 64 + i)] = static_cast<float>(std::exp(-3.0 * (x * x + y * y + z * z)) * (1.0 + 0.3 * std::sin(7.0 * x + 5.0 * y)));
      }
  return d;
}

// The optical-depth sweep for a directional light over every x-row of 64^3 cells, in order.
Work sweep_work(bool scalar) {
  auto density = density64();
  auto depth = std::make_shared<std::vector<float>>(density->size()), mean = std::make_shared<std::vector<float>>(density->size());
  auto v = std::make_shared<grids::SweepVolume>();
  for (int e = 0; e < 3; ++e) v->n[e] = 64, v->lo[e] = -1.0f, v->h[e] = 2.0f / 64.0f;
  v->density = density->data(), v->mean = mean->data(), v->directional = true;
  const float to_light[3] = {0.3f, 0.9f, 0.3f};
  const float norm = std::sqrt(0.99f);
  for (int e = 0; e < 3; ++e) v->light[e] = to_light[e] / norm;
  return {[=] {
            for (int layer = 63; layer >= 0; --layer)  // y is the dominant axis toward the light
              for (int k = 0; k < 64; ++k) {
                const size_t at = static_cast<size_t>((k * 64 + layer) * 64);
                (scalar ? grids::sweep_cells_reference : grids::sweep_cells)(*v, 0, layer, k, 0, 64, depth->data() + at, mean->data() + at);
              }
            benchmark::DoNotOptimize(depth->data());
          },
          64.0 * 64.0 * 64.0, 0.0, {density}};
}

// 256 rays through the 64^3 volume, 2 point lights, step half a cell (items: ray steps).
Work march_work(bool scalar) {
  auto density = density64();
  auto depths = std::make_shared<std::vector<float>>(2 * density->size(), 0.5f);
  auto lights = std::make_shared<std::vector<grids::MarchLight>>(2);
  (*lights)[0].position[0] = 1.5f, (*lights)[1].position[1] = 1.5f;
  auto v = std::make_shared<grids::MarchVolume>();
  for (int e = 0; e < 3; ++e) v->n[e] = 64, v->lo[e] = -1.0f, v->h[e] = 2.0f / 64.0f;
  v->density = density->data(), v->depths = depths->data(), v->lights = lights->data(), v->light_count = 2;
  const size_t n = 256;
  auto in = std::make_shared<std::vector<float>>(9 * n), out = std::make_shared<std::vector<float>>(6 * n);
  for (size_t r = 0; r < n; ++r) {
    const float y = -0.9f + 1.8f * static_cast<float>(r) / static_cast<float>(n);
    const float values[9] = {-3.0f, y, 0.1f, 1.0f, 0.0f, 0.0f, 2.0f, 1.0f / 64.0f, 128.0f};
    for (size_t a = 0; a < 9; ++a) (*in)[a * n + r] = values[a];
  }
  auto row = [](std::vector<float>& b, size_t a, size_t count) { return b.data() + a * count; };
  auto packet = std::make_shared<grids::RayPacket>(grids::RayPacket{row(*in, 0, n), row(*in, 1, n), row(*in, 2, n), row(*in, 3, n), row(*in, 4, n),
                                                                   row(*in, 5, n), row(*in, 6, n), row(*in, 7, n), row(*in, 8, n), n,
                                                                   {row(*out, 0, n), row(*out, 1, n), row(*out, 2, n)},
                                                                   {row(*out, 3, n), row(*out, 4, n), row(*out, 5, n)}});
  const PhaseFunction phase = PhaseFunction::henyey_greenstein(0.4);
  (void)scalar;  // its reference is the float64 marcher in grids (MarchSettings::scalar), not a kernel
  return {[=] {
            grids::march_rays(*v, phase, *packet);
            benchmark::DoNotOptimize(out->data());
          },
          128.0 * static_cast<double>(n), 0.0, {density, depths, lights, in}};
}

// One DOM row of 64 cells, one octant of p directions (16: D = 128; 8: D = 64) and `terms` terms, by
// one spatial scheme (items: cell-directions); the diamond's cells unmarked by its fix-up (alpha(tau)
// alone, most cells of a solve).
Work dom_work(bool scalar, bool diamond, int p, int terms) {
  const int padded = (terms + 7) / 8 * 8, count = 64;
  auto a = std::make_shared<std::vector<float>>(5 * p, 0.0f), lq = std::make_shared<std::vector<float>>(static_cast<size_t>(terms * p)),
       q = std::make_shared<std::vector<float>>(static_cast<size_t>(p * padded), 0.0f);
  for (int d = 0; d < p; ++d) {
    float sum = 0.0f;
    for (int e = 0; e < 3; ++e) sum += (*a)[static_cast<size_t>(e * p + d)] = 10.0f + static_cast<float>((d + e) % 5);
    (*a)[static_cast<size_t>(3 * p + d)] = sum;
    for (int k = 0; k < terms; ++k) {
      (*lq)[static_cast<size_t>(k * p + d)] = 0.01f * static_cast<float>((k + d) % 7);
      (*q)[static_cast<size_t>(d * padded + k)] = 0.02f * static_cast<float>((k * d) % 5);
    }
  }
  auto octant = std::make_shared<grids::DomOctant>(grids::DomOctant{p, terms, padded, a->data(), lq->data(), q->data(), diamond});
  auto density = std::make_shared<std::vector<float>>(count, 1.0f), first = std::make_shared<std::vector<float>>(static_cast<size_t>(count * p), 0.1f);
  auto m_in = std::make_shared<std::vector<float>>(static_cast<size_t>(count * terms), 0.05f),
       m_out = std::make_shared<std::vector<float>>(static_cast<size_t>(count * terms));
  auto x = std::make_shared<std::vector<float>>(p), y = std::make_shared<std::vector<float>>(static_cast<size_t>(count * p)),
       z = std::make_shared<std::vector<float>>(static_cast<size_t>(count * p)), scratch = std::make_shared<std::vector<float>>(4 * p + padded);
  auto marks = std::make_shared<std::vector<std::uint8_t>>(8 * count, 0);
  auto row = std::make_shared<grids::DomRow>();
  row->count = count, row->density = density->data(), row->sigma_t_scale = 2.0f, row->albedo = 0.9f;
  row->first = first->data(), row->first_stride = static_cast<size_t>(p), row->m_in = m_in->data(), row->m_out = m_out->data();
  row->x_run = x->data(), row->y_row = y->data(), row->z_row = z->data(), row->scratch = scratch->data();
  row->bounded = marks->data();
  return {[=] {
            (scalar ? grids::dom_sweep_row_reference : grids::dom_sweep_row)(*octant, *row);
            benchmark::DoNotOptimize(m_out->data());
          },
          static_cast<double>(count * p), 0.0, {a, lq, q, density, first, m_in, x, y, z, scratch, marks}};
}

// ---- Solver steps at 1 and 2 threads, on the 64^3 density with 2 point lights and the sun.
struct Solver {
  Scene scene;
  grids::ExtinctionVolume volume{grids::DenseGrid({64, 64, 64}, {Vec3(-1.0), Vec3(1.0)}), Rgb(4.0), Rgb(0.9), PhaseFunction::henyey_greenstein(0.5)};
  std::vector<grids::DenseGrid> depths;
  Solver() {
    volume.density.values() = *density64();
    scene.camera.position = Vec3(0.3, 0.4, 3.5);
    scene.camera.width_px = scene.camera.height_px = 256;
    scene.lights = {PointLight{Vec3(1.5, 0.5, 0.2), Rgb(3.0)}, PointLight{Vec3(-0.4, 1.6, 0.9), Rgb(2.0)},
                    DirectionalLight{glm::normalize(Vec3(0.3, -0.9, -0.3)), Rgb(1.0)}};
    depths = grids::optical_depths(volume.density, scene.lights);
  }
};
const Solver& solver() {
  static const Solver s;
  return s;
}

// The three lights' optical-depth volumes by the SIMD sweep (items: cells x lights).
void BM_OpticalDepths(benchmark::State& state) {
  grids::DepthOptions options;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(grids::optical_depths(solver().volume.density, solver().scene.lights, options));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * 64 * 64 * 64 * 3);
  state.SetLabel(std::to_string(options.threads) + " thread" + (options.threads > 1 ? "s" : ""));
}
BENCHMARK(BM_OpticalDepths)->Name("solver/optical_depths_64^3_3_lights")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

// The SIMD ray march of a 256 x 256 image through the same fields (items: pixels).
void BM_MarchImage(benchmark::State& state) {
  RenderOptions options;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(grids::march_image(solver().scene, solver().volume, solver().depths, {}, options));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * 256 * 256);
  state.SetLabel(std::to_string(options.threads) + " thread" + (options.threads > 1 ? "s" : ""));
}
BENCHMARK(BM_MarchImage)->Name("solver/march_image_256^2")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

// The 64^3 density at 32^3; with `empty`, cells outside the inscribed ball (48% of them) are
// empty: at density 0 (the sweep skips those no radiance reaches yet) or, with `empty` 2, at
// 1e-30 (the same answer, nothing skipped).
grids::ExtinctionVolume coarse_volume(int empty) {
  grids::ExtinctionVolume v = solver().volume;
  v.density = grids::DenseGrid({32, 32, 32}, v.density.bounds());
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i) {
        const bool outside = glm::length(v.density.cell_center(i, j, k)) > 1.0;
        v.density.at(i, j, k) = empty && outside ? (empty == 1 ? 0.0f : 1e-30f) : solver().volume.density.at(2 * i, 2 * j, 2 * k);
      }
  return v;
}

// Ten DOM source iterations on a 32^3 grid, 128 directions, 25 terms (items: cell-directions
// swept); the second argument picks coarse_volume's empty cells.
void BM_DomIterations(benchmark::State& state) {
  static const grids::ExtinctionVolume volumes[3] = {coarse_volume(0), coarse_volume(1), coarse_volume(2)};
  const grids::ExtinctionVolume& coarse = volumes[state.range(1)];
  const std::vector<grids::DenseGrid> depths = grids::optical_depths(coarse.density, solver().scene.lights);
  grids::DomSettings settings;
  settings.threads = static_cast<int>(state.range(0));
  settings.accelerator = grids::DomAccelerator::none;
  settings.max_iterations = 10;
  settings.tolerance = 1e-9;
  double skipped = 0.0;
  for (auto _ : state) {
    const grids::DomSolution solution = grids::solve_dom(coarse, solver().scene.lights, depths, settings);
    skipped = solution.skipped_fraction;
    benchmark::DoNotOptimize(solution.moments.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * 32 * 32 * 32 * 128 * 10);
  const char* empty[3] = {"", ", empty outside the ball", ", empty outside the ball at 1e-30"};
  char label[160];
  std::snprintf(label, sizeof label, "%d thread%s, phase matrix and first collision included%s, %.0f%% of cell visits skipped", settings.threads,
                settings.threads > 1 ? "s" : "", empty[state.range(1)], 100.0 * skipped);
  state.SetLabel(label);
}
BENCHMARK(BM_DomIterations)
    ->Name("solver/dom_10_iterations_32^3_D128")
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Args({2, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// ---- --markdown: the medians (or single runs) as tables.
class Collector : public benchmark::ConsoleReporter {
 public:
  struct Entry {
    std::string name, label;
    double seconds = 0.0, items = 0.0, bytes = 0.0;
  };
  std::vector<Entry> entries;
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median") continue;
      Entry e{r.run_name.function_name + (r.run_name.args.empty() ? "" : "/" + r.run_name.args), r.report_label,
              r.GetAdjustedRealTime() * 1e-9 * (r.time_unit == benchmark::kMillisecond ? 1e6 : r.time_unit == benchmark::kMicrosecond ? 1e3 : 1.0)};
      if (auto it = r.counters.find("items_per_second"); it != r.counters.end()) e.items = it->second.value;
      if (auto it = r.counters.find("bytes_per_second"); it != r.counters.end()) e.bytes = it->second.value;
      entries.push_back(e);
    }
  }
};

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

// The DOM sweep's grind time (ns per cell-direction and sweep), the arithmetic its 2 N FMAs per
// cell-direction do (source and moments, N terms, as a row's name says, else 25: 4 N flops; the
// transport's few operations, the diamond's weights and its reciprocals are not counted) against the fma/ peak at the same
// threads, and, for the whole-solver rows, the memory it moves against STREAM copy: per cell and
// octant pass the moments in and out (12 N bytes) and the density (4), per cell-direction the
// first-collision source (4), with D = 128.
void write_grind_times(std::ofstream& md, const std::vector<Collector::Entry>& entries, const std::map<int, double>& copy) {
  std::map<int, double> peak;  // threads -> flops/s
  for (const auto& e : entries)
    if (e.name.rfind("fma/", 0) == 0) peak[e.label[0] - '0'] = e.items;
  const double directions = 128.0, bytes = (12.0 * 25.0 + 4.0) * 8.0 / directions + 4.0;
  md << "\n## The DOM sweep's grind time\n\n"
     << "| benchmark | target | ns per cell-direction | GFLOP/s in its FMAs | of FMA peak | GB/s | of STREAM copy |\n|---|---|---|---|---|---|---|\n";
  for (const auto& e : entries) {
    const bool row = e.name.rfind("dom_sweep_row/", 0) == 0, solver = e.name.rfind("solver/dom_", 0) == 0;
    if (!(row || solver) || e.items <= 0.0) continue;
    const int threads = solver ? e.label[0] - '0' : 1;
    const size_t n_at = e.name.find("_N");  // N terms: a row's name says; the solver's are 25
    const double terms = n_at == std::string::npos ? 25.0 : std::stod(e.name.substr(n_at + 2));
    const double gflops = e.items * 4.0 * terms * 1e-9;
    const std::string of_peak = peak.count(threads) ? fmt("%.0f%%", 100.0 * gflops * 1e9 / peak.at(threads)) : "";
    const std::string moved = solver ? fmt("%.1f", e.items * bytes * 1e-9) : "";
    const std::string of_copy = solver && copy.count(threads) ? fmt("%.0f%%", 100.0 * e.items * bytes / copy.at(threads)) : "";
    md << "| " << e.name << " | " << (solver ? e.label.substr(0, e.label.find(',')) : e.label) << " | " << fmt("%.2f", 1e9 / e.items) << " | "
       << fmt("%.1f", gflops) << " | " << of_peak << " | " << moved << " | " << of_copy << " |\n";
  }
}

void write_markdown(const std::string& file, const std::vector<Collector::Entry>& entries) {
  std::map<int, double> copy;  // threads -> bytes/s
  for (const auto& e : entries)
    if (e.name.rfind("stream/copy", 0) == 0) copy[e.label[0] - '0'] = e.bytes;
  std::ofstream md(file);
  md << "| benchmark | target | time per call | throughput | bandwidth | of STREAM copy (1 thread) |\n|---|---|---|---|---|---|\n";
  for (const auto& e : entries) {
    const double t = e.seconds;
    const std::string time = t < 1e-3 ? fmt("%.1f us", t * 1e6) : fmt("%.2f ms", t * 1e3);
    const std::string items = e.items > 0 ? fmt("%.3g items/s", e.items) : "";
    const std::string bytes = e.bytes > 0 ? fmt("%.1f GB/s", e.bytes * 1e-9) : "";
    const std::string share = e.bytes > 0 && copy.count(1) && e.name.rfind("stream", 0) != 0 ? fmt("%.0f%%", 100.0 * e.bytes / copy[1]) : "";
    md << "| " << e.name << " | " << e.label << " | " << time << " | " << items << " | " << bytes << " | " << share << " |\n";
  }
  write_grind_times(md, entries, copy);
}

}  // namespace

int main(int argc, char** argv) {
  std::string markdown;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::string(argv[i]) == "--markdown" && i + 1 < argc) {
      markdown = argv[++i];
      continue;
    }
    args.push_back(argv[i]);
  }
  int count = static_cast<int>(args.size());
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    benchmark::RegisterBenchmark("fma/avx2_peak", BM_FmaPeak)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
#endif
  register_kernel("phase_eval/hg", phase_work);
  register_kernel("to_half", half_work);
  register_kernel("sweep_cells/64^3", sweep_work);
  register_kernel("march_rays/256_rays", march_work, false);
  register_kernel("dom_sweep_row/step/64_cells_P16_N25", [](bool scalar) { return dom_work(scalar, false, 16, 25); });
  register_kernel("dom_sweep_row/diamond/64_cells_P16_N25", [](bool scalar) { return dom_work(scalar, true, 16, 25); });
  register_kernel("dom_sweep_row/diamond/64_cells_P8_N16", [](bool scalar) { return dom_work(scalar, true, 8, 16); });
  benchmark::Initialize(&count, args.data());
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  if (!markdown.empty()) write_markdown(markdown, collector.entries);
  benchmark::Shutdown();
  return 0;
}
