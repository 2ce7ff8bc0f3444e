// haze info: version, SIMD targets, threads, GL availability, registered methods.
#include "commands.h"

#include <haze/core/method.h>
#include <haze/simd/phase_batch.h>
#ifdef HAZE_WITH_GL
#include <haze/gl/context.h>
#endif

#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include <iostream>

namespace haze::app {

Command add_info(CLI::App& app) {
  auto* sub = app.add_subcommand("info", "Version, SIMD targets, threads, GL availability and methods");
  auto json = std::make_shared<bool>(false);
  sub->add_flag("--json", *json, "Print JSON");
  return {sub, [json] {
            nlohmann::json out;
            out["version"] = HAZE_VERSION;
            out["simd"] = {{"available_targets", simd::available_targets()}, {"selected", simd::selected_target()}};
            out["threads"] = tbb::info::default_concurrency();
#ifdef HAZE_WITH_GL
            auto gl = gl::probe();
            out["gl"] = {{"built", true}, {"available", gl.available}, {"backend", gl.backend},
                         {"renderer", gl.renderer}, {"version", gl.version}, {"error", gl.error}};
#else
            out["gl"] = {{"built", false}, {"available", false}};
#endif
            for (const auto& m : registered_methods()) out["methods"][m.name] = m.summary;
            if (*json) {
              std::cout << out.dump(2) << "\n";
              return 0;
            }
            std::cout << "haze " << HAZE_VERSION << "\n";
            std::cout << "simd: selected " << out["simd"]["selected"].get<std::string>() << "; available";
            for (const auto& t : out["simd"]["available_targets"]) std::cout << " " << t.get<std::string>();
            std::cout << "\nthreads: " << out["threads"] << " (oneTBB default; --threads caps it)\n";
            if (!out["gl"]["built"].get<bool>()) {
              std::cout << "gl: not built (HAZE_WITH_GL=OFF)\n";
            } else if (out["gl"]["available"].get<bool>()) {
              std::cout << "gl: " << out["gl"]["backend"].get<std::string>() << ", " << out["gl"]["renderer"].get<std::string>()
                        << ", OpenGL " << out["gl"]["version"].get<std::string>() << "\n";
            } else {
              std::cout << "gl: unavailable (" << out["gl"]["error"].get<std::string>() << ")\n";
            }
            std::cout << "methods:\n";
            for (const auto& [name, summary] : out["methods"].items())
              std::cout << "  " << name << ": " << summary.get<std::string>() << "\n";
            return 0;
          }};
}

}  // namespace haze::app
