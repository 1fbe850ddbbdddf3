// Directions, sky, checks, the flat layout and the frame logic shared by the
// CPU and Vulkan engines.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "gi_bridge/detail/gi_engine.h"
#include "ldc/world.h"
#include "ldc/internal/vec_text.h"

namespace ldc {

const std::array<glm::vec3, kGiDirections>& gi_directions() {
  // A spherical 5-design of 16 points (see gi.h), rotated so that the first is +z.
  static const std::array<glm::vec3, kGiDirections> dirs = {{
      {0.000000000f, 0.000000000f, 1.000000000f},   {0.111322681f, -0.759955073f, 0.640371414f},
      {-0.602368130f, 0.689405709f, 0.402333699f},  {-0.609689154f, 0.655894209f, -0.445063954f},
      {0.892643446f, 0.408121935f, -0.191374412f},  {0.676167203f, -0.236961508f, -0.697601001f},
      {0.765071787f, -0.633572552f, 0.115112908f},  {0.091852540f, 0.347298752f, -0.933245245f},
      {0.220492089f, 0.778874054f, 0.587144315f},   {0.233512282f, 0.937721798f, -0.257196119f},
      {-0.401600270f, -0.337574962f, -0.851328590f}, {-0.768022854f, -0.110343176f, 0.630844893f},
      {-0.960572127f, -0.105614392f, -0.257190181f}, {-0.551208054f, -0.826388575f, 0.115115614f},
      {0.805185298f, 0.083286831f, 0.587145586f},   {0.097201628f, -0.890207774f, -0.445063998f},
  }};
  return dirs;
}

glm::dvec3 gi_cone_ray(int cone, int k, int n) {
  const glm::dvec3 d(gi_directions()[size_t(cone)]);
  // One ray stands for the whole cap: its axis (the ring rule would put it
  // 20 degrees off, at cos 0.9375).
  if (n == 1) return glm::normalize(d);
  const glm::dvec3 a = std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(d, a)), w = glm::cross(d, u);
  const double ct = 1.0 - (k + 0.5) / n * (1.0 - 0.875), st = std::sqrt(1.0 - ct * ct);
  const double phi = 2.399963229728653 * k;  // the golden angle
  return glm::normalize(d * ct + u * (st * std::cos(phi)) + w * (st * std::sin(phi)));
}

SkyLight SkyLight::uniform(const glm::vec3& radiance) {
  SkyLight s;
  s.amplitude.fill(radiance);
  return s;
}

SkyLight SkyLight::gradient(const glm::vec3& zenith, const glm::vec3& horizon, const glm::vec3& ground,
                            int up_axis) {
  const int up = up_axis >= 0 && up_axis <= 2 ? up_axis : 2;
  SkyLight s;
  for (int i = 0; i < kGiDirections; ++i) {
    const float z = gi_directions()[size_t(i)][up];
    s.amplitude[size_t(i)] = z >= 0.0f ? glm::mix(horizon, zenith, z) : glm::mix(horizon, ground, -z);
  }
  return s;
}

glm::vec3 SkyLight::radiance(const glm::vec3& w) const {
  glm::vec3 sum(0.0f);
  float norm = 0.0f;
  for (int i = 0; i < kGiDirections; ++i) {
    const float g = std::exp(sharpness * (glm::dot(w, gi_directions()[size_t(i)]) - 1.0f));
    sum += g * amplitude[size_t(i)];
    norm += g;
  }
  return sum / norm;
}

namespace {
bool finite_nonneg(const glm::vec3& v) {
  return detail::is_finite(glm::dvec3(v)) && glm::all(glm::greaterThanEqual(v, glm::vec3(0.0f)));
}
Status bad(const std::string& what) { return Status(ErrorCode::kInvalidArgument, what); }
}  // namespace

Status check_gi_lights(const GiLights& lights, const GiConfig& config) {
  for (int i = 0; i < kGiDirections; ++i) {
    if (!finite_nonneg(lights.sky.amplitude[size_t(i)]))
      return bad("sky amplitude " + std::to_string(i) + " must be finite and >= 0");
  }
  if (!(lights.sky.sharpness >= 0.5f && lights.sky.sharpness <= 64.0f)) {
    std::ostringstream s;
    s << "sky sharpness " << lights.sky.sharpness << " must be in 0.5 .. 64";
    return bad(s.str());
  }
  const int max_points = config.light_volume ? kGiMaxInjectedPointLights : kGiMaxPointLights;
  if (lights.points.size() > size_t(max_points))
    return bad(std::to_string(lights.points.size()) + " point lights: at most " + std::to_string(max_points) +
               (config.light_volume ? " injected" : " exact (GiConfig::light_volume takes more)"));
  for (size_t i = 0; i < lights.points.size(); ++i) {
    const PointLight& p = lights.points[i];
    if (!finite_nonneg(p.intensity) || !detail::is_finite(glm::dvec3(p.position)))
      return bad("point light " + std::to_string(i) + ": position must be finite and intensity finite and >= 0");
  }
  return {};
}

