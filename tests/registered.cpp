// Every test program starts with all that this build has registered (haze/all.h), as the command
// and Python do, so that a test names any method or density type without registering it first.
#include <haze/all.h>

namespace {
const bool registered = (haze::register_all(), true);
}  // namespace
