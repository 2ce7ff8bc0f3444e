// A toy method added in this one file, as a module would add one: the registry, settings
// validation, the help text and method "auto" all see it through its MethodInfo alone.
#include <haze/auto/auto.h>
#include <haze/core/error.h>
#include <haze/core/method.h>

#include <gtest/gtest.h>

#include <algorithm>

namespace haze {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kToyName = "toy";
namespace {

// Renders every pixel at `brightness` times the medium's albedo.
class ToySolution final : public MethodSolution {
 public:
  ToySolution(const Rgb& value) : value_(value) {}
  RenderResult render(const View& view, const RenderOptions&) const override {
    Image image(view.camera.width_px, view.camera.height_px);
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x) image.set(x, y, value_);
    return {image, std::nullopt, {{"toy", true}}};
  }

 private:
  Rgb value_;
};

class ToyMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    Settings settings(options.settings, kToyName);
    const double brightness = settings.number("brightness");
    settings.reject_unknown();
    return std::make_unique<ToySolution>(brightness * scene.medium.value_or(MediumDesc{}).albedo);
  }
};

MethodInfo toy_info() {
  MethodInfo info;
  info.name = kToyName;
  info.summary = "a constant image (a test of the registry)";
  info.create = [] { return std::make_unique<ToyMethod>(); };
  info.handles = {"any", "any", "none", false};
  info.settings = {SettingInfo::number("brightness", 1.0, 0.0, 10.0, "the image's value over the albedo")};
  info.trade_sweep = {{{"brightness", 1.0}}};
  info.offer = [](const SceneFeatures& f, double) {
    if (!f.homogeneous) return AutoOffer{false, {}, 0.0, "homogeneous media only"};
    return AutoOffer{true, {{"brightness", 2.0}}, 1e-9, "faster than anything"};
  };
  return info;
}

Scene fog() {
  Scene scene;
  scene.camera.width_px = scene.camera.height_px = 4;
  MediumDesc medium;
  medium.bounds = {Vec3(-1.0), Vec3(1.0)};
  medium.albedo = Rgb(0.25);
  scene.medium = medium;
  scene.lights.push_back(PointLight{Vec3(0.0, 2.0, 0.0), Rgb(1.0)});
  return scene;
}

TEST(ToyMethod, RegistrySettingsHelpAndAutoSeeIt) {
  register_method(toy_info());
  const auto methods = registered_methods();
  const auto toy = std::find_if(methods.begin(), methods.end(), [](const MethodInfo& m) { return m.name == "toy"; });
  ASSERT_NE(toy, methods.end());
  EXPECT_NE(settings_help(*toy).find("brightness: the image's value over the albedo (a number in [0, 10], default 1.0)"), std::string::npos)
      << settings_help(*toy);

  RenderOptions options;
  options.settings = {{"brightness", 20}};
  try {
    prepare(fog(), "toy", options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "method.brightness");
    EXPECT_EQ(e.expected(), "a number in [0, 10]");
  }
  options.settings = {{"brightnes", 2}};
  try {
    prepare(fog(), "toy", options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.expected(), "a setting of toy: brightness");
  }

  const AutoChoice choice = choose_method(fog(), 0.05);
  EXPECT_EQ(choice.method, "toy");
  EXPECT_EQ(choice.settings["brightness"], 2.0);
  const RenderResult r = render(fog(), "auto");
  EXPECT_EQ(r.stats["auto"]["method"], "toy");
  EXPECT_FLOAT_EQ(r.radiance.at(0, 0).r, 0.5f);
  register_method({"toy", "gone", [] { return std::make_unique<ToyMethod>(); }, {}, {}, {}, nullptr});  // no offer: auto forgets it
  EXPECT_NE(choose_method(fog(), 0.05).method, "toy");
}

// A method that does not render a host's layers (MethodSolution::renders_layers) is refused a view
// that asks for them, or for a depth buffer, rather than ignoring it.
TEST(ToyMethod, ViewsItCannotRenderAreRefused) {
  register_method(toy_info());
  const Scene scene = fog();
  const std::vector<float> depth(16, 1.0f);
  for (const View& view : {View{scene.camera, {}, true}, View{scene.camera, depth, false}}) {
    try {
      render(scene, "toy", {}, view);
      FAIL();
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), "view");
    }
  }
  EXPECT_FLOAT_EQ(render(scene, "toy", {}, View{scene.camera}).radiance.at(0, 0).r, 0.25f);
}

}  // namespace
}  // namespace haze