std::vector<size_t> remove_buried_lights(const World& world, GiLights* lights) {
  std::vector<size_t> buried;
  std::vector<PointLight> kept;
  for (size_t i = 0; i < lights->points.size(); ++i) {
    if (world.inside(lights->points[i].position))
      buried.push_back(i);
    else
      kept.push_back(lights->points[i]);
  }
  lights->points = std::move(kept);
  return buried;
}

Status check_gi_config(const GiConfig& config) {
  if (!(config.third_bounce_boost >= 0.0f && config.third_bounce_boost <= 1.0f)) {
    std::ostringstream s;
    s << "third_bounce_boost " << config.third_bounce_boost << " must be in 0 .. 1";
    return bad(s.str());
  }
  if (!(config.near_far_split >= 1.0f && config.near_far_split <= 16.0f)) {
    std::ostringstream s;
    s << "near_far_split " << config.near_far_split << " must be in 1 .. 16";
    return bad(s.str());
  }
  if (!(config.query_offset >= 0.0f && config.query_offset <= 4.0f)) {
    std::ostringstream s;
    s << "query_offset " << config.query_offset << " must be in 0 .. 4";
    return bad(s.str());
  }
  if (config.query_rays < 0 || config.query_rays > kGiMaxQueryRays) {
    return bad("query_rays " + std::to_string(config.query_rays) + " must be in 0 .. " +
               std::to_string(kGiMaxQueryRays));
  }
  return {};
}

namespace detail {

namespace {

// The talk's point light injection (it used a geometry shader; here the
// host splats, 8 writes per light and level): each light, at every level,
// over the 8 voxels around it by trilinear weights w, as an emission
// density I w / s^3 [radiance / m]. The cones' trilinear reconstruction of
// those values integrates to I over space, so their march (which adds
// T * density * step) gathers I / r^2 over all directions on average.
// The weights are moved toward open voxels (scaled by 1 - the voxel's mean
// face opacity, renormalised): light put into a solid voxel is never seen,
// and a light a few centimetres from a wall would lose up to half of it.
// Voxels outside a level get nothing: a cone there reads a coarser level.
void inject_point_lights(const std::vector<PointLight>& lights, GiLayout& out) {
  const int n = out.n;
  for (const PointLight& light : lights) {
    for (int l = 0; l < out.k; ++l) {
      const double size = double(out.params.fparams.x) * double(1 << l);
      const glm::dvec3 u = (light.position - out.origin) / size - glm::dvec3(glm::ivec3(out.params.lo[l])) - 0.5;
      const glm::ivec3 c0(glm::floor(u));
      const glm::dvec3 f = u - glm::dvec3(c0);
      const glm::vec3 density = light.intensity / float(size * size * size);
      double w[8] = {}, sum = 0.0, inside = 0.0;
      size_t voxel[8] = {};
      for (int k = 0; k < 8; ++k) {
        const glm::ivec3 o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        const glm::ivec3 c = c0 + o;
        if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, glm::ivec3(n)))) continue;
        voxel[k] = out.voxel(l, c);
        double occ = 0.0;
        for (int face = 0; face < 6; ++face) occ += out.occ[voxel[k] * 6 + size_t(face)] / 6.0;
        const double tri = (o.x ? f.x : 1.0 - f.x) * (o.y ? f.y : 1.0 - f.y) * (o.z ? f.z : 1.0 - f.z);
        w[k] = tri * (1.0 - occ);
        inside += tri;
        sum += w[k];
      }
      if (sum <= 1e-6) continue;  // outside the level, or buried
      for (int k = 0; k < 8; ++k) {
        if (w[k] > 0.0) out.light_volume[voxel[k]] += glm::vec4(density * float(w[k] * inside / sum), 0.0f);
      }
    }
  }
}

