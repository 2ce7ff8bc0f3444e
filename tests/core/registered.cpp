// Core's tests see core's own methods (quadrature, reference) with analytic and auto, which lived
// in core until they became modules of their own, but nothing else: what auto picks and what a
// scene may name with only those registered is part of what they test.
#include <haze/analytic/methods.h>
#include <haze/auto/auto.h>

namespace {
const bool registered = (haze::analytic::register_methods(), haze::register_auto(), true);
}  // namespace
