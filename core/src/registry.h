// The registry's internals, for solution.cpp.
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

}  // namespace haze::internal