// The sky and the point lights: exact lights go in the uniform block, and
// injected ones are splatted into the light volume instead.
void fill_light_params(const GiLights& lights, const GiConfig& config, GiLayout& out) {
  GiParams& p = out.params;
  for (int i = 0; i < kGiDirections; ++i) p.sky[i] = glm::vec4(lights.sky.amplitude[size_t(i)], 0.0f);
  const size_t exact = config.light_volume ? 0 : lights.points.size();
  for (size_t i = 0; i < size_t(kGiMaxPointLights); ++i) {
    p.light_pos[i] = i < exact ? glm::vec4(glm::vec3(lights.points[i].position - out.origin), 1.0f) : glm::vec4(0.0f);
    p.light_int[i] = i < exact ? glm::vec4(lights.points[i].intensity, 0.0f) : glm::vec4(0.0f);
  }
  p.iparams.w = int(exact);
  out.light_volume.assign(config.light_volume ? out.voxels() : 0, glm::vec4(0.0f));
  if (config.light_volume) inject_point_lights(lights.points, out);
}

// Cone i's query rays (GiConfig::query_rays), computed here once so that
// every device marches the same rays; unused slots 0.
void fill_query_rays(int n, GiParams& p) {
  for (int i = 0; i < kGiDirections; ++i)
    for (int k = 0; k < kGiMaxQueryRays; ++k)
      p.rays[i * kGiMaxQueryRays + k] = k < n ? glm::vec4(glm::vec3(gi_cone_ray(i, k, n)), 0.0f) : glm::vec4(0.0f);
}

void fill_params(const Cascades& cascades, const GiLights& lights, const GiConfig& config, GiLayout& out) {
  GiParams& p = out.params;
  for (int i = 0; i < kGiDirections; ++i) p.dirs[i] = glm::vec4(gi_directions()[size_t(i)], 0.0f);
  p.fparams = glm::vec4(float(cascades.voxel_size(0)), config.third_bounce_boost, config.query_offset, 0.0f);
  p.iparams = glm::ivec4(out.n, out.k,
                         (config.precombined ? 1 : 0) | (config.near_far ? 2 : 0) | (config.light_volume ? 4 : 0), 0);
  p.fparams2 = glm::vec4(config.near_far_split, 0.0f, 0.0f, 0.0f);
  p.iparams2 = glm::ivec4(config.query_rays, 0, 0, 0);
  fill_query_rays(config.query_rays, p);
  for (int l = 0; l < out.k; ++l) {
    p.lo[l] = glm::ivec4(cascades.level_box(l).lo, 0);
    p.surf[l] = glm::ivec4(out.level_first[size_t(l)], out.level_count[size_t(l)], 0, 0);
  }
  fill_light_params(lights, config, out);
}

bool s_is_updated(const GiLayout& out, int l, int32_t s) {
  return s >= out.level_first[size_t(l)] && s < out.level_first[size_t(l)] + out.level_count[size_t(l)];
}

bool own_face(const FaceSample& f) { return (f.flags & kFaceOwn) && f.albedo.a > 0.0f; }
bool propagated_face(const FaceSample& f) { return f.flags == kFacePropagated && f.albedo.a > 0.0f; }

// Entries of one level: first the surface voxels (a face holding its own
// surface), then the shadow voxels (solid behind a surface, a face
// propagated from it). A propagated face shows its neighbour's light: a
// cone entering a wall samples the surface voxel and the solid one behind
// it together, and without that light the wall looked half as bright as it
// is (a closed emissive box gave irradiance 1.58 instead of pi).
void add_level(const PackedGBuffer& packed, int l, bool valid, GiLayout& out) {
  const int n = out.n;
  out.level_first[size_t(l)] = int(out.surf_pos.size());
  std::vector<glm::ivec3> shadows;
  auto add_entry = [&](const glm::ivec3& c, const FaceSample* f, bool updated) {
    out.vmap[out.voxel(l, c)] = int32_t(out.surf_pos.size());
    out.surf_pos.emplace_back(c, l);
    for (int i = 0; i < kFaces; ++i) {
      out.attr.emplace_back(glm::vec3(f[i].albedo), updated && own_face(f[i]) ? f[i].albedo.a : 0.0f);
      out.attr.emplace_back(f[i].normal, 0.0f);
      out.attr.emplace_back(f[i].emission, 0.0f);
    }
  };
  for (int z = 0; z < n; ++z) {
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const glm::ivec3 c(x, y, z);
        const size_t voxel = out.voxel(l, c);
        out.vmap[voxel] = -1;
        if (!valid) continue;
        FaceSample f[kFaces];
        bool surface = false, shadow = false;
        for (int i = 0; i < kFaces; ++i) {
          f[i] = packed.sample(i, l, c);
          out.occ[voxel * 6 + size_t(i)] = f[i].occupancy;
          surface = surface || own_face(f[i]);
          shadow = shadow || propagated_face(f[i]);
        }
        if (surface) {
          add_entry(c, f, true);
        } else if (shadow) {
          shadows.push_back(c);
        }
      }
    }
  }
  out.level_count[size_t(l)] = int(out.surf_pos.size()) - out.level_first[size_t(l)];
  for (const glm::ivec3& c : shadows) {
    FaceSample f[kFaces];
    for (int i = 0; i < kFaces; ++i) f[i] = packed.sample(i, l, c);
    add_entry(c, f, false);
  }
  out.level_shadow[size_t(l)] = int(out.surf_pos.size()) - out.level_first[size_t(l)] - out.level_count[size_t(l)];
  // Which light slot each face shows: its own, or its neighbour's on that side.
  for (size_t s = size_t(out.level_first[size_t(l)]); s < out.surf_pos.size(); ++s) {
    const glm::ivec3 c(out.surf_pos[s]);
    for (int i = 0; i < kFaces; ++i) {
      const FaceSample f = packed.sample(i, l, c);
      int32_t src = -1;
      if (own_face(f)) {
        // Shadow entries never hold an own face (they have no surface).
        src = int32_t(s * 6 + size_t(i));
      } else if (propagated_face(f)) {
        glm::ivec3 nb = c;
        nb[face_axis(i)] += face_positive(i) ? 1 : -1;
        const int32_t t = glm::all(glm::greaterThanEqual(nb, glm::ivec3(0))) && glm::all(glm::lessThan(nb, glm::ivec3(n)))
                              ? out.vmap[out.voxel(l, nb)]
                              : -1;
        if (t >= 0 && s_is_updated(out, l, t)) src = t * 6 + i;
      }
      out.face_src.push_back(src);
    }
  }
}

