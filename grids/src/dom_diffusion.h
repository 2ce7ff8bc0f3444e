// Diffusion synthetic acceleration of the DOM's source iteration (Alcouffe 1977; Adams & Larsen
// 2002, sec. 3): after a sweep x -> x' = b + K x, the slow, nearly isotropic part of the error
// obeys the diffusion equation
//   -div(D grad e) + sigma_a e = sigma_s (phi' - phi),   D = 1 / (3 sigma_t),
// (phi the mean radiance: moment 0 times its basis vector's constant entry) with vacuum (Marshak)
// boundaries; adding e to phi' removes it. Cell-centred finite volumes, harmonic face
// coefficients, solved by Jacobi-preconditioned conjugate gradients (internal).
#pragma once

#include "dom_internal.h"

#include <haze/grids/grid.h>

#include <vector>

namespace haze::grids::dom {

// Corrects `next` (moments after a sweep of `previous`, N terms per cell) in place.
// q0: the constant entry of the phase basis's first vector (+-1 / sqrt(D)). Returns the CG
// iterations it took (0 when there was nothing to correct).
int diffusion_correction(const DenseGrid& density, const Channel& channel, int terms, double q0, const std::vector<float>& previous,
                         std::vector<float>& next, int threads);

}  // namespace haze::grids::dom
