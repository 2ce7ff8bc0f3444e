// The transport operator of the discrete-ordinate solver: the upwind sweep, the first-collision
// source, and the paper's Jacobi scheme (dom_internal.h).
#include "dom_internal.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>
#include <haze/simd/phase_batch.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace haze::grids::dom {

namespace {

// L_e of the cell around x (sides h) whose density is rho: what follows the density at rho, the
// cell's own value; the rest (an emission grid, blackbody) averaged over the cell by 2-point
// Gauss-Legendre per axis, since a temperature's T^4 is far from linear across a voxel and its
// value at the centre (a voxel's, where the cells sit on a VDB's voxels) is a local extreme.
Rgb cell_emission(const Emission& emission, const Vec3& x, const Vec3& h, double rho) {
  Rgb e(0.0);
  Emission rest = emission;
  if (emission.strength > 0.0 && !emission.grid) e += emission.strength * emission.color * rho, rest.strength = 0.0;
  if (!rest.emits()) return e;
  const double g = 0.5 / std::sqrt(3.0);
  for (int c = 0; c < 8; ++c)
    e += 0.125 * emitted_radiance(rest, x + h * Vec3((c & 1) ? g : -g, (c & 2) ? g : -g, (c & 4) ? g : -g), 0.0);
  return e;
}

int octant(const Vec3& w) { return (w.x < 0.0 ? 1 : 0) | (w.y < 0.0 ? 2 : 0) | (w.z < 0.0 ? 4 : 0); }

// Cells whose centre lies within kNearCells cells of a point or spot light average its irradiance
// (Transport::first_collision).
constexpr double kNearCells = 2.5;
constexpr int kAverage = 8, kAverageOwn = 16;

// log(sinh(u) / u), even in u, without overflow: the log of the mean of e^(-v) for v uniform on
// [-u, u].
double log_sinhc(double u) {
  u = std::abs(u);
  return u < 1e-3 ? u * u / 6.0 : u + std::log1p(-std::exp(-2.0 * u)) - std::log(2.0 * u);
}

// The change across a cell of e^(-2 u x), x in [-1/2, 1/2], over its mean, by least squares:
// 12 times its centroid, -6 (coth u - 1 / u); at most 2 in size, so that the line stays >= 0 over
// the cell (the top cell of a slab under a sun of cosine 0.1 at 8 cells per optical depth: -1.2).
double linear_change(double u) {
  return std::clamp(std::abs(u) < 1e-3 ? -2.0 * u : -6.0 * (1.0 / std::tanh(u) - 1.0 / u), -2.0, 2.0);
}

// The cell's mean of e^(-sigma_t depth) over the cell, with the depth linear about the centre
// value: e^(-sigma_t depth_c) prod_e sinh(u_e) / u_e, u_e = sigma_t g_e h_e / 2 (the mean of an
// exponential over a box). g_e h_e, the depth's change across the cell along axis e, is the
// smaller of the one-sided differences to the neighbours (0 where they differ in sign: minmod,
// so a density edge next door does not steepen it), the one there is at the grid's faces and
// where the other neighbour is in a surface's shadow (kShadowDepth), and at most twice the
// centre's depth (the depth stays >= 0 over the cell). The centre value alone undercounts the
// light arriving over the cell: under a grazing sun 8 cells per optical depth lose 6% at the top.
// u gets the u_e (0 on an axis left out).
double cell_mean_attenuation(const DenseGrid& depth, int i, int j, int k, double sigma_t, std::array<double, 3>& u) {
  u = {0.0, 0.0, 0.0};
  const std::array<int, 3> n = depth.resolution(), at{i, j, k};
  const float* v = depth.values().data();
  const size_t c = depth.index(i, j, k);
  const auto centre = static_cast<double>(v[c]);
  double exponent = -sigma_t * centre;
  if (!(centre < 0.5 * static_cast<double>(kShadowDepth))) return 0.0;
  for (size_t e = 0; e < 3; ++e) {
    if (n[e] < 2) continue;
    const size_t stride = e == 0 ? 1 : e == 1 ? static_cast<size_t>(n[0]) : static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]);
    const bool low = at[e] > 0 && v[c - stride] < 0.5f * kShadowDepth, high = at[e] < n[e] - 1 && v[c + stride] < 0.5f * kShadowDepth;
    if (!low && !high) continue;
    const double down = low ? centre - static_cast<double>(v[c - stride]) : 0.0, up = high ? static_cast<double>(v[c + stride]) - centre : 0.0;
    const double change = !low ? up : !high ? down : down * up <= 0.0 ? 0.0 : std::abs(down) < std::abs(up) ? down : up;
    u[e] = 0.5 * sigma_t * std::clamp(change, -2.0 * centre, 2.0 * centre);
    exponent += log_sinhc(u[e]);
  }
  return std::exp(exponent);
}

}  // namespace