// Air open to the sky (issue 25; the shaders' sky_open): per level, from
// the coarsest, a flood through the voxels less than half solid, from the
// faces of the level's box: all of them on the coarsest level, and on a
// finer one those whose voxel of the next coarser level is open. Half, so
// that a wall of one voxel's thickness lying across two voxels still
// closes the flood, while a tunnel a voxel wide stays open. Solid voxels
// take the flag of any open air beside them.
// Index of local voxel c within one level's N^3 block (x fastest).
size_t level_local_index(int n, const glm::ivec3& c) {
  return (size_t(c.z) * size_t(n) + size_t(c.y)) * size_t(n) + size_t(c.x);
}

bool in_level(int n, const glm::ivec3& c) {
  return glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c, glm::ivec3(n)));
}

// Floods a level's N^3 block from the voxels on `stack` through their six
// face neighbours: enter(c) marks a neighbour and says whether it joined.
template <class Enter>
void flood_faces(int n, std::vector<glm::ivec3>& stack, Enter&& enter) {
  while (!stack.empty()) {
    const glm::ivec3 c = stack.back();
    stack.pop_back();
    for (int f = 0; f < kFaces; ++f) {
      glm::ivec3 nb = c;
      nb[face_axis(f)] += face_positive(f) ? 1 : -1;
      if (in_level(n, nb) && enter(nb)) stack.push_back(nb);
    }
  }
}

std::vector<uint8_t> flood_level(const Cascades& cascades, int l, const std::vector<uint8_t>* coarser,
                                 const GiLayout& out) {
  const int n = out.n;
  const VoxelBox box = cascades.level_box(l);
  const auto local = [n](const glm::ivec3& c) { return level_local_index(n, c); };
  std::vector<uint8_t> passable(size_t(n) * size_t(n) * size_t(n)), open(passable.size(), 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        passable[local({x, y, z})] = cascades.occupancy(l, box.lo + glm::ivec3(x, y, z)) < 0.5f;
  std::vector<glm::ivec3> stack;
  const VoxelBox up = l + 1 < out.k ? cascades.level_box(l + 1) : VoxelBox{};
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::ivec3 c(x, y, z);
        const bool face = x == 0 || y == 0 || z == 0 || x == n - 1 || y == n - 1 || z == n - 1;
        if (!face || !passable[local(c)]) continue;
        bool seed = coarser == nullptr;
        if (coarser) {
          const glm::ivec3 parent = ((box.lo + c) >> 1) - up.lo;  // arithmetic shift: floor(g / 2)
          seed = !in_level(n, parent) || (*coarser)[local(parent)];
        }
        if (seed) open[local(c)] = 1, stack.push_back(c);
      }
  flood_faces(n, stack, [&](const glm::ivec3& nb) {
    if (!passable[local(nb)] || open[local(nb)]) return false;
    open[local(nb)] = 1;
    return true;
  });
  std::vector<uint8_t> flag = open;  // solid voxels: open where open air touches them
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::ivec3 c(x, y, z);
        if (passable[local(c)]) continue;
        for (int f = 0; f < kFaces && !flag[local(c)]; ++f) {
          glm::ivec3 nb = c;
          nb[face_axis(f)] += face_positive(f) ? 1 : -1;
          flag[local(c)] = in_level(n, nb) && open[local(nb)];
        }
      }
  return flag;
}

