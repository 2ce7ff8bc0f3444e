// haze: render participating media, inspect phase-function factorizations, run the demo.
#include "commands.h"
#include "mpi_world.h"

#include <haze/all.h>
#include <haze/core/error.h>

#include <iostream>
#include <memory>
#include <new>

int main(int argc, char** argv) {
  std::unique_ptr<haze::app::MpiWorld> world;  // under mpirun
  try {
    world = std::make_unique<haze::app::MpiWorld>(argc, argv);
  } catch (const haze::Error& e) {
    std::cerr << "haze: error: " << e.what() << "\n";
    return 2;
  }
  // Under mpirun each rank says which it is.
  const std::string who = haze::app::world_ranks() > 1
                               ? "haze (rank " + std::to_string(haze::app::world_rank()) + " of " + std::to_string(haze::app::world_ranks()) + ")"
                               : "haze";
  CLI::App app{"Haze: light transport in participating media (fog, haze, smoke, clouds)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("haze ") + HAZE_VERSION);
  haze::register_all();  // before the commands: their help lists the methods
  const haze::app::Command commands[] = {haze::app::add_info(app), haze::app::add_phase(app),
                                          haze::app::add_render(app), haze::app::add_demo(app),
                                          haze::app::add_compare(app), haze::app::add_tables(app),
                                          haze::app::add_bench(app), haze::app::add_methods(app)};
  CLI11_PARSE(app, argc, argv);
  try {
    for (const auto& command : commands)
      if (command.sub->parsed()) return command.run();
  } catch (const haze::Error& e) {
    std::cerr << who << ": error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {  // what check_memory's estimates missed
    std::cerr << who << ": error: memory: got an allocation the system refused, expected work that fits "
                 "(lower the resolution, directions, particles or lights, or give --max-memory)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << who << ": unexpected error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
