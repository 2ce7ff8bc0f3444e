// Blackbody colours: Planck's law against the CIE 1931 colour-matching functions, tabulated.
#include <haze/core/blackbody.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace haze {
namespace {

// Wyman, Sloan and Shirley 2013, "Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", eq. 2 (multi-lobe fit): piecewise Gaussians with a width on each side of the mean.
double lobe(double lambda, double mu, double s1, double s2) {
  const double t = (lambda - mu) / (lambda < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}
Vec3 cie_1931(double nm) {
  return {1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) - 0.065 * lobe(nm, 501.1, 20.4, 26.2),
          0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1),
          1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8)};
}

// Planck's spectral radiance at `nm` and `kelvin`, up to a constant factor (normalized away).
double planck(double nm, double kelvin) {
  constexpr double c2 = 1.4387769e7;  // h c / k in nm K
  const double x = c2 / (nm * kelvin);
  if (x > 700.0) return 0.0;
  return 1.0 / (std::pow(nm * 1e-3, 5) * std::expm1(x));
}

Vec3 xyz(double kelvin) {
  Vec3 sum(0.0);
  for (int nm = 360; nm <= 830; ++nm) sum += planck(nm, kelvin) * cie_1931(nm) * ((nm == 360 || nm == 830) ? 0.5 : 1.0);
  return sum;
}

constexpr double kMinKelvin = 500.0, kMaxKelvin = 50000.0;
constexpr int kTable = 1024;

struct Table {
  std::array<Rgb, kTable> colors;
  Table() {
    for (int i = 0; i < kTable; ++i)
      colors[static_cast<size_t>(i)] = blackbody_color_integrated(kMinKelvin * std::pow(kMaxKelvin / kMinKelvin, i / (kTable - 1.0)));
  }
};

}  // namespace

Rgb blackbody_color_integrated(double kelvin) {
  const Vec3 c = xyz(kelvin);
  // XYZ to linear Rec.709 primaries with the D65 white (IEC 61966-2-1).
  Rgb rgb(3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z, -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
          0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z);
  rgb = glm::max(rgb, Rgb(0.0));
  const double luminance = 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
  return luminance > 0.0 ? rgb / luminance : Rgb(0.0);
}

Vec3 blackbody_chromaticity(double kelvin) {
  const Vec3 c = xyz(kelvin);
  const double sum = c.x + c.y + c.z;
  return {c.x / sum, c.y / sum, 0.0};
}

Rgb blackbody_color(double kelvin) {
  static const Table table;
  if (!(kelvin > kMinKelvin)) return table.colors.front();
  if (!(kelvin < kMaxKelvin)) return table.colors.back();
  const double u = std::log(kelvin / kMinKelvin) / std::log(kMaxKelvin / kMinKelvin) * (kTable - 1);
  const auto i = std::min(static_cast<size_t>(u), static_cast<size_t>(kTable - 2));
  const double f = u - static_cast<double>(i);
  return table.colors[i] * (1.0 - f) + table.colors[i + 1] * f;
}

}  // namespace haze