// A coarser voxel whose eight children lie in the finer level's box takes
// their flags (open if any is): the finer flood saw walls the coarse one
// missed, and without this a coarse voxel of a sealed room, flooded
// through walls thinner than it, showed the sky in its direct light.
void restrict_to_finer(const Cascades& cascades, int l, const std::vector<uint8_t>& fine, std::vector<uint8_t>& coarse,
                       int n) {
  const glm::ivec3 fine_lo = cascades.level_box(l).lo, coarse_lo = cascades.level_box(l + 1).lo;
  const auto local = [n](const glm::ivec3& c) { return level_local_index(n, c); };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::ivec3 child0 = 2 * (coarse_lo + glm::ivec3(x, y, z)) - fine_lo;
        if (glm::any(glm::lessThan(child0, glm::ivec3(0))) || glm::any(glm::greaterThan(child0, glm::ivec3(n - 2))))
          continue;
        uint8_t any_open = 0;
        for (int k = 0; k < 8; ++k) any_open |= fine[local(child0 + glm::ivec3(k & 1, (k >> 1) & 1, k >> 2))];
        coarse[local({x, y, z})] = any_open;
      }
}

// Sets or clears flag bits (kVoxelAir, ...) of one vmap entry: bits 28 ..
// 30 of a surface voxel's index, -1 - flags for a voxel with no surface
// (the shaders' vmap_flags).
void set_voxel_flag(int32_t& v, int32_t flag, bool on) {
  int32_t flags = v < 0 ? -1 - v : (v >> 28) & 7;
  flags = on ? (flags | flag) : (flags & ~flag);
  v = v < 0 ? -1 - flags : (v & 0x0FFFFFFF) | (flags << 28);
}
bool voxel_flag(int32_t v, int32_t flag) { return ((v < 0 ? -1 - v : (v >> 28) & 7) & flag) != 0; }

// Writes the flags into vmap: kVoxelOpen, and kVoxelAir where less than
// half solid.
void mark_sky_open(const Cascades& cascades, GiLayout& out) {
  std::vector<std::vector<uint8_t>> flags(size_t(out.k));
  for (int l = out.k - 1; l >= 0; --l)
    flags[size_t(l)] = flood_level(cascades, l, l + 1 < out.k ? &flags[size_t(l) + 1] : nullptr, out);
  for (int l = 0; l + 1 < out.k; ++l) restrict_to_finer(cascades, l, flags[size_t(l)], flags[size_t(l) + 1], out.n);
  for (int l = 0; l < out.k; ++l) {
    const size_t first = out.voxel(l, glm::ivec3(0));
    const VoxelBox box = cascades.level_box(l);
    for (size_t i = 0; i < flags[size_t(l)].size(); ++i) {
      int32_t& v = out.vmap[first + i];
      if (flags[size_t(l)][i]) set_voxel_flag(v, kVoxelOpen, true);
      const glm::ivec3 c(int(i % size_t(out.n)), int(i / size_t(out.n) % size_t(out.n)),
                         int(i / (size_t(out.n) * size_t(out.n))));
      if (cascades.occupancy(l, box.lo + c) < 0.5f) set_voxel_flag(v, kVoxelAir, true);
    }
  }
}

