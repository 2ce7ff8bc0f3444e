// Core's tests see the yardsticks (quadrature, reference), analytic and auto, which lived in core
// until they became modules of their own, but nothing else: what auto picks and what a
// scene may name with only those registered is part of what they test.
#include <haze/analytic/methods.h>
#include <haze/auto/auto.h>
#include <haze/reference/methods.h>

namespace {
const bool registered = (haze::reference::register_methods(), haze::analytic::register_methods(), haze::register_auto(), true);
}  // namespace
