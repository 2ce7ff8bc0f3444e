// haze compare: error of one EXR against another (the reference), with the reference's own noise
// when its standard-error layer is present.
#include "commands.h"

#include <haze/core/error.h>

#include <iostream>

namespace haze::app {

namespace {

struct CompareArgs {
  std::string image, reference;
  bool json = false;
  int worst = 0;
};

int run(const CompareArgs& a) {
  Image image = read_exr(a.image);
  std::optional<Image> ref_error;
  Image reference = read_exr(a.reference, &ref_error);
  nlohmann::json out = {{"image", a.image},
                        {"reference", a.reference},
                        {"rmse", rmse(image, reference)},
                        {"relative_rmse", relative_rmse(image, reference)}};
  Rgb mi = image.mean(), mr = reference.mean();
  out["mean"] = {mi.r, mi.g, mi.b};
  out["reference_mean"] = {mr.r, mr.g, mr.b};
  // The reference's own noise: the RMS of its per-pixel standard errors.
  if (ref_error) out["reference_noise_rms"] = rms(*ref_error);
  // The trade suite's measure (docs/TRADEOFFS.md): relative error over the lit pixels, with the
  // reference's noise removed when its standard-error layer is present.
  const LitPixelError lit = lit_pixel_error(image, reference, ref_error ? &*ref_error : nullptr);
  out["lit_pixels"] = lit.pixels;
  out["lit_mean_abs_relative"] = lit.mean_abs;
  out["lit_signed_mean_relative"] = lit.signed_mean;
  if (ref_error) out["lit_rms_relative_noise_removed"] = lit.rms_noise_removed, out["lit_reference_noise_rms"] = lit.noise_rms;
  const std::vector<PixelError> worst = worst_pixels(image, reference, ref_error ? &*ref_error : nullptr, a.worst);
  for (const PixelError& w : worst)
    out["worst"].push_back({{"x", w.x}, {"y", w.y}, {"relative_error", w.relative}, {"reference_noise", w.noise}, {"share", w.share}});
  if (a.json) {
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "RMSE " << out["rmse"].get<double>() << ", relative RMSE " << out["relative_rmse"].get<double>();
    if (ref_error) std::cout << " (reference noise RMS " << out["reference_noise_rms"].get<double>() << ")";
    std::cout << "\nlit pixels " << lit.pixels << ": mean |relative error| " << lit.mean_abs << ", signed mean " << lit.signed_mean;
    if (ref_error)
      std::cout << ", RMS relative error with the reference's noise removed " << lit.rms_noise_removed << " (reference noise "
                << lit.noise_rms << ")";
    std::cout << "\n";
    for (const PixelError& w : worst)
      std::cout << "pixel (" << w.x << ", " << w.y << "): relative error " << w.relative << " (reference noise " << w.noise << "), "
                << 100.0 * w.share << "% of the squared error\n";
  }
  return 0;
}

}  // namespace

Command add_compare(CLI::App& app) {
  auto* sub = app.add_subcommand("compare", "Error of an EXR image against a reference EXR");
  auto a = std::make_shared<CompareArgs>();
  sub->add_option("image", a->image, "Image to measure")->required()->check(CLI::ExistingFile);
  sub->add_option("reference", a->reference, "Reference image")->required()->check(CLI::ExistingFile);
  sub->add_flag("--json", a->json, "Print JSON");
  sub->add_option("--worst", a->worst, "List the N lit pixels that carry the most squared error (less the reference's noise)")
      ->check(CLI::NonNegativeNumber);
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