Channel make_channel(const ExtinctionVolume& volume, const std::vector<Light>& lights, int channel, double delta_m_fraction,
                     int first_plane) {
  Channel c;
  c.index = channel;
  c.sigma_t_scale = static_cast<float>(delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, delta_m_fraction)[channel]);
  c.albedo = static_cast<float>(delta_m_albedo(volume.albedo, delta_m_fraction)[channel]);
  for (const Light& l : lights)
    if (const auto* sky = std::get_if<SkyLight>(&l)) c.sky += static_cast<float>(sky->radiance[channel]);
  const std::array<int, 3> n = volume.density.resolution();
  c.density = volume.density.values().data() + static_cast<size_t>(first_plane) * static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]);
  return c;
}

Transport::Transport(const DenseGrid& density, const DirectionSet& directions, const PhaseMatrix& matrix, const SeparablePhase& separable,
                     DomSpatial spatial, bool scalar_kernel, DomExchange* exchange)
    : n_(density.resolution()), cells_(density.cell_count()), exchange_(exchange), d_(directions.size()), n_terms_(separable.terms()),
      full_(separable.terms() == directions.size()), scalar_kernel_(scalar_kernel) {
  if (exchange) {
    plane0_ = exchange->first_plane;
    n_[2] = exchange->last_plane - exchange->first_plane;
    cells_ = static_cast<size_t>(n_[0]) * static_cast<size_t>(n_[1]) * static_cast<size_t>(n_[2]);
  }
  std::vector<int> order(static_cast<size_t>(d_));
  for (int i = 0; i < d_; ++i) order[static_cast<size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return octant(directions[a]) < octant(directions[b]); });
  for (int o = 0, i = 0; o <= 8; ++o) {
    while (i < d_ && octant(directions[order[static_cast<size_t>(i)]]) < o) ++i;
    start_[static_cast<size_t>(o)] = i;
  }
  const Vec3 h = density.cell_size();
  const auto d = static_cast<size_t>(d_), n = static_cast<size_t>(n_terms_);
  a_.resize(3 * d), q_.resize(d * n), lq_.resize(d * n);
  for (size_t i = 0; i < d; ++i) {
    const int dir = order[i];
    directions_.push_back(directions[dir]);
    for (int e = 0; e < 3; ++e) a_[i * 3 + static_cast<size_t>(e)] = static_cast<float>(std::abs(directions[dir][e]) / h[e]);
    for (size_t k = 0; k < n; ++k) {
      q_[i * n + k] = static_cast<float>(separable.basis()(dir, static_cast<int>(k)));
      lq_[i * n + k] = static_cast<float>(separable.eigenvalues()(static_cast<int>(k)) * separable.basis()(dir, static_cast<int>(k)));
    }
  }
  if (full_) {
    matrix_.resize(d * d);
    for (size_t i = 0; i < d; ++i)
      for (size_t j = 0; j < d; ++j) matrix_[i * d + j] = static_cast<float>(matrix(order[i], order[j]));
  }
  const size_t np = (n + 7) / 8 * 8;
  padded_index_.resize(d);
  for (size_t o = 0; o < 8; ++o) {
    Octant& oc = octants_[o];
    const auto i0 = static_cast<size_t>(start_[o]), count = static_cast<size_t>(start_[o + 1]) - i0, p = (count + 7) / 8 * 8;
    oc.offset = padded_;
    padded_ += p;
    oc.a.assign(5 * p, 0.0f), oc.lq.assign(n * p, 0.0f), oc.q.assign(p * np, 0.0f);
    for (size_t e = 0; e < p; ++e) oc.a[3 * p + e] = oc.a[4 * p + e] = 1.0f;  // padding: L = 0 / (sigma_t + 1)
    for (size_t e = 0; e < count; ++e) {
      const size_t i = i0 + e;
      padded_index_[i] = oc.offset + e;
      oc.a[3 * p + e] = oc.a[4 * p + e] = 0.0f;
      for (size_t axis = 0; axis < 3; ++axis) {
        oc.a[axis * p + e] = a_[i * 3 + axis];
        oc.a[3 * p + e] += a_[i * 3 + axis];
      }
      for (size_t k = 0; k < n; ++k) oc.lq[k * p + e] = lq_[i * n + k], oc.q[e * np + k] = q_[i * n + k];
    }
    oc.view = {static_cast<int>(p), n_terms_, static_cast<int>(np), oc.a.data(), oc.lq.data(), oc.q.data(), spatial != DomSpatial::step,
               {o & 1 ? -1.0f : 1.0f, o & 2 ? -1.0f : 1.0f, o & 4 ? -1.0f : 1.0f}};
  }
}

