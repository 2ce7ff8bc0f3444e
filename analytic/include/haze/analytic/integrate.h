// Adaptive Gauss-Kronrod quadrature (G7-K15, bisection on the worst interval) in float64: the
// yardstick the analytic methods and their tables are measured against.
#pragma once

#include <functional>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

struct IntegrationResult {
  double value = 0.0;
  double error = 0.0;  // estimated absolute error (|K15 - G7| summed over intervals)
  int evaluations = 0;
};

// integral_a^b f(x) dx to max(rel_tol * |value|, abs_tol), at most max_intervals subintervals.
IntegrationResult integrate_adaptive(const std::function<double(double)>& f, double a, double b, double rel_tol = 1e-10,
                                     double abs_tol = 0.0, int max_intervals = 4096);

// The same for a vector-valued integrand f(x, out) writing `dims` values: every component shares
// the nodes, and the interval with the largest error in any component is split next.
std::vector<double> integrate_adaptive_vector(const std::function<void(double, double*)>& f, int dims, double a, double b,
                                              double rel_tol = 1e-10, int max_intervals = 4096);

// The same with the integrand called once per Gauss-Kronrod panel: f(x, count, out) writes
// out[q * dims + d] for the `count` nodes x[q], so it can vectorize across nodes.
std::vector<double> integrate_adaptive_nodes(const std::function<void(const double*, int, double*)>& f, int dims, double a,
                                             double b, double rel_tol = 1e-10, int max_intervals = 4096);

}  // namespace haze::analytic

#pragma GCC visibility pop
