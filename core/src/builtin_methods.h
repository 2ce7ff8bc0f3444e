// Core's own rendering methods, registered by method.cpp.
#pragma once

#include <haze/core/method.h>

namespace haze::internal {

// Deterministic single scattering by numerical quadrature (quadrature.cpp).
std::unique_ptr<Method> make_quadrature_method();

}  // namespace haze::internal