void Transport::sweep(const Channel& ch, const FirstCollision* first, const float* m_in, float boundary, float* m_out, int threads,
                      const Faces* faces) const {
  const auto nx = n_[0], ny = n_[1], nz = n_[2];
  Stopwatch start;
  const size_t size = cells_ * static_cast<size_t>(n_terms_);
  scratch_.resize(size);
  const auto row_kernel = scalar_kernel_ ? dom_sweep_row_reference : dom_sweep_row;
  long long skipped[2] = {0, 0};
  // Split over processes, the halves in order on this thread: each half's octants wait on the
  // process upwind, which must be in the same half (one process per core).
  parallel_for(2, exchange_ ? 1 : threads, 1, [&](long long h0, long long h1) {
    for (long long half = h0; half < h1; ++half) {
      float* out = half == 0 ? m_out : scratch_.data();
      std::fill(out, out + size, 0.0f);
      for (size_t o = 4 * static_cast<size_t>(half); o < 4 * static_cast<size_t>(half) + 4; ++o) {
        const Octant& oc = octants_[o];
        const auto p = static_cast<size_t>(oc.view.directions);
        if (p == 0) continue;
        // What enters through the upwind face across `axis` at face cell `cell` (its P values).
        auto enter = [&](int axis, size_t cell, float* to) {
          if (!faces) return std::fill(to, to + p, boundary);
          const float* from = faces->values[o][static_cast<size_t>(axis)].data() + cell * p;
          std::copy(from, from + p, to);
        };
        auto dark = [&](const float* v) { return std::all_of(v, v + p, [](float e) { return e == 0.0f; }); };
        const auto sx = static_cast<size_t>(nx), sy = static_cast<size_t>(ny);
        // Split over processes, the octant goes in blocks of y rows through all of this part's
        // planes, each block's z face received before it and sent after it, so that the process
        // downwind starts on a block while this one sweeps the next (KBA's pipelining). Every cell
        // sees the same upwind faces in any block order: the result is the same bits. A block's
        // y faces carry over to the next one, plane by plane.
        const int rows = exchange_ ? std::clamp(exchange_->rows_per_message, 1, ny) : ny, blocks = (ny + rows - 1) / rows;
        const size_t kept = blocks > 1 ? static_cast<size_t>(nz) : 1;  // planes whose y faces are kept between blocks
        std::vector<float> z_plane(sx * sy * p), y_rows(kept * sx * p), x_run(p), scratch(4 * p + static_cast<size_t>(oc.view.terms_padded));
        // Which upwind faces still carry exactly zero radiance (per x of the z plane and of the y
        // row): an empty cell between such faces stays dark, so a row's leading run of them is
        // skipped. Exact.
        std::vector<char> z_dark(sx * sy), y_darks(kept * sx);
        for (size_t c = 0; c < sx * sy; ++c) enter(2, c, z_plane.data() + c * p);
        DomRow row;
        row.step = o & 1 ? -1 : 1;
        row.density = ch.density, row.sigma_t_scale = ch.sigma_t_scale, row.albedo = ch.albedo;
        if (first && !first->rows.empty()) row.first_rows = first->rows.data() + oc.offset, row.first_factor = first->factor.data(), row.first_lights = first->lights;
        else if (first && first->half.empty()) row.first = first->values.data() + oc.offset;
        if (first && !first->half.empty()) row.first_half = first->half.data() + oc.offset, row.first_scale = first->scale.data();
        if (first && !first->slope.empty()) row.first_slope = first->slope.data();
        row.first_stride = padded_;
        row.m_in = m_in, row.m_out = out;
        if (ch.bounded) row.bounded = ch.bounded + o, row.mark = first && (!m_in || ch.mark_with_moments);
        row.x_run = x_run.data(), row.scratch = scratch.data();
        for (int b = 0; b < blocks; ++b) {
          const int jj0 = b * rows, jj1 = std::min(ny, jj0 + rows);
          const auto j_low = static_cast<size_t>(o & 2 ? ny - jj1 : jj0), block_rows = static_cast<size_t>(jj1 - jj0);
          float* face = z_plane.data() + j_low * sx * p;
          // Or, split over processes, what left the process upwind (DomExchange).
          if (exchange_) exchange_->receive(static_cast<int>(o), face, block_rows * sx * p);
          for (size_t c = j_low * sx; c < (j_low + block_rows) * sx; ++c) z_dark[c] = dark(z_plane.data() + c * p);
          for (int kk = 0; kk < nz; ++kk) {
            const int k = o & 4 ? nz - 1 - kk : kk;
            const size_t plane = kept > 1 ? static_cast<size_t>(k) : 0;
            float* y_row = y_rows.data() + plane * sx * p;
            char* y_dark = y_darks.data() + plane * sx;
            row.y_row = y_row;
            if (b == 0)
              for (size_t x = 0; x < sx; ++x) {
                enter(1, static_cast<size_t>(k) * sx + x, y_row + x * p);
                y_dark[x] = dark(y_row + x * p);
              }
            for (int jj = jj0; jj < jj1; ++jj) {
              const int j = o & 2 ? ny - 1 - jj : jj;
              enter(0, static_cast<size_t>(k) * sy + static_cast<size_t>(j), x_run.data());
              const size_t row_start = (static_cast<size_t>(k) * sy + static_cast<size_t>(j)) * sx;
              char* z_dark_row = z_dark.data() + static_cast<size_t>(j) * sx;
              int skip = 0;
              if (dark(x_run.data()))
                for (; skip < nx; ++skip) {
                  const auto x = static_cast<size_t>(o & 1 ? nx - 1 - skip : skip);
                  if (!(y_dark[x] && z_dark_row[x] && ch.density[row_start + x] == 0.0f)) break;
                }
              skipped[half] += skip;
              if (skip == nx) continue;
              row.count = nx - skip;
              row.x0 = o & 1 ? nx - 1 - skip : skip;
              row.cell0 = row_start + static_cast<size_t>(row.x0);
              row.z_row = z_plane.data() + static_cast<size_t>(j) * sx * p;
              row_kernel(oc.view, row);
              for (int m = skip; m < nx; ++m) {
                const auto x = static_cast<size_t>(o & 1 ? nx - 1 - m : m);
                y_dark[x] = z_dark_row[x] = 0;
              }
            }
          }
          if (exchange_) exchange_->send(static_cast<int>(o), face, block_rows * sx * p);  // the leaving face's rows
        }
      }
    }
  });
  parallel_for(static_cast<long long>(size), threads, 1 << 16, [&](long long i0, long long i1) {
    for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i) m_out[i] += scratch_[i];
  });
  cells_skipped_ += skipped[0] + skipped[1];
  cells_visited_ += 8 * static_cast<long long>(cells_);
  seconds_ += start.seconds();
}

