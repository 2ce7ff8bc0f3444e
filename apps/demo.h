// `haze demo`'s arguments, shared by its two parts: the papers' showcase (cmd_demo.cpp) and the
// contact sheets of every method on the built-in scenes (--sheets, cmd_demo_sheets.cpp).
#pragma once

#include <string>

namespace haze::app {

struct DemoArgs {
  std::string out = "haze-demo";
  std::string examples = HAZE_EXAMPLES_DIR;
  int threads = 0;
  double reference_seconds = 30.0;  // --sheets: time each uncached reference may take
  bool sheets = false, make_references = false;
};

// --sheets: every examples/*.json scene with every method against a cached reference.
int run_sheets(const DemoArgs& a);

}  // namespace haze::app
