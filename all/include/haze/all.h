// Every module this build of Haze has, registered with core's registries in one call: the
// yardsticks (reference, quadrature), method auto, the methods of analytic, grids and particles and
// the density types of particles and vdb. The command, Python, the examples and the
// tests call it.
#pragma once

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// Registers everything above; safe to call more than once, from any thread.
void register_all();

}  // namespace haze

#pragma GCC visibility pop
