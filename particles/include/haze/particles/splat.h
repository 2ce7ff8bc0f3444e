// Particles splatted onto camera rays, front to back (seed 001 section 3.4: "sorts the particles
// according to their distance from the camera, splats them, and adds their contributions with alpha
// blending"), in float32 lanes over a tile's rays with Highway runtime dispatch. Per ray and particle
// p, in the order given:
//   tau_p = a_p exp(-r^2 / h_p^2) F_p          (a_p = w_p sqrt(pi) h_p: its Gaussian's integral along
//                                               a line through its centre; r the ray's distance to it)
//   L += T (1 - e^(-sigma_t tau_p)) S_p,   T *= e^(-sigma_t tau_p)     (per channel)
// F_p is the share of the Gaussian within the ray's [0, t_end]: 0.5 (erf((t1 - t_c) / h) - erf((t0 -
// t_c) / h)) over the part of [t_c - kCut h, t_c + kCut h] inside it (t_c the ray's closest
// approach; F_p = 1 when all of it is). A Gaussian ends at r = kCut h, as the exact march's
// (field.h). S_p, the particle's radiance toward the eye, is its scattered light s_p plus its direct
// light e_p at its centre c_p times a factor log-linear across the particle (gradient g_p), taken
// at the ray's closest approach shifted by m_p along it and averaged over the particle's weight
// along the ray (variance v_p = 2 u_p), at most e^(b_p):
//   S_p = s_p + e_p exp(min(b_p, g_p . D + u_p k^2)),  D = o + (t_c + m_p) d - c_p,  k = g_p . d.
// ISA-free header: per-target code in src/splat-inl.h.
#pragma once

#include <cstddef>
#include <cstdint>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

// The particles, structure of arrays, and a tile's list of them front to back.
struct SplatParticles {
  const float *x, *y, *z;
  const float* h;
  const float* amplitude;   // a_p = w_p sqrt(pi) h_p
  const float* source[3];   // s_p per channel
  const float* direct[3];   // e_p per channel
  const float *gx, *gy, *gz;  // g_p
  const float* max_log;       // b_p
  const float *shift, *spread;  // m_p, u_p
  const uint32_t* order;    // indices into the arrays above, front to back
  size_t count;             // entries of `order`
};

// `count` rays (origins, unit directions; a multiple of kSplatPad), each ending at t_end (null: none
// ends); the results per channel: radiance L (from 0) and transmittance T (from 1).
struct SplatRays {
  const float *ox, *oy, *oz, *dx, *dy, *dz;
  const float* t_end;
  float* radiance[3];
  float* transmittance[3];
  size_t count;
};
inline constexpr size_t kSplatPad = 16;
// A ray stops once its transmittance is under this in every channel (checked every 8 particles).
inline constexpr float kSplatOpaque = 1e-4f;

// channels: 1 when sigma_t is grey (one exponential serves all three), else 3.
void splat_rays(const SplatParticles& particles, const float sigma_t[3], int channels, const SplatRays& rays);
// The scalar reference, in float64 (std::exp, std::erf).
void splat_rays_reference(const SplatParticles& particles, const float sigma_t[3], const SplatRays& rays);

}  // namespace haze::particles

#pragma GCC visibility pop
