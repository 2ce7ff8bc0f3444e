#include <haze/particles/methods.h>

namespace haze::particles {

void register_methods() {}

}  // namespace haze::particles
