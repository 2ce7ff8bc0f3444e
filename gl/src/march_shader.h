// GLSL of the display: a fullscreen triangle and the ray-march fragment shader (display.h gives
// the estimator; every formula here mirrors grids/src/march.cpp and grids/src/dom.cpp) (internal).
#pragma once

namespace haze::gl::internal {

inline constexpr const char* kFullscreenVertexShader = R"(#version 330 core
// Vertices 0, 1, 2 at clip (-1, -1), (3, -1), (-1, 3): one triangle covering the viewport.
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

inline constexpr const char* kMarchFragmentShader = R"(#version 330 core
out vec4 out_color;

// Camera (core/camera.h): film position (0, 0) at the top-left corner.
uniform vec2 film;
uniform int orthographic;
uniform vec3 camera_position, camera_forward, camera_right, camera_up;
uniform float tan_half, half_height, aspect;

// The volume: cell-centred textures over [box_lo, box_hi], linear filtering clamped to the edge.
uniform vec3 box_lo, box_hi;
uniform ivec3 cells;
uniform float step_length;
uniform sampler3D density;
uniform sampler3D depths0, depths1, depths2, depths3;  // lights 4i..4i+3 in r, g, b, a
uniform sampler3D visibility0, visibility1, visibility2, visibility3;  // the surfaces' shadows, as the depths
uniform int shadows;  // 1: the visibility volumes hold the surfaces' shadows
uniform vec3 sigma_t_view, sigma_t_light, albedo_single, albedo_ms, background;
// Emission (core Emission): L_e = emission_per_density rho + the texture's L_e at the cell centres
// of what does not follow the density (an emission grid, blackbody), read where emission_on is 1.
uniform vec3 emission_per_density;
uniform int emission_on;
uniform sampler3D emission;

// Phase: [c0 + c2 mu^2] [sum of lobes k / d^(3/2)], d = a + b (1 - s mu); or a table in mu.
uniform int phase_lobes;  // -1: table, 0: polynomial only, 1 or 2 lobes
uniform float phase_c0, phase_c2;
uniform vec2 phase_k, phase_a, phase_b, phase_s;
uniform sampler2D phase_table;
uniform int phase_table_size;

uniform int light_count;
uniform int light_type[16];  // 0 point, 1 spot, 2 directional
uniform vec3 light_position[16], light_axis[16], light_intensity[16];  // directional: axis = toward the light
uniform float light_cos_cone[16], light_exponent[16];

uniform int surface_count;
uniform int surface_type[16];  // 0 plane, 1 sphere
uniform vec4 surface_shape[16];  // plane: unit normal, dot(normal, point); sphere: centre, radius
uniform vec3 surface_kd[16], surface_ks[16];
uniform float surface_shininess[16];

// The DOM's surface texels (grids::SurfaceTexels), rows of one RGBA atlas: per surface (kind 0
// none, 1 plane, 2 sphere; its first row; columns; rows) and its frame (plane: origin and texel
// size, u and u0, v and v0; sphere: centre). Where a surface has none, or past a plane's
// rectangle: pi sky. Off (0) unless a DOM solution with surfaces is shown.
uniform int surface_texels_on;
uniform vec4 surface_map[16], surface_map_o[16], surface_map_u[16], surface_map_v[16];
uniform sampler2D surface_atlas;
uniform vec3 sky;

// Multiple scattering (DOM moments): slab (channel * ms_groups + group) of cells.z texels along z
// holds terms 4 group .. 4 group + 3; the weights c_k toward this pixel's eye direction at texel
// (x, group * film.y + y) of `weights`.
uniform int ms_groups, ms_channels;
uniform sampler3D moments;
uniform sampler2D weights;

const float PI = 3.14159265358979;

float phase(float mu) {
  if (phase_lobes < 0) {
    float u = (mu + 1.0) * 0.5 * float(phase_table_size - 1);
    float i = clamp(floor(u), 0.0, float(phase_table_size - 2));
    float a = texelFetch(phase_table, ivec2(int(i), 0), 0).r, b = texelFetch(phase_table, ivec2(int(i) + 1, 0), 0).r;
    return mix(a, b, u - i);
  }
  float poly = phase_c0 + phase_c2 * mu * mu;
  if (phase_lobes == 0) return poly;
  float sum = 0.0;
  for (int i = 0; i < phase_lobes; ++i) {
    float d = phase_a[i] + phase_b[i] * (1.0 - phase_s[i] * mu);
    sum += phase_k[i] / (d * sqrt(d));
  }
  return poly * sum;
}

// core/light.cpp arrival(): direction and distance to the light, irradiance at x.
void arrive(int l, vec3 x, out vec3 to_light, out float dist, out vec3 E) {
  if (light_type[l] == 2) {
    to_light = light_axis[l];
    dist = 1e30;
    E = light_intensity[l];
    return;
  }
  vec3 v = light_position[l] - x;
  float d2 = dot(v, v);
  dist = sqrt(d2);
  to_light = v / dist;
  E = light_intensity[l] / d2;
  if (light_type[l] == 1) {
    float c = -dot(to_light, light_axis[l]);
    E = (c >= light_cos_cone[l] && c > 0.0) ? E * pow(c, light_exponent[l]) : vec3(0.0);
  }
}

// Slab test (core Aabb::clip).
bool clip_box(vec3 o, vec3 d, inout float t0, inout float t1) {
  for (int a = 0; a < 3; ++a) {
    float inv = 1.0 / d[a];
    float near = (box_lo[a] - o[a]) * inv, far = (box_hi[a] - o[a]) * inv;
    if (near > far) { float s = near; near = far; far = s; }
    if (near > t0) t0 = near;
    if (far < t1) t1 = far;
    if (t0 > t1) return false;
  }
  return true;
}

bool inside_box(vec3 p) { return all(greaterThanEqual(p, box_lo)) && all(lessThanEqual(p, box_hi)); }

// Integral of the piecewise-constant density from o along unit d up to t_max (grids' DDA walk).
float density_integral(vec3 o, vec3 d, float t_max) {
  float t0 = 0.0, t1 = t_max;
  if (!clip_box(o, d, t0, t1) || !(t1 > t0)) return 0.0;
  vec3 h = (box_hi - box_lo) / vec3(cells);
  vec3 start = o + d * t0;
  ivec3 cell, step;
  vec3 t_next, t_delta;
  for (int a = 0; a < 3; ++a) {
    cell[a] = clamp(int(floor((start[a] - box_lo[a]) / h[a])), 0, cells[a] - 1);
    step[a] = d[a] > 0.0 ? 1 : d[a] < 0.0 ? -1 : 0;
    t_delta[a] = step[a] == 0 ? 1e30 : abs(h[a] / d[a]);
    t_next[a] = step[a] == 0 ? 1e30 : t0 + (box_lo[a] + float(cell[a] + (step[a] > 0 ? 1 : 0)) * h[a] - start[a]) / d[a];
  }
  float sum = 0.0, t = t0;
  for (int i = 0; i < cells.x + cells.y + cells.z + 3 && t < t1; ++i) {
    int a = t_next.x < t_next.y ? (t_next.x < t_next.z ? 0 : 2) : (t_next.y < t_next.z ? 1 : 2);
    float t_end = min(t_next[a], t1);
    sum += texelFetch(density, cell, 0).r * (t_end - t);
    t = t_end;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= cells[a]) break;
    t_next[a] += t_delta[a];
  }
  return sum;
}

