#include <haze/grids/dom.h>
#include <haze/grids/methods.h>
#include <haze/grids/propagation.h>

namespace haze::grids {

void register_methods() {
  register_method(propagation_info());
  register_method(dom_info());
}

}  // namespace haze::grids