std::vector<Faces> Transport::faces(const DomBoundary& boundary, const DenseGrid& grid, int channels, int threads) const {
  std::vector<Faces> out(static_cast<size_t>(channels));
  const Aabb& b = grid.bounds();
  for (size_t o = 0; o < 8; ++o) {
    const auto p = static_cast<size_t>(octants_[o].view.directions);
    for (int axis = 0; axis < 3; ++axis) {
      // The face across `axis` the octant's directions enter through; its cells run over the
      // other two axes, u fastest.
      const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
      const int nu = n_[static_cast<size_t>(u)], nv = n_[static_cast<size_t>(v)];
      const double side = o & (1u << axis) ? b.hi[axis] : b.lo[axis];
      for (Faces& f : out) f.values[o][static_cast<size_t>(axis)].assign(static_cast<size_t>(nu) * static_cast<size_t>(nv) * p, 0.0f);
      parallel_for(nv, threads, 1, [&](long long v0, long long v1) {
        for (auto iv = static_cast<int>(v0); iv < v1; ++iv)
          for (int iu = 0; iu < nu; ++iu) {
            std::array<int, 3> cell{0, 0, 0};
            cell[static_cast<size_t>(u)] = iu, cell[static_cast<size_t>(v)] = iv;
            Vec3 point = grid.cell_center(cell[0], cell[1], cell[2]);
            point[axis] = side;
            const size_t at = (static_cast<size_t>(iv) * static_cast<size_t>(nu) + static_cast<size_t>(iu)) * p;
            for (int i = start_[o]; i < start_[o + 1]; ++i) {
              const Rgb r = boundary.radiance(point, directions_[static_cast<size_t>(i)]);
              for (int c = 0; c < channels; ++c)
                out[static_cast<size_t>(c)].values[o][static_cast<size_t>(axis)][at + static_cast<size_t>(i - start_[o])] =
                    static_cast<float>(r[channels == 1 ? 0 : c]);
            }
          }
      });
    }
  }
  return out;
}

