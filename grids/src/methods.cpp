#include <haze/grids/dom.h>
#include <haze/grids/methods.h>
#include <haze/grids/propagation.h>

namespace haze::grids {

void register_methods() {
  register_method({"propagation", "single scattering in heterogeneous media: RBF injection, optical-depth volumes, ray marching (seed 003)",
                   make_propagation_method, false, true});
  register_method({"dom", "multiple scattering on grids: discrete ordinates with a separable phase function (seed 000)",
                   make_dom_method});
}

}  // namespace haze::grids
