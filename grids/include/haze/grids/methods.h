// Registration of the grid methods (propagation, dom) with core's method registry.
#pragma once

namespace haze::grids {

// Registers every grid-based method this build has; safe to call more than once. Today there is
// none yet: heterogeneous single scattering (propagation) and discrete ordinates (dom) land here.
void register_methods();

}  // namespace haze::grids
