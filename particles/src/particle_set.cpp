// The `particles` block of a scene, and validation of particle arrays.
#include <haze/core/error.h>
#include <haze/core/limits.h>
#include <haze/particles/particle_set.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace haze::particles {

namespace {

using nlohmann::json;

// A number for every particle, or an array of one per particle.
std::vector<float> per_particle(const json& j, const std::string& field, size_t count) {
  if (j.is_number()) return std::vector<float>(count, j.get<float>());
  if (!j.is_array() || j.size() != count)
    throw Error("particles." + field, j.is_array() ? to_text(j.size()) + " values" : json_text(j),
                "a number, or an array of " + to_text(count) + " numbers (one per particle)");
  std::vector<float> out;
  for (size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_number()) throw Error("particles." + field + "[" + std::to_string(i) + "]", json_text(j[i]), "a number");
    out.push_back(j[i].get<float>());
  }
  return out;
}

void read_csv(const std::filesystem::path& path, ParticleSet& set) {
  std::ifstream in(path);
  if (!in) throw Error("particles.file", "\"" + path.string() + "\"", "a readable CSV file");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> columns;
  std::stringstream header(line);
  for (std::string c; std::getline(header, c, ',');) columns.push_back(c.substr(0, c.find_last_not_of(" \r") + 1));
  auto column = [&](const std::string& name) {
    for (size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int x = column("x"), y = column("y"), z = column("z"), rho = column("density"), ds = column("diameter");
  if (x < 0 || y < 0 || z < 0)
    throw Error("particles.file", "header \"" + line + "\"", "a header line naming columns x, y, z (and optionally density, diameter)");
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.find_first_not_of(" \r") == std::string::npos) continue;
    std::vector<float> v;
    std::stringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) {
      char* end = nullptr;
      v.push_back(std::strtof(f.c_str(), &end));
      if (end == f.c_str()) throw Error("particles.file", path.string() + " line " + std::to_string(row) + ": \"" + f + "\"", "a number");
    }
    if (v.size() != columns.size())
      throw Error("particles.file", path.string() + " line " + std::to_string(row), to_text(columns.size()) + " values");
    set.positions.emplace_back(v[static_cast<size_t>(x)], v[static_cast<size_t>(y)], v[static_cast<size_t>(z)]);
    if (rho >= 0) set.density.push_back(v[static_cast<size_t>(rho)]);
    if (ds >= 0) set.diameters.push_back(v[static_cast<size_t>(ds)]);
  }
}

}  // namespace

ParticleSet ParticleSet::from_json(const json& j, const std::filesystem::path& base_dir) {
  scene_fields::allow(j, "particles", {"positions", "file", "density", "diameter", "sigma_t", "albedo", "phase", "emission", "blackbody",
                                       "grid_resolution"});  // the last three the density reader's (methods.cpp)
  ParticleSet set;
  set.material = read_material(j, "particles");
  const bool inline_positions = j.contains("positions"), file = j.contains("file");
  if (inline_positions == file) throw Error("particles.positions", file ? "given with file" : "missing", "one of positions and file");
  if (file) {
    read_csv(scene_fields::existing_file(j, "particles", base_dir, "a CSV file name (relative to the scene file's folder)"), set);
  } else {
    const json& p = j["positions"];
    if (!p.is_array()) throw Error("particles.positions", json_text(p), "an array of [x, y, z]");
    for (size_t i = 0; i < p.size(); ++i) {
      if (!p[i].is_array() || p[i].size() != 3 || !p[i][0].is_number() || !p[i][1].is_number() || !p[i][2].is_number())
        throw Error("particles.positions[" + std::to_string(i) + "]", json_text(p[i]), "[x, y, z]");
      set.positions.emplace_back(p[i][0].get<float>(), p[i][1].get<float>(), p[i][2].get<float>());
    }
  }
  if (j.contains("density")) set.density = per_particle(j["density"], "density", set.positions.size());
  if (j.contains("diameter")) set.diameters = per_particle(j["diameter"], "diameter", set.positions.size());
  validate(set.view());
  return set;
}

void validate(const ParticleView& p) {
  const size_t n = p.positions.size();
  if (!p.density.empty() && p.density.size() != n)
    throw Error("particles.density", to_text(p.density.size()) + " values", "none, or one per particle (" + to_text(n) + ")");
  if (!p.diameters.empty() && p.diameters.size() != n)
    throw Error("particles.diameter", to_text(p.diameters.size()) + " values", "none, or one per particle (" + to_text(n) + ")");
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& x = p.positions[i];
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
      throw Error("particles.positions[" + std::to_string(i) + "]", "not finite", "finite coordinates");
    // Before anything is built from them (a particle 8.9e10 away overflowed the density's cell count).
    if (!within_reach(Vec3(x)))
      throw Error("particles.positions[" + std::to_string(i) + "]", to_text(Vec3(x)), "a point within 1e9 of the origin (haze::kMaxCoordinate)");
    if (!p.density.empty() && !(p.density[i] >= 0.0f && std::isfinite(p.density[i])))
      throw Error("particles.density[" + std::to_string(i) + "]", to_text(p.density[i]), "a finite density >= 0");
    if (!p.diameters.empty() && !(p.diameters[i] > 0.0f && std::isfinite(p.diameters[i])))
      throw Error("particles.diameter[" + std::to_string(i) + "]", to_text(p.diameters[i]), "a finite diameter > 0");
  }
}

}  // namespace haze::particles
