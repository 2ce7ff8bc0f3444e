#include <haze/core/error.h>
#include <haze/analytic/integrate.h>

#include <cmath>
#include <queue>
#include <vector>

namespace haze::analytic {

namespace {

// Kronrod nodes (positive half, last is 0) and weights; Gauss weights at the odd Kronrod nodes.
constexpr double kXk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                           0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                           0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                           0.207784955007898467600689403773245, 0.0};
constexpr double kWk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                           0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                           0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                           0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                           0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Interval {
  double a, b, value, error;
  bool operator<(const Interval& o) const { return error < o.error; }
};

Interval gk15(const std::function<double(double)>& f, double a, double b) {
  double c = 0.5 * (a + b), h = 0.5 * (b - a);
  double fc = f(c);
  double kronrod = kWk[7] * fc, gauss = kWg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    double x = h * kXk[j];
    double sum = f(c - x) + f(c + x);
    kronrod += kWk[j] * sum;
    if (j % 2 == 1) gauss += kWg[j / 2] * sum;
  }
  return {a, b, kronrod * h, std::abs((kronrod - gauss) * h)};
}

}  // namespace

IntegrationResult integrate_adaptive(const std::function<double(double)>& f, double a, double b, double rel_tol,
                                     double abs_tol, int max_intervals) {
  if (!(std::isfinite(a) && std::isfinite(b))) throw Error("integration bounds", to_text(a) + ", " + to_text(b), "finite bounds");
  IntegrationResult result;
  if (a == b) return result;
  std::priority_queue<Interval> work;
  work.push(gk15(f, a, b));
  double value = work.top().value, error = work.top().error;
  int intervals = 1;
  while (error > std::max(rel_tol * std::abs(value), abs_tol) && intervals < max_intervals) {
    Interval worst = work.top();
    work.pop();
    double mid = 0.5 * (worst.a + worst.b);
    if (!(mid > worst.a && mid < worst.b)) {  // cannot split further in double precision
      work.push(worst);
      break;
    }
    Interval left = gk15(f, worst.a, mid), right = gk15(f, mid, worst.b);
    value += left.value + right.value - worst.value;
    error += left.error + right.error - worst.error;
    work.push(left);
    work.push(right);
    ++intervals;
  }
  // Re-sum to shed the rounding of the running updates.
  result.value = result.error = 0.0;
  while (!work.empty()) {
    result.value += work.top().value;
    result.error += work.top().error;
    work.pop();
  }
  result.evaluations = 15 * (2 * intervals - 1);
  return result;
}

std::vector<double> integrate_adaptive_vector(const std::function<void(double, double*)>& f, int dims, double a, double b,
                                              double rel_tol, int max_intervals) {
  const auto n = static_cast<size_t>(std::max(dims, 0));
  auto each = [&](const double* x, int count, double* out) {
    for (int q = 0; q < count; ++q) f(x[q], out + static_cast<size_t>(q) * n);
  };
  return integrate_adaptive_nodes(each, dims, a, b, rel_tol, max_intervals);
}

std::vector<double> integrate_adaptive_nodes(const std::function<void(const double*, int, double*)>& f, int dims, double a,
                                             double b, double rel_tol, int max_intervals) {
  if (!(std::isfinite(a) && std::isfinite(b))) throw Error("integration bounds", to_text(a) + ", " + to_text(b), "finite bounds");
  if (dims < 1) throw Error("dims", to_text(dims), "at least 1 component");
  const auto n = static_cast<size_t>(dims);
  struct Piece {
    double a, b, error;
    std::vector<double> value;
    bool operator<(const Piece& o) const { return error < o.error; }
  };
  // Nodes in the order c, c - x_0, c + x_0, c - x_1, ...; values node-major.
  double x[15];
  std::vector<double> fx(15 * n);
  auto rule = [&](double lo, double hi) {
    double c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
    x[0] = c;
    for (int j = 0; j < 7; ++j) x[1 + 2 * j] = c - h * kXk[j], x[2 + 2 * j] = c + h * kXk[j];
    f(x, 15, fx.data());
    Piece p{lo, hi, 0.0, std::vector<double>(n)};
    for (size_t d = 0; d < n; ++d) {
      double kronrod = kWk[7] * fx[d], gauss = kWg[3] * fx[d];
      for (size_t j = 0; j < 7; ++j) {
        double sum = fx[(1 + 2 * j) * n + d] + fx[(2 + 2 * j) * n + d];
        kronrod += kWk[j] * sum;
        if (j % 2 == 1) gauss += kWg[j / 2] * sum;
      }
      p.value[d] = kronrod * h;
      p.error = std::max(p.error, std::abs((kronrod - gauss) * h));
    }
    return p;
  };
  std::priority_queue<Piece> work;
  work.push(rule(a, b));
  std::vector<double> total = work.top().value;
  double error = work.top().error;
  int intervals = 1;
  auto magnitude = [&] {
    double m = 0.0;
    for (double v : total) m = std::max(m, std::abs(v));
    return m;
  };
  while (error > rel_tol * magnitude() && intervals < max_intervals) {
    Piece worst = work.top();
    work.pop();
    double mid = 0.5 * (worst.a + worst.b);
    if (!(mid > worst.a && mid < worst.b)) {
      work.push(worst);
      break;
    }
    Piece left = rule(worst.a, mid), right = rule(mid, worst.b);
    for (size_t d = 0; d < n; ++d) total[d] += left.value[d] + right.value[d] - worst.value[d];
    error += left.error + right.error - worst.error;
    work.push(std::move(left));
    work.push(std::move(right));
    ++intervals;
  }
  std::fill(total.begin(), total.end(), 0.0);
  while (!work.empty()) {
    for (size_t d = 0; d < n; ++d) total[d] += work.top().value[d];
    work.pop();
  }
  return total;
}

}  // namespace haze::analytic
