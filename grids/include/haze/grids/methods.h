// Registration of the grid methods (propagation, dom) with core's method registry.
#pragma once

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

// Registers "propagation" and "dom"; safe to call more than once.
void register_methods();

}  // namespace haze::grids

#pragma GCC visibility pop
