// Registration of the particle methods (network) with core's method registry.
#pragma once

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

// Registers method "network" and density type "particles" (a scene's `particles` block read into
// a medium over the Gaussians' own density, field.h); safe to call more than once.
void register_methods();

}  // namespace haze::particles

#pragma GCC visibility pop