// Sealed air (issue 25): the air voxels (kVoxelAir) the sky flood did not
// reach (no kVoxelOpen), in 6-connected pockets numbered across all levels
// (GiLayout::pocket), and which pockets an emissive face looks into
// (pocket_glows). Light cannot get into a pocket through its walls; with
// no light source inside, everything in it is black (see mark_dark).
void label_pockets(GiLayout& out) {
  const int n = out.n;
  out.pocket.assign(out.voxels(), -1);
  int32_t pockets = 0;
  std::vector<glm::ivec3> stack;
  for (int l = 0; l < out.k; ++l) {
    const size_t first = out.voxel(l, glm::ivec3(0));
    auto sealed_air = [&](const glm::ivec3& c) {
      const size_t v = first + level_local_index(n, c);
      return out.pocket[v] < 0 && voxel_flag(out.vmap[v], kVoxelAir) && !voxel_flag(out.vmap[v], kVoxelOpen);
    };
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          if (!sealed_air({x, y, z})) continue;
          const int32_t id = pockets++;
          out.pocket[first + level_local_index(n, {x, y, z})] = id;
          stack.assign(1, glm::ivec3(x, y, z));
          flood_faces(n, stack, [&](const glm::ivec3& nb) {
            if (!sealed_air(nb)) return false;
            out.pocket[first + level_local_index(n, nb)] = id;
            return true;
          });
        }
  }
  out.pocket_glows.assign(size_t(pockets), 0);
  for (size_t s = 0; s < out.surfaces(); ++s) {
    const int l = out.surf_pos[s].w;
    if (!s_is_updated(out, l, int32_t(s))) continue;
    for (int f = 0; f < kFaces; ++f) {
      const glm::vec4 emission = out.attr[(s * 6 + size_t(f)) * 3 + 2];
      if (out.attr[(s * 6 + size_t(f)) * 3].w <= 0.0f || glm::max(emission.x, glm::max(emission.y, emission.z)) <= 0.0f)
        continue;
      const glm::ivec3 c(out.surf_pos[s]);
      for (int g = -1; g < kFaces; ++g) {  // the voxel and its six neighbours
        glm::ivec3 nb = c;
        if (g >= 0) nb[face_axis(g)] += face_positive(g) ? 1 : -1;
        if (!in_level(n, nb)) continue;
        if (const int32_t id = out.pocket[out.voxel(l, nb)]; id >= 0) out.pocket_glows[size_t(id)] = 1;
      }
    }
  }
}

// The pockets holding a point light (conservatively: any pocket within a
// voxel of it on some level) or glowing are lit.
std::vector<uint8_t> lit_pockets(const std::vector<PointLight>& lights, const GiLayout& out) {
  std::vector<uint8_t> lit = out.pocket_glows;
  for (const PointLight& light : lights) {
    for (int l = 0; l < out.k; ++l) {
      const double size = double(out.params.fparams.x) * double(1 << l);
      const glm::ivec3 c =
          glm::ivec3(glm::floor((light.position - out.origin) / size)) - glm::ivec3(out.params.lo[l]);
      for (int z = -1; z <= 1; ++z)
        for (int y = -1; y <= 1; ++y)
          for (int x = -1; x <= 1; ++x) {
            const glm::ivec3 nb = c + glm::ivec3(x, y, z);
            if (!in_level(out.n, nb)) continue;
            if (const int32_t id = out.pocket[out.voxel(l, nb)]; id >= 0) lit[size_t(id)] = 1;
          }
    }
  }
  return lit;
}

// Dark voxels (kVoxelDark): sealed air of an unlit pocket, and the solid
// voxels all of whose air neighbours are (at least one); a coarser voxel
// covered by the finer level is dark when its eight children are. Returns
// whether any voxel's flag changed.
bool mark_dark(const std::vector<PointLight>& lights, GiLayout& out) {
  std::vector<uint8_t> lit = lit_pockets(lights, out);
  if (lit == out.pocket_lit) return false;  // set_lights: the lights moved within their pockets (the common case)
  out.pocket_lit = std::move(lit);
  const int n = out.n;
  std::vector<uint8_t> dark(out.voxels(), 0);
  for (size_t v = 0; v < dark.size(); ++v) dark[v] = out.pocket[v] >= 0 && !out.pocket_lit[size_t(out.pocket[v])];
  for (int l = 0; l < out.k; ++l)
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const glm::ivec3 c(x, y, z);
          const size_t v = out.voxel(l, c);
          if (out.pocket[v] >= 0 || voxel_flag(out.vmap[v], kVoxelOpen)) continue;  // sealed air, or open
          int air = 0, dark_air = 0;
          for (int f = 0; f < kFaces; ++f) {
            glm::ivec3 nb = c;
            nb[face_axis(f)] += face_positive(f) ? 1 : -1;
            if (!in_level(n, nb) || out.pocket[out.voxel(l, nb)] < 0) continue;
            ++air;
            dark_air += dark[out.voxel(l, nb)];
          }
          dark[v] = air > 0 && dark_air == air;
        }
  for (int l = 0; l + 1 < out.k; ++l) {
    const glm::ivec3 fine_lo(out.params.lo[l]), coarse_lo(out.params.lo[l + 1]);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const glm::ivec3 child0 = 2 * (coarse_lo + glm::ivec3(x, y, z)) - fine_lo;
          if (!in_level(n, child0) || !in_level(n, child0 + 1)) continue;
          uint8_t all = 1;
          for (int k = 0; k < 8; ++k) all &= dark[out.voxel(l, child0 + glm::ivec3(k & 1, (k >> 1) & 1, k >> 2))];
          dark[out.voxel(l + 1, {x, y, z})] = all;
        }
  }
  bool changed = false;
  for (size_t v = 0; v < dark.size(); ++v) {
    const int32_t before = out.vmap[v];
    set_voxel_flag(out.vmap[v], kVoxelDark, dark[v] != 0);
    changed = changed || out.vmap[v] != before;
  }
  return changed;
}

}  // namespace

