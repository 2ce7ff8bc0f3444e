// haze render --display gl (commands.h).
#include "commands.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#ifdef HAZE_WITH_GL
#include <haze/gl/context.h>
#include <haze/gl/display.h>
#include <haze/grids/solution.h>
#endif

namespace haze::app {

#ifdef HAZE_WITH_GL
RenderResult render_gl(const Scene& scene, const std::string& method, const RenderOptions& options) {
  gl::HeadlessContext context;
  RenderOptions prepared = options;
  prepared.single_view = true;
  const Solution solution = prepare(scene, method, prepared);
  const auto* grid = dynamic_cast<const grids::GridSolution*>(&solution.method_solution());
  if (!grid) throw Error("--display gl", "method \"" + method + "\"", "a method whose solution keeps grid fields (propagation, dom)");
  Stopwatch watch;
  gl::VolumeDisplay display(*grid);
  const double upload_seconds = watch.lap();
  RenderResult result{display.render(scene.camera), std::nullopt, solution.stats()};
  result.stats["gl"] = {{"backend", context.info().backend},
                        {"renderer", context.info().renderer},
                        {"version", context.info().version},
                        {"upload_seconds", upload_seconds},
                        {"display_seconds", watch.seconds()}};
  return result;
}
#else
RenderResult render_gl(const Scene&, const std::string&, const RenderOptions&) {
  throw Error("--display", "gl", "a build with HAZE_WITH_GL=ON (this one was configured without GL)");
}
#endif

}  // namespace haze::app
