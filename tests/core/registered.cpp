// Core's tests see core's own methods (quadrature, reference, auto) and analytic, which lived in
// core until it became a module of its own, but nothing above them: what auto picks and what a
// scene may name with only those registered is part of what they test.
#include <haze/analytic/methods.h>

namespace {
const bool registered = (haze::analytic::register_methods(), true);
}  // namespace