Result<GiLayout> build_gi_layout(const Cascades& cascades, const GiLights& lights, const GiConfig& config) {
  if (Status s = check_gi_config(config); !s.ok()) return s;
  if (Status s = check_gi_lights(lights, config); !s.ok()) return s;
  GiLayout out;
  out.n = cascades.resolution();
  out.k = cascades.levels();
  if (out.k > kGiMaxLevels) return bad("cascades of " + std::to_string(out.k) + " levels: at most 16");
  // The kernels index voxel * 16 + direction in 32-bit ints.
  if (size_t(out.k) * size_t(out.n) * size_t(out.n) * size_t(out.n) * 16 > size_t(INT32_MAX)) {
    return Status(ErrorCode::kTooLarge, "gi: " + std::to_string(out.k) + " levels of " + std::to_string(out.n) +
                                            "^3 voxels are too many (at most 2^31 / 16 voxels in all)");
  }
  out.origin = cascades.origin();
  PackedGBuffer packed;
  cascades.pack(&packed);
  out.occ.assign(out.voxels() * 6, 0.0f);
  out.vmap.assign(out.voxels(), -1);
  out.level_first.assign(size_t(out.k), 0);
  out.level_count.assign(size_t(out.k), 0);
  out.level_shadow.assign(size_t(out.k), 0);
  for (int l = 0; l < out.k; ++l) add_level(packed, l, cascades.level_valid(l), out);
  mark_sky_open(cascades, out);
  fill_params(cascades, lights, config, out);  // after the opacities: injection reads them
  label_pockets(out);
  mark_dark(lights.points, out);
  return out;
}

Status GiEngineBase::load(const Cascades& cascades, const GiLights& lights) {
  Result<GiLayout> layout = build_gi_layout(cascades, lights, config_);
  if (!layout.ok()) return layout.status();
  layout_ = std::move(layout).value();
  loaded_ = false;
  if (Status s = upload(layout_); !s.ok()) return s;
  const int alpha_items = int(layout_.voxels() * 16);
  if (Status s = run(GiKernel::kAlpha, 0, alpha_items, 0); !s.ok()) return s;
  loaded_ = true;
  frame_ = 0;
  return {};
}

Status GiEngineBase::set_lights(const GiLights& lights) {
  if (!loaded_) return Status(ErrorCode::kInvalidArgument, "gi: load() the cascades first");
  if (Status s = check_gi_lights(lights, config_); !s.ok()) return s;
  fill_light_params(lights, config_, layout_);
  if (mark_dark(lights.points, layout_)) {  // a light went into a sealed pocket, or left one
    if (Status s = upload_vmap(layout_); !s.ok()) return s;
  }
  return upload_lights(layout_);
}

Result<GiTimings> GiEngineBase::update_levels(const std::vector<int>& levels) {
  if (!loaded_) return Status(ErrorCode::kInvalidArgument, "gi: load() the cascades first");
  const auto t0 = std::chrono::steady_clock::now();
  GiTimings t;
  for (int l : levels) {
    if (l < 0 || l >= layout_.k) return bad("gi: level " + std::to_string(l) + " is not in 0 .. " +
                                            std::to_string(layout_.k - 1));
  }
  // All reads come from the previous frame's buffers: trace every level's
  // cones, then update, then commit, then precombine; one batch.
  std::vector<GiStep> cones, updates, commits, precombines;
  for (int l : levels) {
    const int first = layout_.level_first[size_t(l)], c = layout_.level_count[size_t(l)];
    if (c == 0) continue;
    cones.push_back({GiKernel::kCones, 0, c * 16, l});
    updates.push_back({GiKernel::kUpdate, first, c, l});
    commits.push_back({GiKernel::kCommit, first, c, l});
    const int all = c + layout_.level_shadow[size_t(l)];
    if (config_.precombined) precombines.push_back({GiKernel::kPrecombine, first * 16, all * 16, l});
    t.surface_voxels += size_t(c);
  }
  std::vector<GiStep> steps = std::move(cones);
  steps.insert(steps.end(), updates.begin(), updates.end());
  steps.insert(steps.end(), commits.begin(), commits.end());
  steps.insert(steps.end(), precombines.begin(), precombines.end());
  if (Status s = run_steps(steps); !s.ok()) return s;
  t.levels_updated = int(levels.size());
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.device_seconds = last_device_seconds_;
  const auto kernel = [&](GiKernel k) { return last_kernel_seconds_[int(k) - 1]; };
  t.stage_device_seconds = {kernel(GiKernel::kCones), kernel(GiKernel::kUpdate), kernel(GiKernel::kCommit),
                            kernel(GiKernel::kPrecombine)};
  return t;
}

