// The analytic airlight's error against adaptive quadrature as a function of table resolution and
// of Legendre orders (docs/ANALYTIC.md). Writes CSV and markdown to the directory given (default
// .); scripts/plot-analytic turns the CSV into docs/analytic_error.png.
// Run: build/release/bench/haze_analytic_accuracy OUT_DIR
#include <haze/analytic/airlight.h>
#include <haze/core/stopwatch.h>
#include <haze/core/rng.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

namespace {

using namespace haze;
using namespace haze::analytic;

struct Errors {
  double worst, median, rms;
};

// The randomized sweep with the extremes (haze::random_airlight_case), as the tests use.
Errors measure(const PhaseFunction& phase, const AirlightTable& table, int n, std::uint64_t seed) {
  Rng rng(seed, 3);
  std::vector<double> errors;
  for (int k = 0; k < n; ++k) {
    auto [m, s] = random_airlight_case(rng, k);
    double exact = airlight_quadrature(phase, m, s, 1e-9);
    errors.push_back(std::abs(table.eval(m, s) - exact) / exact);
  }
  std::sort(errors.begin(), errors.end());
  double sum2 = 0.0;
  for (double e : errors) sum2 += e * e;
  return {errors.back(), errors[errors.size() / 2], std::sqrt(sum2 / static_cast<double>(errors.size()))};
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(out);
  const int samples = 2000;

  std::ofstream res(out / "analytic_resolution.csv");
  res << "a_samples,eta_samples,g,build_seconds,worst,median,rms\n";
  std::printf("| table (a x eta) | g | build (s) | worst | median | RMS |\n|---|---|---|---|---|---|\n");
  for (auto [na, ne] : std::vector<std::pair<int, int>>{{64, 128}, {128, 256}, {256, 512}, {512, 1024}}) {
    for (double g : {0.0, 0.5, 0.95}) {
      PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
      Stopwatch start;
      AirlightTable table(phase, na, ne);
      double build = start.seconds();
      Errors e = measure(phase, table, samples, 11);
      res << na << "," << ne << "," << g << "," << build << "," << e.worst << "," << e.median << "," << e.rms << "\n";
      std::printf("| %d x %d | %.2f | %.2f | %.1e | %.1e | %.1e |\n", na, ne, g, build, e.worst, e.median, e.rms);
    }
  }

  std::ofstream leg(out / "analytic_legendre.csv");
  leg << "g,terms,bound,worst,median,rms\n";
  std::printf("\n| g | Legendre orders | bound | worst | median | RMS |\n|---|---|---|---|---|---|\n");
  Stopwatch start;
  LegendreAirlightTables legendre(48, 256, 512);
  std::printf("(48 Legendre tables of 256 x 512 built in %.2f s)\n", start.seconds());
  for (double g : {0.3, 0.5, 0.7}) {
    PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
    for (int terms : {3, 6, 9, 12, 18, 24, 32, 40, 48}) {
      Errors e = measure(phase, legendre.combine_hg(g, terms), samples / 4, 13);
      double bound = LegendreAirlightTables::truncation_bound(g, terms);
      leg << g << "," << terms << "," << bound << "," << e.worst << "," << e.median << "," << e.rms << "\n";
      std::printf("| %.1f | %d | %.1e | %.1e | %.1e | %.1e |\n", g, terms, bound, e.worst, e.median, e.rms);
    }
  }
  return 0;
}
