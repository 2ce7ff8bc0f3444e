// Diffusion synthetic acceleration of the DOM's source iteration (dom_diffusion.h).
#include "dom_diffusion.h"

#include <haze/core/progress.h>

#include <algorithm>
#include <cmath>

namespace haze::grids::dom {

namespace {

// Per z-slab partial sums, added in slab order: the same result on any number of threads.
double total(const std::vector<double>& slabs) {
  double s = 0.0;
  for (double v : slabs) s += v;
  return s;
}

}  // namespace

int diffusion_correction(const DenseGrid& density, const Channel& channel, int terms, double q0, const std::vector<float>& previous,
                         std::vector<float>& next, int threads) {
  const std::array<int, 3> n = density.resolution();
  const size_t cells = density.cell_count(), nt = static_cast<size_t>(terms);
  const auto nx = static_cast<size_t>(n[0]), ny = static_cast<size_t>(n[1]), plane = nx * ny;
  const size_t stride[3] = {1, nx, plane};
  const Vec3 h = density.cell_size();
  // D is capped at a cell's width (sigma_t at least 1 / (3 h)): a void or thin cell scatters next
  // to nothing and needs no correction, and the operator stays well conditioned.
  const double floor = 1.0 / (3.0 * std::min({h.x, h.y, h.z}));
  const auto sigma_t = [&](size_t c) { return static_cast<double>(channel.sigma_t_scale) * static_cast<double>(channel.density[c]); };
  const auto diffusion = [&](size_t c) { return 1.0 / (3.0 * std::max(sigma_t(c), floor)); };
  // The operator A e = sigma_a e + sum over faces of f (e - e_neighbour) + (Marshak vacuum faces,
  // J = phi / 2) b e, per unit volume: its diagonal, and each cell's coefficient to its +x, +y, +z
  // neighbour (0 past the grid's edge).
  std::vector<double> diagonal(cells), source(cells), slab(static_cast<size_t>(n[2]));
  std::array<std::vector<double>, 3> face{std::vector<double>(cells), std::vector<double>(cells), std::vector<double>(cells)};
  parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {
    for (auto k = static_cast<size_t>(k0); k < static_cast<size_t>(k1); ++k) {
      double sum = 0.0;
      for (size_t j = 0; j < ny; ++j)
        for (size_t i = 0; i < nx; ++i) {
          const size_t c = k * plane + j * nx + i, along[3] = {i, j, k};
          const double t = sigma_t(c), s = static_cast<double>(channel.albedo) * t, d = diffusion(c);
          double diag = t - s;
          for (size_t a = 0; a < 3; ++a) {
            const double ha = h[static_cast<int>(a)];
            const bool low = along[a] == 0, high = along[a] + 1 == static_cast<size_t>(n[a]);
            diag += (low + high) * 2.0 * d / (ha * (ha + 4.0 * d));
            if (!low) {
              const double dn = diffusion(c - stride[a]);
              diag += 2.0 * d * dn / (d + dn) / (ha * ha);
            }
            if (high) {
              face[a][c] = 0.0;
            } else {
              const double dn = diffusion(c + stride[a]);
              diag += (face[a][c] = 2.0 * d * dn / (d + dn) / (ha * ha));
            }
          }
          diagonal[c] = diag;
          source[c] = s * q0 * (static_cast<double>(next[c * nt]) - static_cast<double>(previous[c * nt]));
          sum += source[c] * source[c];
        }
      slab[k] = sum;
    }
  });
  const double source_norm = total(slab);
  if (!(source_norm > 0.0)) return 0;
  // Jacobi-preconditioned conjugate gradients from 0, to a tenth of the source's norm: the
  // correction removes the slow error's bulk, the next sweep the rest.
  std::vector<double> e(cells, 0.0), r = source, z(cells), p(cells), q(cells);
  for (size_t c = 0; c < cells; ++c) p[c] = z[c] = r[c] / diagonal[c];
  double rz = 0.0;
  for (size_t c = 0; c < cells; ++c) rz += r[c] * z[c];
  std::vector<double> slab2(slab.size());
  int iterations = 0;
  for (double rr = source_norm; iterations < 200 && rr > 1e-2 * source_norm; ++iterations) {
    parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {  // q = A p, and p . q
      for (auto k = static_cast<size_t>(k0); k < static_cast<size_t>(k1); ++k) {
        double sum = 0.0;
        for (size_t c = k * plane; c < (k + 1) * plane; ++c) {
          double v = diagonal[c] * p[c];
          for (size_t a = 0; a < 3; ++a) {
            v -= face[a][c] * (face[a][c] != 0.0 ? p[c + stride[a]] : 0.0);
            if (c >= stride[a]) v -= face[a][c - stride[a]] * p[c - stride[a]];
          }
          q[c] = v, sum += p[c] * v;
        }
        slab[k] = sum;
      }
    });
    const double alpha = rz / total(slab);
    parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {
      for (auto k = static_cast<size_t>(k0); k < static_cast<size_t>(k1); ++k) {
        double a = 0.0, b = 0.0;
        for (size_t c = k * plane; c < (k + 1) * plane; ++c) {
          e[c] += alpha * p[c], r[c] -= alpha * q[c], z[c] = r[c] / diagonal[c];
          a += r[c] * z[c], b += r[c] * r[c];
        }
        slab[k] = a, slab2[k] = b;
      }
    });
    const double rz_next = total(slab), beta = rz_next / rz;
    rr = total(slab2), rz = rz_next;
    parallel_for(static_cast<long long>(cells), threads, 1 << 14, [&](long long c0, long long c1) {
      for (auto c = static_cast<size_t>(c0); c < static_cast<size_t>(c1); ++c) p[c] = z[c] + beta * p[c];
    });
  }
  for (size_t c = 0; c < cells; ++c) next[c * nt] += static_cast<float>(e[c] / q0);
  return iterations;
}

}  // namespace haze::grids::dom
