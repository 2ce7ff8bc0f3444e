#include <haze/grids/methods.h>
#include <haze/grids/propagation.h>

namespace haze::grids {

void register_methods() {
  register_method({"propagation", "single scattering in heterogeneous media: RBF injection, optical-depth volumes, ray marching (seed 003)",
                   make_propagation_method});
}

}  // namespace haze::grids
