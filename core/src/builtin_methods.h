// Core's own rendering methods, registered by method.cpp.
#pragma once

#include <haze/core/method.h>

namespace haze {
// The registry's entry for a method (throws haze::Error listing the methods when unknown;
// method.cpp, for solution.cpp).
MethodInfo method_info(const std::string& name);
// The form of method `name` split over processes (register_split); when it has none, null for
// one rank and a haze::Error naming those there are for more.
std::unique_ptr<Method> create_split(const std::string& name, int ranks);
}  // namespace haze

namespace haze::internal {

// The value of the haze::Error a MethodSolution without lighting fields throws.
inline constexpr const char* kNoField = "not kept by this method";
// How far a ray leaving a surface starts off it, along the normal.
inline constexpr double kSurfaceOffset = 1e-7;

// Deterministic single scattering by numerical quadrature (quadrature.cpp).
MethodInfo quadrature_info();
// The unbiased volumetric path tracer every fast method is measured against (reference.cpp).
MethodInfo reference_info();

}  // namespace haze::internal
