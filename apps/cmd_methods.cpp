// haze methods: every registered method with what it handles and its settings (MethodInfo), as
// text or as the markdown tables docs/METHODS.md holds.
#include "commands.h"

#include <iostream>

namespace haze::app {

std::string methods_help() {
  std::string out = "Methods and their settings (--set key=value):\n";
  for (const MethodInfo& m : registered_methods()) out += m.name + ": " + m.summary + "\n" + settings_help(m);
  return out;
}

Command add_methods(CLI::App& app) {
  auto* sub = app.add_subcommand("methods", "Every method: what it handles and its settings (from the registry)");
  auto markdown = std::make_shared<bool>(false);
  auto name = std::make_shared<std::string>();
  sub->add_option("name", *name, "One method only");
  sub->add_flag("--markdown", *markdown, "The settings tables of docs/METHODS.md");
  return {sub, [markdown, name] {
            bool found = false;
            for (const MethodInfo& m : registered_methods()) {
              if (!name->empty() && m.name != *name) continue;
              found = true;
              if (*markdown) {
                std::cout << "Settings of `" << m.name << "`:\n\n" << settings_markdown(m) << "\n";
                continue;
              }
              const MethodHandles& h = m.handles;
              std::cout << m.name << ": " << m.summary << "\n  media: " << h.media << "\n  lights: " << h.lights << "\n  surfaces: " << h.surfaces
                        << "\n  scattering: " << (h.multiple_scattering ? "multiple" : "single") << "\n  settings:\n"
                        << settings_help(m);
            }
            if (!found) create_method(*name);  // the error lists the available methods
            return 0;
          }};
}

}  // namespace haze::app