// Depth to light l at uvw, from the four groups sampled there.
float pick(int l, vec4 d0, vec4 d1, vec4 d2, vec4 d3) {
  int g = l / 4;
  vec4 d = g == 0 ? d0 : g == 1 ? d1 : g == 2 ? d2 : d3;
  return d[l - 4 * g];
}

bool nearest_surface(vec3 o, vec3 d, out float t, out vec3 n, out int which) {
  t = 1e30;
  which = -1;
  n = vec3(0.0);
  for (int i = 0; i < surface_count; ++i) {
    vec4 s = surface_shape[i];
    float th;
    vec3 nh;
    if (surface_type[i] == 0) {
      float denom = dot(s.xyz, d);
      if (abs(denom) < 1e-12) continue;
      th = (s.w - dot(s.xyz, o)) / denom;
      if (!(th > 1e-7 && th < t)) continue;
      nh = denom < 0.0 ? s.xyz : -s.xyz;
    } else {
      vec3 oc = o - s.xyz;
      float b = dot(oc, d), c = dot(oc, oc) - s.w * s.w, disc = b * b - c;
      if (disc < 0.0) continue;
      float root = sqrt(disc);
      th = -b - root;
      if (!(th > 1e-7)) th = -b + root;
      if (!(th > 1e-7 && th < t)) continue;
      nh = (o + th * d - s.xyz) / s.w;
      if (dot(nh, d) > 0.0) nh = -nh;
    }
    t = th;
    n = nh;
    which = i;
  }
  return which >= 0;
}

