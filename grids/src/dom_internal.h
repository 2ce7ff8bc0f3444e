// Internal: the transport operator of the discrete-ordinate solver (dom_transport.cpp), shared by
// the iteration drivers in dom_solver.cpp.
#pragma once

#include <haze/grids/dom.h>
#include <haze/grids/dom_sweep.h>

#include <array>
#include <cstdint>
#include <vector>

namespace haze::grids::dom {

// Delta-M's scaled coefficients (DomSettings::delta_m): sigma_t (1 - albedo f) and
// albedo (1 - f) / (1 - albedo f); f = 0 leaves them as they are.
inline Rgb delta_m_sigma_t(const Rgb& sigma_t, const Rgb& albedo, double f) { return sigma_t * (Rgb(1.0) - albedo * f); }
inline Rgb delta_m_albedo(const Rgb& albedo, double f) { return albedo * (1.0 - f) / (Rgb(1.0) - albedo * f); }

// One channel of the medium: sigma_t = sigma_t_scale * density, sigma_s = albedo * sigma_t; with
// delta-M fraction f, the scaled sigma_t (1 - albedo f) and albedo (1 - f) / (1 - albedo f).
struct Channel {
  int index = 0;  // 0, 1, 2: which RGB channel
  float sigma_t_scale = 1.0f, albedo = 0.0f;
  float sky = 0.0f;  // radiance entering through the boundary
  const float* density = nullptr;
  // Or null (the bound everywhere): per cell and octant ([cell * 8 + octant]), 1 where the diamond
  // scheme takes its positivity bound; set by a sweep of the first-collision source alone (no
  // moments in) where a leaving radiance would go below 0 (simd/dom_sweep.h): the single-scattered
  // light's sharp edges.
  std::uint8_t* bounded = nullptr;
  // Mark in every sweep with the first-collision source, moments in or not (warm updates'
  // combined sweeps): where the first-collision and scattered light together would go below 0.
  bool mark_with_moments = false;
};
// `density` from plane `first_plane` of the volume's grid on.
Channel make_channel(const ExtinctionVolume& volume, const std::vector<Light>& lights, int channel, double delta_m_fraction,
                     int first_plane = 0);

// The first-collision source per cell and direction (regrouped and padded: [cell * padded + i]),
// in float32 or, divided by a per-cell scale (the cell's largest value), in float16.
struct FirstCollision {
  std::vector<float> values;
  // Or, where every light is directional and nothing emits (`separable` asked for): values[cell][d] =
  // sum_l factor[cell * lights + l] rows[l * padded + d], each light's phase row in the padded order.
  std::vector<float> rows, factor;
  int lights = 0;
  std::vector<simd::Half> half;
  std::vector<float> scale;  // [cell], with `half`
  std::vector<float> slope;  // [cell * 3 + axis]: the source's change across the cell over its mean
};

// Radiance entering through the grid's faces (DomBoundary) for one channel: per octant and the
// upwind face across each axis, per face cell and the octant's padded directions (P of them):
// x faces [(k * ny + j) * P + e], y faces [(k * nx + i) * P + e], z faces [(j * nx + i) * P + e].
struct Faces {
  std::array<std::array<std::vector<float>, 3>, 8> values;
};

// The directions regrouped by octant (signs of x, y, z), so that each octant's directions share
// one upwind order through the grid, with their separable-phase rows and face coefficients.
class Transport {
 public:
  // With an exchange, over its planes of `density` only: the sweeps trade z faces through it.
  Transport(const DenseGrid& density, const DirectionSet& directions, const PhaseMatrix& matrix, const SeparablePhase& separable,
            DomSpatial spatial, bool scalar_kernel, DomExchange* exchange = nullptr);

