// A particle medium (seed 001 section 2.1): particle p stands for its spherical neighbourhood of
// diameter delta_s_p and carries an extinction density rho_p, so sigma_t = sigma_t_scale * rho
// (docs/SCENES.md, "particles"); albedo and phase are shared by the set. Simulations hand particles over as spans
// (ParticleView, not copied); scenes give them in a `particles` block (docs/SCENES.md).
#pragma once

#include <haze/core/scene.h>

#include <filesystem>
#include <span>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

struct ParticleView {
  std::span<const Vec3f> positions;
  std::span<const float> density;    // rho per particle, or empty: 1 everywhere
  std::span<const float> diameters;  // delta_s per particle, or empty: from the nearest neighbours
  MaterialDesc material;
};

// Particles that own their arrays (read from a scene).
struct ParticleSet {
  std::vector<Vec3f> positions;
  std::vector<float> density, diameters;
  MaterialDesc material;

  ParticleView view() const { return {positions, density, diameters, material}; }

  // The scene's `particles` block: "positions" ([[x, y, z], ...]) or "file" (CSV with a header
  // naming columns x, y, z and optionally density and diameter; relative to base_dir), "density"
  // and "diameter" (a number for all, or an array of one per particle), "sigma_t", "albedo",
  // "phase" as in a medium. Errors name the field, the value and what was expected.
  static ParticleSet from_json(const nlohmann::json& j, const std::filesystem::path& base_dir = ".");
};

// Checks sizes and values (finite positions; density >= 0 and finite; diameters > 0 and finite);
// throws haze::Error naming particles.<field>[index].
void validate(const ParticleView& particles);

}  // namespace haze::particles

#pragma GCC visibility pop