FirstCollision Transport::first_collision(const ExtinctionVolume& volume, const std::vector<Light>& lights,
                                          const std::vector<DenseGrid>& depths, int channel, double scale_all, bool half, int threads,
                                          bool separable) const {
  const DenseGrid& grid = volume.density;
  const auto d = static_cast<size_t>(d_);
  const Vec3 h = grid.cell_size();
  // A cell near a point or spot light takes the light's irradiance averaged over the cell (the
  // 1 / d^2 peak, which its centre alone undercounts: by half in the light's own cell), over
  // midpoints of a kAverage^3 (kAverageOwn^3 in the light's own cell) subgrid; the light's own
  // cell scatters it isotropically.
  const double near = kNearCells * std::max({h.x, h.y, h.z}), on_light = 1e-3 * std::min({h.x, h.y, h.z});
  auto cell_irradiance = [&](const Light& light, const Vec3& x, int n) {
    double sum = 0.0;
    LightArrival b;
    for (int c = 0; c < n * n * n; ++c) {
      const Vec3 f((c % n + 0.5) / n - 0.5, ((c / n) % n + 0.5) / n - 0.5, (c / (n * n) + 0.5) / n - 0.5);
      // A midpoint within a thousandth of a cell of the light (whose 1 / d^2 integrates to next
      // to nothing over that ball) counts nothing.
      if (arrival(light, x + f * h, b) && b.distance > on_light) sum += b.irradiance[channel];
    }
    return sum / (n * n * n);
  };
  const double sigma_t = volume.sigma_t_scale[channel], weight = 4.0 * kPi / d_;
  const bool emits = volume.emission.emits();
  // p(w_light . w_d) / (sum_j p(w_light . w_j) w_j) per direction: for a directional light the
  // same in every cell, so made once here.
  auto normalized_phase = [&](const Vec3& to_light, std::vector<float>& cosines, std::vector<float>& phase) {
    for (size_t t = 0; t < d; ++t) cosines[t] = static_cast<float>(-glm::dot(to_light, directions_[t]));
    simd::eval_phase(volume.phase, cosines.data(), phase.data(), d);
    double sum = 0.0;
    for (size_t t = 0; t < d; ++t) sum += static_cast<double>(phase[t]);
    for (size_t t = 0; t < d; ++t) phase[t] = static_cast<float>(static_cast<double>(phase[t]) / (sum * weight));
  };
  std::vector<std::vector<float>> rows(lights.size());
  for (size_t l = 0; l < lights.size(); ++l)
    if (const auto* sun = std::get_if<DirectionalLight>(&lights[l])) {
      std::vector<float> cosines(d);
      rows[l].resize(d);
      normalized_phase(-sun->direction, cosines, rows[l]);  // as arrival() gives to_light
    }
  FirstCollision first;
  separable = separable && !half && !emits && !lights.empty() &&
              std::all_of(lights.begin(), lights.end(), [](const Light& l) { return std::holds_alternative<DirectionalLight>(l); });
  if (separable) {
    first.lights = static_cast<int>(lights.size());
    first.rows.assign(lights.size() * padded_, 0.0f), first.factor.assign(cells_ * lights.size(), 0.0f);
    for (size_t l = 0; l < lights.size(); ++l)
      for (size_t t = 0; t < d; ++t) first.rows[l * padded_ + padded_index_[t]] = rows[l][t];
  } else if (half) {
    first.half.resize(cells_ * padded_), first.scale.resize(cells_);
  } else {
    first.values.assign(cells_ * padded_, 0.0f);
  }
  first.slope.assign(3 * cells_, 0.0f);
  const auto nx = n_[0], ny = n_[1];
  parallel_for(n_[2], threads, 1, [&](long long k0, long long k1) {
    std::vector<float> cosines(d), phase(d), cell(half ? padded_ : 0);
    for (auto k = static_cast<int>(k0); k < k1; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int kg = k + plane0_;  // the plane in the volume's grid
          const size_t c = grid.index(i, j, k), cg = grid.index(i, j, kg);
          if (grid.values()[cg] == 0.0f) {  // an empty cell scatters nothing: no source
            if (half) first.scale[c] = 0.0f, std::fill_n(first.half.data() + c * padded_, padded_, simd::Half(0.0f));
            continue;
          }
          const Vec3 x = grid.cell_center(i, j, kg);
          float* f = separable ? nullptr : half ? cell.data() : first.values.data() + c * padded_;
          std::array<double, 3> slope{0.0, 0.0, 0.0};  // each light's change weighted by its share
          double total = 0.0;
          if (half) std::fill(cell.begin(), cell.end(), 0.0f);
          for (size_t l = 0; l < lights.size(); ++l) {
            LightArrival a;
            if (!arrival(lights[l], x, a)) continue;
            double e = a.irradiance[channel];
            if (std::isfinite(a.distance) && a.distance < near) {
              const Vec3 offset = glm::abs(a.to_light * a.distance);
              const bool own = !(a.distance > 0.0) || (offset.x <= 0.5 * h.x && offset.y <= 0.5 * h.y && offset.z <= 0.5 * h.z);
              e = cell_irradiance(lights[l], x, own ? kAverageOwn : kAverage);
              if (own) a.to_light = Vec3(0.0);  // every cosine 0: an isotropic source
            }
            std::array<double, 3> u;
            e *= cell_mean_attenuation(depths[l], i, j, kg, sigma_t, u);
            if (!(e > 0.0)) continue;
            for (size_t axis = 0; axis < 3; ++axis) slope[axis] += e * linear_change(u[axis]);
            total += e;
            const auto scale = static_cast<float>(scale_all * e);
            if (separable) {
              first.factor[c * lights.size() + l] = scale;
              continue;
            }
            if (rows[l].empty()) normalized_phase(a.to_light, cosines, phase);
            const float* row = rows[l].empty() ? phase.data() : rows[l].data();
            for (size_t t = 0; t < d; ++t) f[padded_index_[t]] += scale * row[t];
          }
          // Emission: an isotropic source L_e of its own, entering the sweep's sigma_s S as
          // L_e / sigma_s (and, under delta-M, the scaled sigma_s: scale_all). Not slope-weighted.
          // Cells that scatter nothing send their emission to the camera only (render_dom's march).
          if (emits) {
            const double sigma_s = volume.albedo[channel] * sigma_t * static_cast<double>(grid.values()[cg]);
            const double emitted = cell_emission(volume.emission, x, h, grid.values()[cg])[channel];
            if (sigma_s > 0.0 && emitted > 0.0) {
              const auto value = static_cast<float>(scale_all * emitted / sigma_s);
              for (size_t t = 0; t < d; ++t) f[padded_index_[t]] += value;
              total += 4.0 * kPi * emitted / sigma_s;
            }
          }
          if (total > 0.0)
            for (size_t axis = 0; axis < 3; ++axis) first.slope[c * 3 + axis] = static_cast<float>(slope[axis] / total);
          if (half) {  // values / their largest, in [0, 1]: no overflow, 2^-11 relative
            const float largest = *std::max_element(cell.begin(), cell.end());
            if (largest > 0.0f)
              for (float& v : cell) v /= largest;
            first.scale[c] = largest;
            simd::to_half(cell.data(), first.half.data() + c * padded_, padded_);
          }
        }
  });
  return first;
}