  // One upwind sweep of every direction by the spatial scheme (simd/dom_sweep.h; step:
  // L_d = (sigma_s S_d + sum_e a_e L_up,e) / (sigma_t + sum_e a_e),  a_e = |w_e| / h_e), with
  //   S_d = first[cell][d] + sum_k lambda_k Q[d][k] m_in[cell * N + k]   (seed 000 eq. 9),
  // radiance `boundary` entering through every face (or, given, `faces`), and the moments of the
  // result  m_out[cell * N + k] = sum_d Q[d][k] L_d   (eq. 10).
  // first (from first_collision) and m_in may be null; with first and no m_in it sets the
  // channel's fix-up marks (Channel::bounded). Rows run through dom_sweep_row. Directions
  // going up and going down run on two threads into separate buffers, summed in a fixed order.
  void sweep(const Channel& channel, const FirstCollision* first, const float* m_in, float boundary, float* m_out, int threads,
             const Faces* faces = nullptr) const;

  // The boundary's radiance at the centre of every face cell, per channel (1 or 3).
  std::vector<Faces> faces(const DomBoundary& boundary, const DenseGrid& grid, int channels, int threads) const;

  // The first-collision source from point, spot and directional lights, depths[i] to lights[i],
  // per cell and direction, before the factor sigma_s:
  //   sum_lights p(w_light . w_d) E_light e^(-sigma_t depth) / sum_j p(w_light . w_j) w_j,
  // normalized so its quadrature over directions is exactly E e^(-sigma_t depth), times `scale`
  // (1 / (1 - f) under delta-M scaling, so that the scaled sigma_s gives back the true one).
  // In float16 when `half`; separable (FirstCollision::rows) when asked and every light is
  // directional and nothing emits (not with `half`).
  FirstCollision first_collision(const ExtinctionVolume& volume, const std::vector<Light>& lights, const std::vector<DenseGrid>& depths,
                                 int channel, double scale, bool half, int threads, bool separable = false) const;

  // The paper's scheme: full radiance per cell and direction, every cell updated from its upwind
  // neighbours' previous values (Jacobi). Returns the moments; appends one change per iteration.
  std::vector<float> paper(const Channel& channel, const FirstCollision& first, const std::vector<float>* warm,
                           const DomSettings& settings, int& iterations, std::vector<double>& changes) const;

  // Wall time spent in sweep() and paper() so far.
  double seconds() const { return seconds_; }
  // The share of cell-octant visits sweep() skipped so far (empty cells no radiance reaches yet).
  double skipped_fraction() const { return cells_visited_ > 0 ? static_cast<double>(cells_skipped_) / static_cast<double>(cells_visited_) : 0.0; }

 private:
  std::array<int, 3> n_;            // the cells solved: with an exchange, its planes'
  size_t cells_;
  int plane0_ = 0;                  // the first of them in the volume's grid
  DomExchange* exchange_;
  int d_, n_terms_;
  bool full_;                       // N = D: the paper scheme multiplies by the matrix itself
  std::vector<float> matrix_;       // [i * D + j]: P between regrouped directions i and j, when full_
  mutable std::vector<float> scratch_;  // the second half's sweep output
  mutable double seconds_ = 0.0;
  mutable long long cells_skipped_ = 0, cells_visited_ = 0;
  bool scalar_kernel_;
  std::vector<Vec3> directions_;    // regrouped
  std::array<int, 9> start_{};      // octant o holds regrouped directions [start_[o], start_[o + 1])
  std::vector<float> a_;            // [i * 3 + e]: |w_e| / h_e
  std::vector<float> q_, lq_;       // [i * N + k]: Q[order[i]][k] and lambda_k Q[order[i]][k]
  // The kernel's view: per octant, its directions padded to a multiple of 8.
  struct Octant {
    std::vector<float> a, lq, q;
    DomOctant view;
    size_t offset = 0;              // of its first direction in a cell's padded run
  };
  std::array<Octant, 8> octants_;
  size_t padded_ = 0;               // directions per cell in the padded layout
  std::vector<size_t> padded_index_;  // regrouped direction i -> its place in the padded layout
};

}  // namespace haze::grids::dom
