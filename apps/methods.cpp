#include "commands.h"

#include <haze/grids/methods.h>
#include <haze/particles/methods.h>

namespace haze::app {

void register_all_methods() {
  grids::register_methods();
  particles::register_methods();
}

}  // namespace haze::app
