#include <haze/core/error.h>
#include <haze/core/phase_matrix.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <numeric>

namespace haze {

PhaseMatrix::PhaseMatrix(const PhaseFunction& phase, const DirectionSet& directions) : phase_(phase), directions_(directions) {
  const int d = directions.size();
  for (int j = 1; j < d; ++j)
    if (std::abs(directions.weight(j) - directions.weight(0)) > 1e-12 * directions.weight(0))
      throw Error("directions.weights", "unequal weights", "equal quadrature weights (Fibonacci or uniform random)");
  Eigen::MatrixXd k(d, d);
  for (int i = 0; i < d; ++i)
    for (int j = i; j < d; ++j)
      k(i, j) = k(j, i) = phase.eval(directions[i], directions[j]) * directions.weight(j);
  raw_row_sums_ = k.rowwise().sum();

  // Symmetric Sinkhorn scaling s <- sqrt(s / (K s)): P = S K S stays symmetric (so the separable
  // factorization is an eigen-decomposition) and its rows sum to 1. The new row sum over the old one
  // is then exactly 1 / raw_row_sums, as plain row renormalization would give.
  Eigen::VectorXd s = raw_row_sums_.cwiseInverse().cwiseSqrt();
  for (int it = 0; it < 200; ++it) {
    Eigen::VectorXd ks = k * s;
    double worst = (s.cwiseProduct(ks).array() - 1.0).abs().maxCoeff();
    if (worst < 1e-14) break;
    s = (s.array() / ks.array()).sqrt();
  }
  matrix_ = s.asDiagonal() * k * s.asDiagonal();
  scaling_ = s;
}

Eigen::VectorXd PhaseMatrix::row(const Vec3& w) const {
  Eigen::VectorXd r;
  row(w, r);
  return r;
}

void PhaseMatrix::row(const Vec3& w, Eigen::VectorXd& out) const {
  out.resize(size());
  for (int j = 0; j < size(); ++j) out(j) = phase_.eval(glm::dot(w, directions_[j])) * directions_.weight(j) * scaling_(j);
  out /= out.sum();
}

SeparablePhase::SeparablePhase(const PhaseMatrix& matrix, int terms) {
  const int d = matrix.size();
  if (terms < 1 || terms > d)
    throw Error("terms", to_text(terms), "a number of separable terms in [1, " + std::to_string(d) + "] (the direction count)");
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(matrix.matrix());
  if (solver.info() != Eigen::Success) throw Error("phase matrix eigen-decomposition did not converge");
  std::vector<int> order(static_cast<size_t>(d));
  std::iota(order.begin(), order.end(), 0);
  const auto& values = solver.eigenvalues();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(values(a)) > std::abs(values(b)); });

  all_eigenvalues_.resize(d);
  for (int i = 0; i < d; ++i) all_eigenvalues_(i) = values(order[static_cast<size_t>(i)]);
  eigenvalues_ = all_eigenvalues_.head(terms);
  basis_.resize(d, terms);
  for (int k = 0; k < terms; ++k) basis_.col(k) = solver.eigenvectors().col(order[static_cast<size_t>(k)]);

  // With orthonormal eigenvectors ||P - P_N||_F^2 is the sum of the dropped lambda^2.
  double total = all_eigenvalues_.squaredNorm();
  double dropped = all_eigenvalues_.tail(d - terms).squaredNorm();
  relative_error_ = std::sqrt(dropped / total);
  rmse_ = std::sqrt(dropped) / d;
}

Eigen::MatrixXd SeparablePhase::reconstruct() const {
  return basis_ * eigenvalues_.asDiagonal() * basis_.transpose();
}

}  // namespace haze
