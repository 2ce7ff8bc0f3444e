// Method "analytic" (seed 002): closed-form single scattering in a homogeneous medium from point
// and spot lights, registered with core's method registry.
#pragma once

#include <haze/core/method.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

// The registry's entry (analytic/src/analytic.cpp).
MethodInfo analytic_info();
// Registers "analytic"; safe to call more than once.
void register_methods();

}  // namespace haze::analytic

#pragma GCC visibility pop
