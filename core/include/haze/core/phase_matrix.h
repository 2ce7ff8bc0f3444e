// The discrete phase matrix over a DirectionSet and its separable factorization (seed 000 sec. 3.2).
#pragma once

#include <haze/core/directions.h>
#include <haze/core/phase.h>

#include <Eigen/Core>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// P[i][j] = p(w_i . w_j) w_j, scaled symmetrically (P = S K S, S diagonal) so that every row sums to
// exactly 1: the discrete in-scattering neither loses nor gains energy, which matters for strongly
// forward phase functions whose peak the quadrature misses. Needs equal quadrature weights.
class PhaseMatrix {
 public:
  PhaseMatrix(const PhaseFunction& phase, const DirectionSet& directions);

  int size() const { return static_cast<int>(matrix_.rows()); }
  const Eigen::MatrixXd& matrix() const { return matrix_; }
  double operator()(int i, int j) const { return matrix_(i, j); }
  // Row sums of the unscaled matrix: the quadrature's estimate of integral p = 1 for each direction.
  const Eigen::VectorXd& raw_row_sums() const { return raw_row_sums_; }
  // New row sum over old row sum, 1 / raw_row_sums(): the accuracy diagnostic (docs/ARCHITECTURE.md, "Phase matrix").
  Eigen::VectorXd renormalization_factors() const { return raw_row_sums_.cwiseInverse(); }
  // The symmetric scaling: P_ij = s_i p(w_i . w_j) w_j s_j. A direction w outside the set gets the
  // row s(w) p(w . w_j) w_j s_j with s(w) = 1 / sum_j p(w . w_j) w_j s_j (the same rule at w_i).
  const Eigen::VectorXd& scaling() const { return scaling_; }
  // That row at w, normalized to sum to 1: the in-scattering weights of the D directions toward a
  // direction off the set (a camera's view; seed 000's separable form and seed 001's splats).
  Eigen::VectorXd row(const Vec3& w) const;
  // The same into `out` (resized to size(): no allocation once it has that size).
  void row(const Vec3& w, Eigen::VectorXd& out) const;
  // out_i = sum_j P_ij in_j: the direct O(D^2) in-scattering sum (seed 000 eq. 6).
  Eigen::VectorXd apply(const Eigen::VectorXd& in) const { return matrix_ * in; }

 private:
  PhaseFunction phase_;
  DirectionSet directions_;
  Eigen::MatrixXd matrix_;
  Eigen::VectorXd raw_row_sums_, scaling_;
};

// P ~ Q_N diag(lambda_N) Q_N^T, keeping the N eigenpairs of largest |lambda| of the symmetric P
// (seed 000 eq. 8: for a symmetric matrix the SVD is the eigen-decomposition, up to signs).
class SeparablePhase {
 public:
  SeparablePhase(const PhaseMatrix& matrix, int terms);

  int terms() const { return static_cast<int>(eigenvalues_.size()); }
  int directions() const { return static_cast<int>(basis_.rows()); }
  // Kept eigenvalues, by decreasing magnitude, and the D x N matrix of their eigenvectors.
  const Eigen::VectorXd& eigenvalues() const { return eigenvalues_; }
  const Eigen::MatrixXd& basis() const { return basis_; }
  // Every eigenvalue of P, by decreasing magnitude.
  const Eigen::VectorXd& all_eigenvalues() const { return all_eigenvalues_; }

  // ||P - P_N||_F / ||P||_F and sqrt(mean((P - P_N)^2)), from the dropped eigenvalues.
  double relative_error() const { return relative_error_; }
  double rmse() const { return rmse_; }

  Eigen::MatrixXd reconstruct() const;
  // Moments m_k = sum_d Q[d][k] L_d (seed 000 eq. 10, with sqrt(xi_k) moved to expand()).
  Eigen::VectorXd moments(const Eigen::VectorXd& radiance) const { return basis_.transpose() * radiance; }
  // out_d = sum_k lambda_k Q[d][k] m_k (seed 000 eq. 11): O(D N) instead of O(D^2).
  Eigen::VectorXd expand(const Eigen::VectorXd& moments) const {
    return basis_ * eigenvalues_.cwiseProduct(moments);
  }
  Eigen::VectorXd apply(const Eigen::VectorXd& in) const { return expand(moments(in)); }

 private:
  Eigen::VectorXd eigenvalues_, all_eigenvalues_;
  Eigen::MatrixXd basis_;
  double relative_error_ = 0.0, rmse_ = 0.0;
};

}  // namespace haze

#pragma GCC visibility pop
