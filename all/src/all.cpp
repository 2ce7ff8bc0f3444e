#include <haze/all.h>
#include <haze/analytic/methods.h>
#include <haze/auto/auto.h>
#include <haze/grids/methods.h>
#include <haze/particles/methods.h>
#include <haze/reference/methods.h>
#include <haze/vdb/vdb.h>

namespace haze {

void register_all() {
  reference::register_methods();
  register_auto();
  analytic::register_methods();
  grids::register_methods();
  particles::register_methods();
  vdb::register_readers();
}

}  // namespace haze