std::vector<float> Transport::paper(const Channel& ch, const FirstCollision& first, const std::vector<float>* warm,
                                    const DomSettings& settings, int& iterations, std::vector<double>& changes) const {
  const auto d = static_cast<long>(d_), n = static_cast<long>(n_terms_);
  const auto nx = n_[0], ny = n_[1], nz = n_[2];
  using Matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Map<const Matrix> qt(q_.data(), n, d), lqt(lq_.data(), n, d);  // Q^T and (Q Lambda)^T, regrouped
  std::vector<float> radiance(cells_ * static_cast<size_t>(d), 0.0f), next(radiance.size()), inscatter(radiance.size());
  std::vector<float> moments(cells_ * static_cast<size_t>(n), 0.0f), previous;
  auto project = [&](const std::vector<float>& from, std::vector<float>& to) {  // moments of every cell
    parallel_for(static_cast<long long>(cells_), settings.threads, 4096, [&](long long c0, long long c1) {
      Eigen::Map<Matrix>(to.data() + c0 * n, n, c1 - c0).noalias() = qt * Eigen::Map<const Matrix>(from.data() + c0 * d, d, c1 - c0);
    });
  };
  if (warm) {  // radiance from the warm moments: L = Q m (exact for the full matrix)
    moments = *warm;
    parallel_for(static_cast<long long>(cells_), settings.threads, 4096, [&](long long c0, long long c1) {
      Eigen::Map<Matrix>(radiance.data() + c0 * d, d, c1 - c0).noalias() =
          qt.transpose() * Eigen::Map<const Matrix>(moments.data() + c0 * n, n, c1 - c0);
    });
  }
  const size_t sx = 1, sy = static_cast<size_t>(nx), sz = static_cast<size_t>(nx) * static_cast<size_t>(ny);
  Stopwatch start;
  for (int it = 0; it < settings.max_iterations; ++it) {
    // In-scattering, seed 000 eq. 6 (full matrix) or eq. 9 (separable), as two products per block.
    parallel_for(static_cast<long long>(cells_), settings.threads, 4096, [&](long long c0, long long c1) {
      const Eigen::Map<const Matrix> l(radiance.data() + c0 * d, d, c1 - c0);
      Eigen::Map<Matrix> s(inscatter.data() + c0 * d, d, c1 - c0);
      if (full_) s.noalias() = Eigen::Map<const Matrix>(matrix_.data(), d, d) * l;  // P symmetric
      else s.noalias() = lqt.transpose() * (qt * l);
    });
    // Every cell from its upwind neighbours' previous radiance (eq. 7): one cell per iteration.
    parallel_for(nz, settings.threads, 1, [&](long long k0, long long k1) {
      for (auto k = static_cast<int>(k0); k < k1; ++k)
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i) {
            const size_t c = static_cast<size_t>(k) * sz + static_cast<size_t>(j) * sy + static_cast<size_t>(i) * sx;
            const float sigma_t = ch.sigma_t_scale * ch.density[c], sigma_s = ch.albedo * sigma_t;
            for (int o = 0; o < 8; ++o) {
              const int ui = o & 1 ? i + 1 : i - 1, uj = o & 2 ? j + 1 : j - 1, uk = o & 4 ? k + 1 : k - 1;
              const float* ux = ui >= 0 && ui < nx ? radiance.data() + (c + (o & 1 ? sx : -sx)) * static_cast<size_t>(d) : nullptr;
              const float* uy = uj >= 0 && uj < ny ? radiance.data() + (c + (o & 2 ? sy : -sy)) * static_cast<size_t>(d) : nullptr;
              const float* uz = uk >= 0 && uk < nz ? radiance.data() + (c + (o & 4 ? sz : -sz)) * static_cast<size_t>(d) : nullptr;
              for (int e = start_[static_cast<size_t>(o)]; e < start_[static_cast<size_t>(o) + 1]; ++e) {
                const auto t = static_cast<size_t>(e);
                const float* a = a_.data() + 3 * t;
                const size_t cd = c * static_cast<size_t>(d) + t;
                const float in = a[0] * (ux ? ux[t] : ch.sky) + a[1] * (uy ? uy[t] : ch.sky) + a[2] * (uz ? uz[t] : ch.sky);
                const float source = first.values[c * padded_ + padded_index_[t]] + inscatter[cd];
                next[cd] = (sigma_s * source + in) / (sigma_t + a[0] + a[1] + a[2]);
              }
            }
          }
    });
    radiance.swap(next);
    ++iterations;
    previous.swap(moments);
    moments.resize(previous.size());
    project(radiance, moments);
    double diff = 0.0, ref = 0.0;  // relative L2 change of the moments, as the sweep scheme measures it
    for (size_t i = 0; i < moments.size(); ++i) {
      const double m = moments[i], dm = m - static_cast<double>(previous[i]);
      diff += dm * dm, ref += m * m;
    }
    changes.push_back(ref > 0.0 ? std::sqrt(diff / ref) : 0.0);
    if (settings.progress && !settings.progress(std::min(1.0, (it + 1.0) / settings.max_iterations))) throw Cancelled();
    if (changes.back() < settings.tolerance) break;
  }
  seconds_ += start.seconds();
  return moments;
}

}  // namespace haze::grids::dom