// Lambert kd / pi plus normalized Phong (core/surface.cpp).
vec3 brdf(int i, vec3 wi, vec3 wo, vec3 n) {
  vec3 f = surface_kd[i] / PI;
  if (any(greaterThan(surface_ks[i], vec3(0.0)))) {
    vec3 m = 2.0 * dot(wi, n) * n - wi;
    float ca = max(0.0, dot(m, wo)), sh = surface_shininess[i];
    float lobe = ca > 0.0 ? pow(ca, sh) : (sh == 0.0 ? 1.0 : 0.0);
    f += surface_ks[i] * ((sh + 2.0) / (2.0 * PI) * lobe);
  }
  return f;
}

// SurfaceTexels::Rectangle::lookup and Globe::lookup (grids/src/dom_surfaces.cpp).
vec3 atlas_at(int row0, int col, int row) { return texelFetch(surface_atlas, ivec2(col, row0 + row), 0).rgb; }
vec3 surface_irradiance(int i, vec3 p) {
  vec4 m = surface_map[i];
  int kind = int(m.x), row0 = int(m.y), nu = int(m.z), nv = int(m.w);
  if (kind == 1) {
    vec4 o = surface_map_o[i], u = surface_map_u[i], v = surface_map_v[i];
    float fu = (dot(p - o.xyz, u.xyz) - u.w) / o.w - 0.5, fv = (dot(p - o.xyz, v.xyz) - v.w) / o.w - 0.5;
    if (!(fu >= -0.5 && fu <= float(nu) - 0.5 && fv >= -0.5 && fv <= float(nv) - 0.5)) return PI * sky;
    float cu = clamp(fu, 0.0, float(nu - 1)), cv = clamp(fv, 0.0, float(nv - 1));
    int a = min(int(cu), nu - 2), b = min(int(cv), nv - 2);
    float s = cu - float(a), t = cv - float(b);
    return (1.0 - t) * ((1.0 - s) * atlas_at(row0, a, b) + s * atlas_at(row0, a + 1, b)) +
           t * ((1.0 - s) * atlas_at(row0, a, b + 1) + s * atlas_at(row0, a + 1, b + 1));
  }
  if (kind == 2) {
    int np = nu, nt = nv;
    vec3 u = normalize(p - surface_map_o[i].xyz);
    float ft = clamp(acos(clamp(u.y, -1.0, 1.0)) / PI * float(nt) - 0.5, 0.0, float(nt - 1));
    float fp = (atan(u.z, u.x) + PI) / (2.0 * PI) * float(np) - 0.5;
    int t = min(int(ft), nt - 2);
    float a = ft - float(t), fl = floor(fp), b = fp - fl;
    int p0 = ((int(fl) % np) + np) % np, p1 = (p0 + 1) % np;
    return (1.0 - a) * ((1.0 - b) * atlas_at(row0, p0, t) + b * atlas_at(row0, p1, t)) +
           a * ((1.0 - b) * atlas_at(row0, p0, t + 1) + b * atlas_at(row0, p1, t + 1));
  }
  return PI * sky;
}

