// haze render --display gl (commands.h).
#include "commands.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#ifdef HAZE_WITH_GL
#include <haze/gl/context.h>
#include <haze/gl/display.h>
#include <haze/grids/dom.h>
#include <haze/grids/propagation.h>

#endif

namespace haze::app {

#ifdef HAZE_WITH_GL
RenderResult render_gl(const Scene& scene, const std::string& method, const RenderOptions& options) {
  if (method != "propagation" && method != "dom")
    throw Error("--display gl", "method \"" + method + "\"", "method propagation or dom (the methods with grid fields to display)");
  gl::HeadlessContext context;
  gl::DisplaySettings settings;
  nlohmann::json stats;
  std::optional<gl::VolumeDisplay> display;
  Stopwatch start;
  if (method == "propagation") {
    grids::PropagationFields fields = grids::propagation_fields(scene, options);
    settings.step_cells = fields.march.step_cells;
    start.restart();
    display.emplace(scene, fields.volume, fields.depths, settings);
    stats = std::move(fields.stats);
  } else {
    grids::DomFields fields = grids::dom_fields(scene, options);
    settings.step_cells = fields.step_cells;
    start.restart();
    display.emplace(scene, fields.volume, fields.delta_depths, settings);
    display->show_dom(fields.solution);
    stats = std::move(fields.stats);
  }
  const double upload_seconds = start.seconds();
  start.restart();
  RenderResult result{display->render(scene.camera), std::nullopt, std::move(stats)};
  result.stats["gl"] = {{"backend", context.info().backend},
                        {"renderer", context.info().renderer},
                        {"version", context.info().version},
                        {"upload_seconds", upload_seconds},
                        {"display_seconds", start.seconds()}};
  return result;
}
#else
RenderResult render_gl(const Scene&, const std::string&, const RenderOptions&) {
  throw Error("--display", "gl", "a build with HAZE_WITH_GL=ON (this one was configured without GL)");
}
#endif

}  // namespace haze::app
