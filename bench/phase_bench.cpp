// Phase evaluation (SIMD vs scalar reference) and in-scattering with the full phase matrix vs its
// separable factorization. Run: build/release/bench/haze_bench_core --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true; compare medians of the same run.
#include <haze/core/phase_matrix.h>
#include <haze/simd/phase_batch.h>

#include <benchmark/benchmark.h>

namespace {

std::vector<float> cosines(size_t n) {
  std::vector<float> mu(n);
  for (size_t i = 0; i < n; ++i) mu[i] = -1.0f + 2.0f * static_cast<float>(i) / static_cast<float>(n - 1);
  return mu;
}

template <bool kSimd>
void BM_PhaseEval(benchmark::State& state) {
  auto phase = haze::PhaseFunction::henyey_greenstein(0.7);
  const auto n = static_cast<size_t>(state.range(0));
  auto mu = cosines(n);
  std::vector<float> out(n);
  for (auto _ : state) {
    if constexpr (kSimd) {
      haze::simd::eval_phase(phase, mu.data(), out.data(), n);
    } else {
      haze::simd::eval_phase_reference(phase, mu.data(), out.data(), n);
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(n));
  state.SetLabel(kSimd ? haze::simd::selected_target() : "scalar float64");
}
BENCHMARK(BM_PhaseEval<true>)->Name("phase_eval/hg/simd")->Arg(4096);
BENCHMARK(BM_PhaseEval<false>)->Name("phase_eval/hg/scalar")->Arg(4096);

// One cell's in-scattering over D directions: O(D^2) matrix product vs O(D N) separable terms.
void BM_InScatter(benchmark::State& state) {
  const int dirs = static_cast<int>(state.range(0)), terms = static_cast<int>(state.range(1));
  haze::PhaseMatrix matrix(haze::PhaseFunction::henyey_greenstein(0.5), haze::DirectionSet::fibonacci(dirs));
  haze::SeparablePhase separable(matrix, terms > 0 ? terms : dirs);
  Eigen::VectorXd radiance = Eigen::VectorXd::Random(dirs).cwiseAbs(), out(dirs);
  for (auto _ : state) {
    out.noalias() = terms > 0 ? separable.apply(radiance) : matrix.apply(radiance);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
  state.SetLabel(terms > 0 ? "separable, rel. error " + std::to_string(separable.relative_error()) : "full matrix");
}
BENCHMARK(BM_InScatter)->Name("in_scatter/full")->Args({128, 0})->Args({256, 0});
BENCHMARK(BM_InScatter)->Name("in_scatter/separable")->Args({128, 24})->Args({256, 24})->Args({256, 49});

}  // namespace
