#include <haze/all.h>
#include <haze/analytic/methods.h>
#include <haze/grids/methods.h>
#include <haze/particles/methods.h>
#include <haze/vdb/vdb.h>

namespace haze {

void register_all() {
  analytic::register_methods();
  grids::register_methods();
  particles::register_methods();
  vdb::register_readers();
}

}  // namespace haze