void main() {
  vec2 pix = vec2(gl_FragCoord.x, film.y - gl_FragCoord.y);
  float sx = (2.0 * pix.x / film.x - 1.0) * aspect, sy = 1.0 - 2.0 * pix.y / film.y;
  vec3 o = camera_position, d = camera_forward;
  if (orthographic == 1) {
    o += camera_right * (sx * half_height) + camera_up * (sy * half_height);
  } else {
    d = normalize(camera_forward + camera_right * (sx * tan_half) + camera_up * (sy * tan_half));
  }
  float t_hit;
  vec3 normal;
  int surface;
  bool hit = nearest_surface(o, d, t_hit, normal, surface);

  vec3 L = vec3(0.0), T = vec3(1.0);
  float t0 = 0.0, t1 = t_hit;
  if (clip_box(o, d, t0, t1) && t1 > t0) {
    int steps = int(ceil((t1 - t0) / step_length));
    float dt = (t1 - t0) / float(steps);
    vec3 size = box_hi - box_lo;
    ivec2 texel = ivec2(pix);
    float slabs = float(cells.z * ms_groups * ms_channels);
    for (int s = 0; s < steps; ++s) {
      vec3 x = o + d * (t0 + (float(s) + 0.5) * dt);
      vec3 uvw = (x - box_lo) / size;
      float rho = texture(density, uvw).r;
      vec3 Le = emission_per_density * rho;
      if (emission_on == 1) Le += texture(emission, uvw).rgb;
      if (rho <= 0.0) {
        L += T * Le * dt;
        continue;
      }
      vec4 g0 = texture(depths0, uvw), g1 = vec4(0.0), g2 = vec4(0.0), g3 = vec4(0.0);
      if (light_count > 4) g1 = texture(depths1, uvw);
      if (light_count > 8) g2 = texture(depths2, uvw);
      if (light_count > 12) g3 = texture(depths3, uvw);
      vec4 v0 = vec4(1.0), v1 = vec4(1.0), v2 = vec4(1.0), v3 = vec4(1.0);
      if (shadows == 1) {
        v0 = texture(visibility0, uvw);
        if (light_count > 4) v1 = texture(visibility1, uvw);
        if (light_count > 8) v2 = texture(visibility2, uvw);
        if (light_count > 12) v3 = texture(visibility3, uvw);
      }
      vec3 single = vec3(0.0);
      for (int l = 0; l < light_count; ++l) {
        vec3 to_light, E;
        float dist;
        arrive(l, x, to_light, dist, E);
        if (E == vec3(0.0)) continue;
        single += phase(dot(to_light, d)) * E * pick(l, v0, v1, v2, v3) * exp(-sigma_t_light * pick(l, g0, g1, g2, g3));
      }
      vec3 scattered = albedo_single * single;
      if (ms_groups > 0) {
        float z = clamp(uvw.z * float(cells.z), 0.5, float(cells.z) - 0.5);
        vec3 ms = vec3(0.0);
        for (int c = 0; c < ms_channels; ++c)
          for (int g = 0; g < ms_groups; ++g) {
            vec3 at = vec3(uvw.xy, (float((c * ms_groups + g) * cells.z) + z) / slabs);
            ms[c] += dot(texture(moments, at), texelFetch(weights, ivec2(texel.x, g * int(film.y) + texel.y), 0));
          }
        if (ms_channels == 1) ms = vec3(ms.x);
        scattered += albedo_ms * ms;
      }
      vec3 tau = sigma_t_view * rho * dt, step_T = exp(-tau);
      L += T * (vec3(1.0) - step_T) * scattered;
      // L_e integral_0^dt e^(-sigma_t rho s) ds, as grids/src/march.cpp.
      for (int c = 0; c < 3; ++c) L[c] += T[c] * Le[c] * (tau[c] > 1e-6 ? (1.0 - step_T[c]) / (sigma_t_view[c] * rho) : dt);
      T *= step_T;
    }
  }

  vec3 end = background;
  if (hit) {
    vec3 p = o + d * t_hit;
    end = vec3(0.0);
    for (int l = 0; l < light_count; ++l) {
      vec3 to_light, E;
      float dist;
      arrive(l, p, to_light, dist, E);
      float cos_i = dot(normal, to_light);
      if (cos_i <= 0.0) continue;
      float t_block;
      vec3 n_block;
      int blocker;
      // In a surface's shadow? From just off the surface: float32 hits the surface itself otherwise.
      vec3 from = p + normal * (1e-4 * (1.0 + length(p)));
      if (nearest_surface(from, to_light, t_block, n_block, blocker) && t_block < dist * (1.0 - 1e-6)) continue;
      float depth;
      if (inside_box(p)) {
        vec3 uvw = (p - box_lo) / (box_hi - box_lo);
        vec4 g0 = texture(depths0, uvw), g1 = texture(depths1, uvw), g2 = texture(depths2, uvw), g3 = texture(depths3, uvw);
        depth = pick(l, g0, g1, g2, g3);
      } else {
        depth = density_integral(p, to_light, dist);
      }
      end += brdf(surface, to_light, -d, normal) * E * cos_i * exp(-sigma_t_view * depth);
    }
    if (surface_texels_on == 1) end += (surface_kd[surface] + surface_ks[surface]) / PI * surface_irradiance(surface, p);
  }
  out_color = vec4(L + T * end, 1.0);
}
)";

}  // namespace haze::gl::internal
