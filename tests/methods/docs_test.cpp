// docs/METHODS.md holds every registered method's settings table as `haze methods --markdown`
// prints it from the registry (MethodInfo::settings), so the docs cannot drift from the code.
#include <haze/core/method.h>
#include <haze/grids/methods.h>
#include <haze/particles/methods.h>

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace haze {
namespace {

TEST(Docs, MethodsMdHoldsEveryMethodsSettingsTable) {
  grids::register_methods();
  particles::register_methods();
  std::ifstream in(std::string(HAZE_DOCS_DIR) + "/METHODS.md");
  ASSERT_TRUE(in) << HAZE_DOCS_DIR;
  std::stringstream doc;
  doc << in.rdbuf();
  for (const MethodInfo& m : registered_methods()) {
    if (m.name == "toy") continue;  // tests/toy's
    EXPECT_NE(doc.str().find(settings_markdown(m)), std::string::npos) << m.name << ": regenerate with `haze methods " << m.name << " --markdown`:\n"
                                                                       << settings_markdown(m);
  }
}

}  // namespace
}  // namespace haze
