// Registration of the particle methods (network) with core's method registry.
#pragma once

namespace haze::particles {

// Registers every particle method this build has; safe to call more than once. Today there is
// none yet: the illumination-network method lands here.
void register_methods();

}  // namespace haze::particles
