// Registration of the particle methods (network) with core's method registry.
#pragma once

namespace haze::particles {

// Registers method "network" and the conversion of a scene's particles into a medium (their
// continuous density on a grid, field.h) for every other method; safe to call more than once.
void register_methods();

}  // namespace haze::particles