namespace {

// a + b, or -1 where either was not measured.
double add_measured(double a, double b) { return a < 0 || b < 0 ? -1.0 : a + b; }

}  // namespace

Result<GiTimings> GiEngineBase::update_level(int level) { return update_levels({level}); }

Result<GiTimings> GiEngineBase::update_all(int passes) {
  std::vector<int> all;
  for (int l = 0; l < layout_.k; ++l) all.push_back(l);
  GiTimings sum;
  for (int p = 0; p < passes; ++p) {
    Result<GiTimings> t = update_levels(all);
    if (!t.ok()) return t;
    sum.levels_updated += t.value().levels_updated;
    sum.surface_voxels += t.value().surface_voxels;
    sum.seconds += t.value().seconds;
    const GiTimings& one = t.value();
    if (p == 0) {
      sum.device_seconds = one.device_seconds;
      sum.stage_device_seconds = one.stage_device_seconds;
      continue;
    }
    sum.device_seconds = add_measured(sum.device_seconds, one.device_seconds);
    GiTimings::Stages& s = sum.stage_device_seconds;
    const GiTimings::Stages& o = one.stage_device_seconds;
    s = {add_measured(s.cones, o.cones), add_measured(s.update, o.update), add_measured(s.copy, o.copy),
         add_measured(s.precombine, o.precombine)};
  }
  return sum;
}

Result<GiTimings> GiEngineBase::frame() {
  if (!config_.staggered) return update_all(1);
  const int level = Cascades::scheduled_level(frame_++, layout_.k);
  return update_level(level);
}

Status GiEngineBase::irradiance(std::span<const glm::dvec3> points, std::span<const glm::vec3> normals,
                                int bounces, std::span<glm::vec3> out) {
  if (!loaded_) return Status(ErrorCode::kInvalidArgument, "gi: load() the cascades first");
  if (normals.size() != points.size() || out.size() != points.size())
    return bad("gi irradiance: " + std::to_string(points.size()) + " points, " + std::to_string(normals.size()) +
               " normals and " + std::to_string(out.size()) + " outputs: the sizes must match");
  if (bounces < 1 || bounces > 3) return bad("gi irradiance: bounces " + std::to_string(bounces) + " must be 1 .. 3");
  if (points.empty()) return {};
  std::vector<glm::vec4> qin(points.size() * 2);
  for (size_t i = 0; i < points.size(); ++i) {
    qin[2 * i] = glm::vec4(glm::vec3(points[i] - layout_.origin), 1.0f);
    const float len = glm::length(normals[i]);
    if (!(len > 0.0f) || !std::isfinite(len)) return bad("gi irradiance: normal " + std::to_string(i) + " has no length");
    qin[2 * i + 1] = glm::vec4(normals[i] / len, 0.0f);
  }
  if (Status s = set_queries(qin); !s.ok()) return s;
  if (Status s = run(GiKernel::kQuery, 0, int(points.size()), bounces); !s.ok()) return s;
  std::vector<glm::vec4> qout;
  if (Status s = get_queries(qout, points.size()); !s.ok()) return s;
  for (size_t i = 0; i < points.size(); ++i) out[i] = glm::vec3(qout[i]);
  return {};
}

Result<GiRadiance> GiEngineBase::radiance() {
  if (!loaded_) return Status(ErrorCode::kInvalidArgument, "gi: load() the cascades first");
  std::vector<glm::vec4> light;
  if (Status s = read_light(light); !s.ok()) return s;
  GiRadiance r;
  for (int l = 0; l < layout_.k; ++l) {
    const size_t first = size_t(layout_.level_first[size_t(l)]);
    for (size_t s = first; s < first + size_t(layout_.level_count[size_t(l)]); ++s) {
      const glm::ivec4 p = layout_.surf_pos[s];
      r.voxels.emplace_back(glm::ivec3(p) + glm::ivec3(layout_.params.lo[p.w]), p.w);
      std::array<glm::vec3, 18>& faces = r.light.emplace_back();
      for (int j = 0; j < 18; ++j) faces[size_t(j)] = glm::vec3(light[s * 18 + size_t(j)]);
    }
  }
  return r;
}

}  // namespace detail
}  // namespace ldc
