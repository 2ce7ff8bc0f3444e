// Error and cost of method "network" (seed 001) for docs/NETWORKS.md, against the reference path
// tracer on the particles' continuous density:
// - examples/particle_cloud.json at the defaults, single scattering alone and in full;
// - the example as D and the separable terms N vary;
// - a procedural cloud (three overlapping balls) drawn with 500 to 30000 particles, at the defaults.
// Writes network_error.csv into the directory given (default .) and prints markdown tables.
// Not a Google Benchmark: it measures error, and the time each setting costs on this machine.
// Run: build/release/bench/haze_network_accuracy build/network
#include <haze/core/method.h>
#include <haze/core/stopwatch.h>
#include <haze/core/rng.h>
#include <haze/particles/field.h>
#include <haze/particles/methods.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

using namespace haze;

namespace {

struct Reference {
  RenderResult result;
  double seconds = 0.0;
};

Reference reference(const Scene& scene, long long spp, int max_scattering = -1) {
  RenderOptions options;
  options.settings = {{"spp", spp}, {"seed", 7}, {"max_scattering", max_scattering}};
  Stopwatch start;
  Reference r{render(scene, "reference", options)};
  r.seconds = start.seconds();
  return r;
}

void row(std::FILE* csv, const char* scene_name, const Scene& scene, const Reference& ref, const char* varied, int directions,
         int iterations, int terms = 0) {
  RenderOptions options;
  options.settings = {{"directions", directions}, {"iterations", iterations}, {"terms", terms}};
  Stopwatch start;
  const RenderResult network = render(scene, "network", options);
  const double seconds = start.seconds();
  const LitPixelError e = lit_pixel_error(network.radiance, ref.result.radiance, &*ref.result.std_error);
  const auto particles = network.stats["particles"].get<long long>();
  std::printf("| %s | %s | %lld | %d | %d | %s | %.1f%% | %.1f%% | %+.1f%% | %.1f%% | %.3f |\n", scene_name, varied, particles, directions,
              network.stats["terms"].get<int>(), iterations == 0 ? "single" : "full", 100 * e.mean_abs, 100 * e.rms_noise_removed, 100 * e.signed_mean, 100 * e.noise_rms,
              seconds);
  std::fprintf(csv, "%s,%s,%lld,%d,%d,%d,%g,%g,%g,%g,%g\n", scene_name, varied, particles, directions, network.stats["terms"].get<int>(), iterations, e.mean_abs,
               e.rms_noise_removed, e.signed_mean, e.noise_rms, seconds);
  std::fflush(stdout);
}

// N particles uniform in the union of three balls, each carrying the density 1: a cloud whose
// continuous density is about 1 inside whatever N is (field.h sizes the particles from their
// neighbours), so the N sweep compares representations of one medium.
Scene three_balls(const Scene& like, int count) {
  const Vec3 centres[3] = {Vec3(-0.35, -0.1, 0.0), Vec3(0.4, 0.05, -0.1), Vec3(0.0, 0.35, 0.15)};
  const double radii[3] = {0.55, 0.5, 0.45};
  Rng rng(17);
  nlohmann::json positions = nlohmann::json::array();
  while (static_cast<int>(positions.size()) < count) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    for (int b = 0; b < 3; ++b)
      if (glm::length(x - centres[b]) < radii[b]) {
        positions.push_back({x.x, x.y, x.z});
        break;
      }
  }
  Scene scene = like;
  scene.medium = particles::particle_medium(particles::ParticleSet::from_json(
      {{"positions", positions}, {"sigma_t", {6.0, 6.6, 7.2}}, {"albedo", 0.9}, {"phase", {{"type", "hg"}, {"g", 0.3}}}}));
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  particles::register_methods();
  const std::filesystem::path dir = argc > 1 ? argv[1] : ".";
  const long long spp = argc > 2 ? std::stoll(argv[2]) : 4096;
  std::filesystem::create_directories(dir);
  std::FILE* csv = std::fopen((dir / "network_error.csv").c_str(), "w");
  if (!csv) return 1;
  std::fprintf(csv, "scene,varied,particles,directions,terms,iterations,mean_abs,rms_corrected,signed,reference_noise,seconds\n");

  Scene example = Scene::load(std::filesystem::path(HAZE_SOURCE_DIR) / "examples" / "particle_cloud.json");
  const Reference single = reference(example, spp, 1), full = reference(example, spp);
  std::printf("Against the reference path tracer at %lld spp on the particles' density (a 96-cell grid; %.0f s for the full\n"
              "reference). Errors over lit pixels: mean |relative error|, its rms with the reference's variance removed,\n"
              "the signed mean, and the reference's own mean relative standard error. Seconds: the network's whole render\n"
              "on 2 threads.\n\n",
              spp, full.seconds);
  std::printf("| scene | varied | particles | D | N | scattering | mean abs | rms, noise removed | signed | reference noise | seconds |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|\n");
  row(csv, "example", example, single, "defaults", 128, 0);
  row(csv, "example", example, full, "defaults", 128, 200);
  for (int d : {32, 64, 256, 512}) row(csv, "example", example, full, "directions", d, 200);
  row(csv, "example", example, full, "terms", 128, 200, 128);  // the full phase matrix
  row(csv, "example", example, full, "terms", 128, 200, 4);
  for (int count : {500, 1000, 3000, 10000, 30000}) {
    const Scene balls = three_balls(example, count);
    const Reference r = reference(balls, spp);
    row(csv, "three balls", balls, r, "particles", 128, 200);
  }
  std::fclose(csv);
  return 0;
}
