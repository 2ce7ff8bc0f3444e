#include "commands.h"

#include <haze/grids/methods.h>
#include <haze/particles/methods.h>
#include <haze/simd/airlight_batch.h>
#include <haze/vdb/vdb.h>

namespace haze::app {

void register_all_methods() {
  simd::install();
  grids::register_methods();
  particles::register_methods();
  vdb::register_readers();
}

}  // namespace haze::app
