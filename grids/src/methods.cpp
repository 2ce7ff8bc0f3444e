#include <haze/grids/methods.h>

namespace haze::grids {

void register_methods() {}

}  // namespace haze::grids
