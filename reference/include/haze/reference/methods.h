// The yardsticks every fast method is measured against: method "reference", the unbiased
// volumetric path tracer (docs/REFERENCE.md), and method "quadrature", deterministic single
// scattering by numerical quadrature for any medium. Module reference/ (target haze::reference).
#pragma once

#include <haze/core/method.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::reference {

// The registry's entries (reference/src/reference.cpp, quadrature.cpp).
MethodInfo reference_info();
MethodInfo quadrature_info();
// Registers "reference" and "quadrature"; safe to call more than once.
void register_methods();

}  // namespace haze::reference

#pragma GCC visibility pop
