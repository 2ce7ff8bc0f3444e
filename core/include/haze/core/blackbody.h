// Blackbody colour and radiance for emission (docs/SCENES.md, "medium.emission", after Blender Cycles'
// Principled Volume): the Rec.709 colour of a Planck spectrum, normalized to luminance 1.
#pragma once

#include <haze/core/math.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// Stefan-Boltzmann's sigma as Cycles scales it (W/(m^2 K^4) * 1e-6 / pi): sigma T^4 is the
// blackbody term's radiance per unit length before its colour.
inline constexpr double kBlackbodySigma = 5.670373e-8 * 1e-6 / kPi;

// The linear Rec.709 colour of a blackbody at `kelvin`, luminance (0.2126 R + 0.7152 G + 0.0722 B)
// 1, negative channels clipped to 0 before the normalization: from a table of 1024 temperatures
// log-spaced over [500 K, 50000 K] (clamped outside), linear in log T between them.
Rgb blackbody_color(double kelvin);

// The same by direct integration of Planck's law against the CIE 1931 2-degree colour-matching
// functions (the multi-lobe fit of Wyman, Sloan and Shirley 2013), 360 to 830 nm in 1 nm steps,
// then XYZ to Rec.709 (D65). What the table is made of; the tests' yardstick.
Rgb blackbody_color_integrated(double kelvin);
// The CIE 1931 chromaticity (x, y) of that integration, as (x, y, 0).
Vec3 blackbody_chromaticity(double kelvin);

}  // namespace haze

#pragma GCC visibility pop
