// Internal: the pieces of the network that a full build (network.cpp) and an update of moved
// particles (network_update.cpp) share, and what the renderer (network_render.cpp) hands its splat
// (network_splat.cpp).
#pragma once

#include <haze/particles/network.h>

#include <array>
#include <cmath>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace haze::particles::network_internal {

// Direction w's view of the window: a particle's pixel (its column) and its depth along w.
struct Projector {
  Vec3 c, w, t1, t2;
  double r;
  int m;
  Projector(const NetworkWindow& window, const Vec3& direction);
  int pixel(const Vec3& x) const;
  double depth(const Vec3& x) const { return glm::dot(x - c, w); }
};

// A column's particles as (depth, index): sorted by depth (ties by index), written to `out` in
// upstream-first order, and each linked to the one before it: V's upstream ([p], -1 for the
// first) and the gap's density integral (the trapezoid of rho at both ends).
void link_column(std::vector<std::pair<double, int>>& members, int* out, int* upstream, float* depth, const std::vector<float>& rho);

// The density integral over the gap between particles at depths `upstream` and `p` along a
// direction: the trapezoid of rho at both ends.
inline float gap_depth(float rho_p, float rho_upstream, double p, double upstream) {
  return static_cast<float>(0.5 * (static_cast<double>(rho_p) + static_cast<double>(rho_upstream)) * (p - upstream));
}

// exp(-sigma_t depth) over a particle's gap, or -1 where nothing is upstream (the sweep's marker).
inline float gap_transmittance(double sigma_t, int upstream, float depth) {
  return upstream < 0 ? -1.0f : static_cast<float>(std::exp(-sigma_t * static_cast<double>(depth)));
}

// Where a particle's direct light is sampled: its Gaussian's 2-point Gauss-Hermite nodes per axis,
// x +- h / sqrt(2).
std::array<Vec3, 8> gaussian_nodes(const Vec3& x, double h);

// The delta lights of `lights` (point, spot, directional), and the sky radiance summed.
std::vector<const Light*> delta_lights(const std::vector<Light>& lights, Rgb& sky);

// Whether the medium, its emission, the sky and every light are grey (one channel serves three).
bool grey_scene(const MaterialDesc& material, const Emission& emission, const Rgb& sky, const std::vector<const Light*>& delta);

// s.emitted from s.emission and s.rho.
void emission_source(NetworkSolution& s, const ParticleField& field);

// S[c][i * n + p] for the listed particles p from the solution's light maps:
// the direct light scattered into each direction, per unit albedo, overwriting what was there.
void direct_light(NetworkSolution& s, const ParticleField& field, const std::vector<const Light*>& delta, const std::vector<int>& particles,
                  int threads);

// The transmittance of every gap in sweep order, per solved channel, from V.
void all_transmittance(NetworkSolution& s, const MaterialDesc& material, int threads);

// Iterates from s.incoming until the change is under the tolerance or the iterations run out.
void iterate(NetworkSolution& s, const NetworkSettings& settings);

// What update_network compares the next frame against.
void remember(NetworkSolution& s, const ParticleField& field, const std::vector<const Light*>& delta);

// Camera::generate_ray inverted: the pixel position and footprint radius (pixels) of a sphere.
struct FilmProjection {
  const Camera& cam;
  Vec3 forward = glm::normalize(cam.look_at - cam.position);
  Vec3 right = glm::normalize(glm::cross(forward, cam.up));
  Vec3 up = glm::cross(right, forward);
  double aspect = static_cast<double>(cam.width_px) / cam.height_px;
  double tan_half = std::tan(0.5 * cam.fov_y_deg * kPi / 180.0);

  // False when the sphere of radius `extent` around x lies wholly behind a pinhole camera. A
  // host's camera (matrices) is not binned: every particle covers the whole image.
  bool operator()(const Vec3& x, double extent, double& px, double& py, double& radius) const {
    if (cam.type == Camera::Type::matrices) {
      px = 0.5 * cam.width_px, py = 0.5 * cam.height_px, radius = 2.0 * (cam.width_px + cam.height_px);
      return true;
    }
    const Vec3 d = x - cam.position;
    double scale;  // film units per world unit at x
    if (cam.type == Camera::Type::orthographic) {
      scale = 2.0 / cam.height;
    } else {
      const double z = glm::dot(d, forward);
      if (z <= extent) {  // touching or behind the eye: cover the whole image
        if (z < -extent) return false;
        px = 0.5 * cam.width_px, py = 0.5 * cam.height_px, radius = 2.0 * (cam.width_px + cam.height_px);
        return true;
      }
      scale = 1.0 / ((z - extent) * tan_half);
    }
    const double sx = glm::dot(d, right) * scale, sy = glm::dot(d, up) * scale;
    px = (sx / aspect + 1.0) * 0.5 * cam.width_px;
    py = (1.0 - sy) * 0.5 * cam.height_px;
    radius = extent * scale * 0.5 * cam.height_px + 1.0;
    return true;
  }
};


// The splat's lattice: a node per this many of the narrowest footprint's width h in pixels (where
// the image is interpolated between nodes; docs/NETWORKS.md gives the error).
inline constexpr double kSplatNodesPerWidth = 3.0;

// What render_network hands its splat.
struct SplatInputs {
  const Camera& camera;
  const ParticleField& field;
  const NetworkSolution& solution;
  std::span<const Rgb> scattered;  // each particle's scattered light toward the eye (albedo J, emission)
  std::function<Rgb(const Vec3& x, const Vec3& w)> direct;  // the single-scattered direct light toward w at x
  double nearest;                  // LightDepthMap::arrival's
  Rgb background;                  // behind the particles where nothing ends a ray
  std::function<Vec3(const Vec3& x)> toward_eye;
  // Per pixel: where its ray ends (its t_end: Haze's own surface or the host's depth, else inf) and
  // the light leaving that end; empty where nothing ends any ray.
  std::function<Rgb(int x, int y, const Ray& ray, double& t_end)> end_of;
  // Or null: the caller's float32 layers, which the pixels interpolated from a lattice go into
  // straight, not through the sink.
  const LayerSpans* layers = nullptr;
};

// Where a render hands its pixels' layers: a run of row y from pixel x0 on, threaded.
using PixelSink = std::function<void(int y, int x0, std::span<const PixelLayers> run)>;

// The splat of `front_to_back` (the particles by distance from the eye) into `sink`, per pixel;
// or, without ends, over a lattice of kSplatNodesPerWidth nodes to the narrowest footprint's width,
// interpolated bilinearly. Returns the lattice's step in pixels.
int splat_network(const SplatInputs& in, std::span<const uint32_t> front_to_back, const PixelSink& sink, const RenderOptions& options);

}  // namespace haze::particles::network_internal
