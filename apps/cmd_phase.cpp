// haze phase: the discrete phase matrix and its separable factorization report (seed 000 fig. 3).
#include "commands.h"

#include <haze/core/error.h>
#include <haze/core/phase_matrix.h>

#include <nlohmann/json.hpp>

#include <iomanip>
#include <iostream>

namespace haze::app {

namespace {

struct PhaseArgs {
  std::string phase = "hg", directions = "fibonacci";
  double g = 0.5, g2 = -0.3, w = 0.7;
  int dirs = 128, terms = 24;
  std::uint64_t seed = 1;
  bool json = false;
};

PhaseFunction make_phase(const PhaseArgs& a) {
  if (a.phase == "isotropic") return PhaseFunction::isotropic();
  if (a.phase == "rayleigh") return PhaseFunction::rayleigh();
  if (a.phase == "hg") return PhaseFunction::henyey_greenstein(a.g);
  if (a.phase == "cornette_shanks") return PhaseFunction::cornette_shanks(a.g);
  if (a.phase == "double_hg") return PhaseFunction::double_hg(a.g, a.g2, a.w);
  throw Error("--phase", a.phase, "isotropic, rayleigh, hg, cornette_shanks or double_hg");
}

int run(const PhaseArgs& a) {
  PhaseFunction phase = make_phase(a);
  DirectionSet dirs = a.directions == "fibonacci" ? DirectionSet::fibonacci(a.dirs)
                      : a.directions == "random"  ? DirectionSet::uniform_random(a.dirs, a.seed)
                                                  : throw Error("--directions", a.directions, "fibonacci or random");
  PhaseMatrix matrix(phase, dirs);
  SeparablePhase separable(matrix, a.terms);
  auto factors = matrix.renormalization_factors();

  nlohmann::json out;
  out["phase"] = phase.name();
  out["mean_cosine"] = phase.mean_cosine();
  out["directions"] = {{"type", a.directions}, {"count", a.dirs}};
  out["terms"] = a.terms;
  out["relative_error"] = separable.relative_error();
  out["rmse"] = separable.rmse();
  out["renormalization"] = {{"min", factors.minCoeff()}, {"max", factors.maxCoeff()}};
  out["eigenvalues"] = std::vector<double>(separable.eigenvalues().data(), separable.eigenvalues().data() + a.terms);
  if (phase.type() == PhaseType::henyey_greenstein) {
    // Eigenvalues come in groups of 2l + 1 (spherical harmonics): N terms hold floor(sqrt(N)) full
    // Legendre orders, whose continuous truncation error is the yardstick for the discrete one.
    int orders = static_cast<int>(std::floor(std::sqrt(static_cast<double>(a.terms))));
    out["legendre"] = {{"orders", orders}, {"truncation_error", hg_legendre_truncation_error(a.g, orders)}};
  }
  if (a.json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::cout << std::setprecision(6);
  std::cout << "phase " << out["phase"].get<std::string>() << ", mean cosine " << phase.mean_cosine() << ", "
            << a.dirs << " " << a.directions << " directions, " << a.terms << " separable terms\n";
  std::cout << "relative Frobenius error " << separable.relative_error() << "\n";
  std::cout << "RMSE                     " << separable.rmse() << "\n";
  std::cout << "row renormalization      [" << factors.minCoeff() << ", " << factors.maxCoeff() << "]\n";
  if (out.contains("legendre"))
    std::cout << "HG Legendre truncation   " << out["legendre"]["truncation_error"].get<double>() << " (relative L2, "
              << out["legendre"]["orders"].get<int>() << " orders)\n";
  std::cout << "eigenvalues:";
  for (int k = 0; k < a.terms; ++k) std::cout << (k % 8 ? " " : "\n  ") << separable.eigenvalues()(k);
  std::cout << "\n";
  return 0;
}

}  // namespace

Command add_phase(CLI::App& app) {
  auto* sub = app.add_subcommand("phase", "Discrete phase matrix and its separable (eigen) factorization report");
  auto a = std::make_shared<PhaseArgs>();
  sub->add_option("--phase", a->phase, "isotropic, rayleigh, hg, cornette_shanks, double_hg")->capture_default_str();
  sub->add_option("--g", a->g, "Asymmetry g (hg, cornette_shanks; first lobe of double_hg)")->capture_default_str();
  sub->add_option("--g2", a->g2, "Second lobe of double_hg")->capture_default_str();
  sub->add_option("--w", a->w, "Weight of the first double_hg lobe")->capture_default_str();
  sub->add_option("--dirs", a->dirs, "Number of discrete directions D")->capture_default_str();
  sub->add_option("--terms", a->terms, "Separable terms N kept")->capture_default_str();
  sub->add_option("--directions", a->directions, "fibonacci or random")->capture_default_str();
  sub->add_option("--seed", a->seed, "Seed for random directions")->capture_default_str();
  sub->add_flag("--json", a->json, "Print JSON");
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
