// The cone tracing kernels, in the subset of GLSL 4.50 that is also C++20
// with GLM: compiled by glslc into the Vulkan shaders (shaders/gi.comp) and
// included by the CPU reference (gi_cpu.cpp) inside a struct, so that both
// run the same algorithm step for step. Conventions that keep it both:
// float literals carry an f suffix, conversions are written T(x), out and
// inout parameters go through OUT(T) / INOUT(T), GI_INLINE asks the C++
// compiler to inline a hot function (empty in GLSL), and the data is reached
// through accessor functions each side defines (occ_load, light_load, ...),
// plus the uniform block P and the push constants pc.
//
// Layouts (indices into flat arrays; N voxels per axis, K levels, S surface
// voxels, sorted by level):
//   voxel v of level l (local coords c):  l * N^3 + (c.z * N + c.y) * N + c.x
//   occ:    (voxel * 6 + face)            face opacity
//   alpha:  (voxel * 16 + dir)            premultiplied opacity seen along dir
//   vmap:   voxel -> surface index (bits 0..27) and flags (bits 28..30),
//           or -1 - flags for a voxel with no surface; flags: 1 air (less
//           than half solid), 2 dark (sealed from the sky, no light inside),
//           4 open to the sky; see surface_at and vmap_flags
//   attr:   (s * 6 + face) * 3 + {0 albedo rgb+weight, 1 normal xyz, 2 emission}
//   fsrc:   (s * 6 + face)            light slot the face shows (its own, or
//                                     the neighbour's it was propagated from), -1 none
//   light:  (s * 6 + face) * 3 + ch       ch 0 direct (D), 1 bounce (B1), 2 bounce 2 (B2)
//   pre:    (s * 16 + dir) * 3 + ch       light of ch seen along dir, premultiplied by opacity
//   plight: voxel                         injected point lights' emission density (kFlagLightVolume)
//   cones:  (s * 16 + dir) * 3 + {0 sources, 1 D, 2 B1}   what the voxel centre's cone dir gathered

// Cone half-angle of the 16 cones: solid angle 4 pi / 16 = pi / 4, so
// cos = 7/8 and tan = sqrt(15) / 7.
GI_CONST float kTanHalf = 0.5532833352f;
GI_CONST float kPi = 3.1415926536f;
GI_CONST int kFlagPrecombined = 1;
GI_CONST int kFlagNearFar = 2;
GI_CONST int kFlagLightVolume = 4;
GI_CONST int kMaxSteps = 160;
GI_CONST int kMaxQueryRays = 16;  // kGiMaxQueryRays

int gi_n() { return P.iparams.x; }
int gi_k() { return P.iparams.y; }
int gi_flags() { return P.iparams.z; }
int gi_lights() { return P.iparams.w; }
float gi_s0() { return P.fparams.x; }
float level_size(int l) { return gi_s0() * float(1 << l); }

vec3 voxel_centre(int l, ivec3 c) { return (vec3(IXYZ(P.lo[l]) + c) + vec3(0.5f)) * level_size(l); }

// vmap's fields (see the layouts above).
GI_CONST int kVoxelAir = 1;
GI_CONST int kVoxelDark = 2;
GI_CONST int kVoxelOpen = 4;
int surface_at(int voxel) {
  int v = vmap_load(voxel);
  return v < 0 ? -1 : (v & 0x0FFFFFFF);
}
int vmap_flags(int voxel) {
  int v = vmap_load(voxel);
  return v < 0 ? -1 - v : ((v >> 28) & 7);
}
bool sky_open(int voxel) { return (vmap_flags(voxel) & kVoxelOpen) != 0; }
bool sealed_dark(int voxel) { return (vmap_flags(voxel) & kVoxelDark) != 0; }

int voxel_index(int l, ivec3 c) {
  int n = gi_n();
  return l * n * n * n + (c.z * n + c.y) * n + c.x;
}

// Face f of a voxel that a cone travelling along d sees on axis a: the face
// looking back toward the cone's apex. Weights d[a]^2 sum to 1.
int facing_face(vec3 d, int a) { return 2 * a + (d[a] > 0.0f ? 1 : 0); }

float blend_alpha(int voxel, vec3 d) {
  float r = 0.0f;
  for (int a = 0; a < 3; ++a) r += d[a] * d[a] * occ_load(voxel * 6 + facing_face(d, a));
  return r;
}

// Light of channel ch of surface voxel s seen along d, premultiplied by the
// faces' opacity (three lookups: the path the precombined buffer saves).
// The opacity blends all three facing faces; the light is the mean over the
// faces that show a surface. A voxel inside a flat wall has opacity on all
// its faces but a surface on one: seen obliquely, its other faces are
// hidden by the wall's next voxels, and counting them as black made a
// closed emissive box look 40% darker than it is.
// faces[a]: the face seen on axis a, or -1 where none is (hidden).
vec3 blend_light_faces(int s, int voxel, vec3 d, int ch, ivec3 faces) {
  vec3 lit = vec3(0.0f);
  float all_w = 0.0f;
  float lit_w = 0.0f;
  for (int a = 0; a < 3; ++a) {
    // The opacity is blend_alpha's; the light, the seen faces' mean.
    float w = d[a] * d[a] * occ_load(voxel * 6 + facing_face(d, a));
    all_w += w;
    int slot = faces[a] >= 0 ? fsrc_load(s * 6 + faces[a]) : -1;
    if (slot >= 0) {
      lit += w * XYZ(light_load(slot * 3 + ch));
      lit_w += w;
    }
  }
  return lit_w > 0.0f ? lit * (all_w / lit_w) : vec3(0.0f);
}

vec3 blend_light(int s, int voxel, vec3 d, int ch) {
  return blend_light_faces(s, voxel, d, ch, ivec3(facing_face(d, 0), facing_face(d, 1), facing_face(d, 2)));
}

struct ConeSample {
  float alpha;
  vec3 d;
  vec3 b1;
  vec3 b2;
};

// A trilinear corner whose voxel is not wholly ahead of the plane through
// the cone's apex normal to d is skipped: at the coarse levels a cone
// reaches, such a voxel holds the very surface the cone starts from (its
// faces say "opaque from outside" while the apex is inside it), and
// counting it made surfaces occlude themselves wherever they do not lie on
// the level's voxel faces (a slab's underside at z = -0.6 m received 63%
// of a uniform sky, its top at z = 0 98%).
//
// The faces a cone sees are those on the apex's side of the voxel. They are
// the faces facing d (what the precombined buffers hold) when the voxel lies
// ahead of the apex on every axis; a voxel beside the cone's path (the apex
// between its two faces on some axis, or past it) shows the face toward
// the apex on each axis, none on an axis whose slab holds the apex, so a
// cone grazing a coarse voxel never sees the far side of a wall in it
// (a thin wall lit on one side leaked 2.5% of its light to the other).
// The test is a hard cut, so a tie must not be left to float rounding: a
// point light on lattice planes (as at (0.4, -0.3, -0.2) m with 0.2 m
// voxels) puts neighbours of the apex exactly on the support plane, and
// there an NVIDIA GPU and the CPU engine decided apart (9% of a voxel's
// direct light). A voxel within 1e-3 of a voxel of the plane counts as
// not ahead on every device.
bool corner_ahead(int l, ivec3 c, vec3 d, vec3 apex) {
  float size = level_size(l);
  float support = 0.5f * size * (abs(d.x) + abs(d.y) + abs(d.z));
  return dot(voxel_centre(l, c) - apex, d) > support + 1e-3f * size;
}

// Opacity of a voxel seen along cone dir: precombined, or the three facing
// faces blended.
float voxel_alpha(int voxel, int dir) {
  return (gi_flags() & kFlagPrecombined) != 0 ? alpha_load(voxel * 16 + dir) : blend_alpha(voxel, XYZ(P.dirs[dir]));
}

// d: the direction of travel (the cone's axis, or a ray of it); dir: the
// cone whose buffers (opacity and light seen along its axis) stand for it.
// Inlined into the marches on the CPU engine (GI_INLINE): called from the
// cones' and the rays' marches, gcc stopped inlining it and the cones took
// 1.8 times as long.
GI_INLINE void sample_corner(int l, ivec3 c, vec3 d, int dir, float w, vec3 apex, INOUT(ConeSample) cs) {
  if (!corner_ahead(l, c, d, apex)) return;
  float size = level_size(l);
  vec3 centre = voxel_centre(l, c);
  int voxel = voxel_index(l, c);
  bool pre = (gi_flags() & kFlagPrecombined) != 0;
  cs.alpha += w * voxel_alpha(voxel, dir);
  int s = surface_at(voxel);
  if (s < 0) return;
  ivec3 seen = ivec3(-1);
  bool ahead = true;
  // An apex on a face's plane (within 1e-3 voxel, so that float rounding
  // does not pick the side) sees that face.
  float half_size = 0.499f * size;
  for (int a = 0; a < 3; ++a) {
    if (apex[a] <= centre[a] - half_size) seen[a] = 2 * a + 1;
    if (apex[a] >= centre[a] + half_size) seen[a] = 2 * a;
    if (d[a] != 0.0f && seen[a] != facing_face(d, a)) ahead = false;
  }
  if (!ahead) {
    cs.d += w * blend_light_faces(s, voxel, d, 0, seen);
    cs.b1 += w * blend_light_faces(s, voxel, d, 1, seen);
    cs.b2 += w * blend_light_faces(s, voxel, d, 2, seen);
    return;
  }
  if (pre) {
    cs.d += w * XYZ(pre_load((s * 16 + dir) * 3 + 0));
    cs.b1 += w * XYZ(pre_load((s * 16 + dir) * 3 + 1));
    cs.b2 += w * XYZ(pre_load((s * 16 + dir) * 3 + 2));
  } else {
    vec3 dc = XYZ(P.dirs[dir]);
    cs.d += w * blend_light(s, voxel, dc, 0);
    cs.b1 += w * blend_light(s, voxel, dc, 1);
    cs.b2 += w * blend_light(s, voxel, dc, 2);
  }
}

// Continuous voxel coordinates of p at level l (voxel centres at whole
// numbers); true when the 8 trilinear corners lie inside the level.
bool level_coords(int l, vec3 p, OUT(vec3) u) {
  u = p / level_size(l) - vec3(IXYZ(P.lo[l])) - vec3(0.5f);
  float hi = float(gi_n() - 1);
  return u.x >= 0.0f && u.y >= 0.0f && u.z >= 0.0f && u.x <= hi && u.y <= hi && u.z <= hi;
}

// Trilinear corner k (0..7) of the cell holding level coordinates u: its
// offset from the cell's low corner c0, and its weight.
ivec3 corner_offset(int k) { return ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1); }
ivec3 cell_low(vec3 u) { return min(ivec3(floor(u)), ivec3(gi_n() - 2)); }
float corner_weight(vec3 f, ivec3 o) {
  return (o.x == 1 ? f.x : 1.0f - f.x) * (o.y == 1 ? f.y : 1.0f - f.y) * (o.z == 1 ? f.z : 1.0f - f.z);
}

ConeSample sample_level(int l, vec3 u, vec3 d, int dir, vec3 apex) {
  ConeSample cs;
  cs.alpha = 0.0f;
  cs.d = vec3(0.0f);
  cs.b1 = vec3(0.0f);
  cs.b2 = vec3(0.0f);
  ivec3 c0 = cell_low(u);
  vec3 f = u - vec3(c0);
  for (int k = 0; k < 8; ++k) {
    float w = corner_weight(f, corner_offset(k));
    if (w > 0.0f) sample_corner(l, c0 + corner_offset(k), d, dir, w, apex, cs);
  }
  return cs;
}

// Injected point lights (kFlagLightVolume): the light volume's emission
// density [radiance / m] at level coordinates u, trilinear.
vec3 sample_light_volume(int l, vec3 u) {
  ivec3 c0 = cell_low(u);
  vec3 f = u - vec3(c0);
  vec3 r = vec3(0.0f);
  for (int k = 0; k < 8; ++k) r += corner_weight(f, corner_offset(k)) * XYZ(plight_load(voxel_index(l, c0 + corner_offset(k))));
  return r;
}

// The widest voxel a cone along d may sample at distance t from its apex:
// as wide as the cone (2 t tan_half), but only as wide as keeps all eight
// trilinear corners wholly ahead of the apex. Each corner's centre lies
// within one voxel s of p on every axis, so ahead of the apex by at least
// t - s (|dx| + |dy| + |dz|), and corner_ahead wants more than half of
// s (|dx| + |dy| + |dz|): t > 1.5 s (|dx| + |dy| + |dz|). Coarsening as
// soon as a voxel fit the cone (t = 0.9 s) dropped most corners of each new
// level, and the cone crossed metres of ground nearly unoccluded: inside
// the main job's tunnel under a sky alone, cones let in 33 times the
// path tracer's light (issue 25).
float cone_voxel_width(float t, vec3 d, float tan_half) {
  return min(2.0f * tan_half * t, t / (1.5f * (abs(d.x) + abs(d.y) + abs(d.z))));
}

// The level a march samples at p where the cone is diam wide: the
// coarsest not wider than the cone (at least l0), or a coarser one where p
// leaves that level's box; gi_k() past the coarsest. u: p's coordinates in it.
int march_level(vec3 p, float diam, int l0, OUT(vec3) u) {
  int l = l0;
  while (l + 1 < gi_k() && level_size(l + 1) <= diam) ++l;
  while (l < gi_k() && !level_coords(l, p, u)) ++l;
  return l;
}

// What one cone gathers: light of the three buffers and of the direct
// sources, each already multiplied by the transmittance in front of it.
struct ConeResult {
  vec3 src;  // injected point lights
  float sky;  // transmittance left where the cone escaped the coarsest level (0: it did not)
  vec3 d;
  vec3 b1;
  vec3 b2;
  float transmittance;
};

ConeResult no_light() {
  ConeResult r;
  r.src = vec3(0.0f);
  r.sky = 0.0f;
  r.d = vec3(0.0f);
  r.b1 = vec3(0.0f);
  r.b2 = vec3(0.0f);
  r.transmittance = 0.0f;
  return r;
}

// True when the 8 voxels of level l around level coordinates u hold no
// solid (each one's opacity along cone dir is 0).
bool block_empty(int l, vec3 u, int dir) {
  ivec3 c0 = cell_low(u);
  for (int k = 0; k < 8; ++k)
    if (voxel_alpha(voxel_index(l, c0 + corner_offset(k)), dir) > 0.0f) return false;
  return true;
}

// How far along d a march at p (level coordinates u at level l, whose 8
// voxels around u are empty) may jump: to where p leaves the largest empty
// block of 2 x 2 x 2 voxels around it on level l or a coarser one.
float empty_run(int l, vec3 u, vec3 p, vec3 d, int dir) {
  int le = l;
  vec3 ue = u;
  vec3 un = vec3(0.0f);
  while (le + 1 < gi_k() && level_coords(le + 1, p, un) && block_empty(le + 1, un, dir)) {
    ++le;
    ue = un;
  }
  float size = level_size(le);
  vec3 lo = vec3(IXYZ(P.lo[le]) + cell_low(ue)) * size;
  vec3 hi = lo + vec3(2.0f * size);
  float run = 1e30f;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0.0f) run = min(run, (hi[a] - p[a]) / d[a]);
    if (d[a] < 0.0f) run = min(run, (lo[a] - p[a]) / d[a]);
  }
  return max(run, 0.0f) + 1e-3f * level_size(l);
}

// Marches along d from apex (relative to the lattice origin) starting at
// distance t0 at level l0 or coarser, reading the precombined buffers of
// cone dir, on voxels as wide as a cone of half-angle atan(tan_half) allows
// (cone_voxel_width). The 16 cones march along their axes with kTanHalf;
// the queries' rays (query_rays) along directions inside cone dir, narrow
// (kRayTan), skipping empty blocks (skip_empty) and taking up to
// max_steps. `lit`: the point being lit. Injected light at p reaches it as
// 1 / |p - lit|^2, not as the cone's 1 / t^2 from its apex: a query's apex
// sits a voxel above the surface, and without the correction a light 1.75
// voxels above a plane gave 1.7 times its irradiance.
GI_INLINE ConeResult march_lit(vec3 apex, vec3 lit, vec3 d, int dir, float tan_half, bool skip_empty,
                               int max_steps, int l0, float t0, float t1) {
  ConeResult r = no_light();
  float T = 1.0f;
  float t = t0;
  float base = level_size(l0);
  bool escaped = false;
  for (int step = 0; step < max_steps; ++step) {
    if (t >= t1) break;
    vec3 p = apex + t * d;
    vec3 u = vec3(0.0f);
    int l = march_level(p, max(cone_voxel_width(t, d, tan_half), base), l0, u);
    if (l == gi_k()) {
      escaped = true;
      break;
    }
    if (skip_empty && block_empty(l, u, dir)) {
      t += empty_run(l, u, p, d, dir);
      continue;
    }
    float dt = 0.5f * level_size(l);
    // Injected lights in this step, behind the occlusion in front of it.
    // Read from the level as wide as the cone, not the finer one the
    // opacity comes from (cone_voxel_width): a light splatted over voxels
    // narrower than the cone is hit or missed by its axis, not gathered.
    if ((gi_flags() & kFlagLightVolume) != 0) {
      vec3 to = p - lit;
      float g = t * t / max(dot(to, to), t * t);
      vec3 ul = vec3(0.0f);
      int ll = march_level(p, max(2.0f * kTanHalf * t, base), l0, ul);
      if (ll < gi_k()) r.src += (T * dt * g) * sample_light_volume(ll, ul);
    }
    ConeSample cs = sample_level(l, u, d, dir, apex);
    float a = min(cs.alpha, 1.0f);
    // Opacity of half a voxel: 1 - (1 - a)^(1/2); the premultiplied light scales alike.
    float ac = 1.0f - sqrt(1.0f - a);
    float k = a > 0.0f ? ac / a : 0.5f;
    r.d += (T * k) * cs.d;
    r.b1 += (T * k) * cs.b1;
    r.b2 += (T * k) * cs.b2;
    T *= 1.0f - ac;
    t += dt;
    if (T < 1e-4f) break;
  }
  if (escaped) r.sky = T;
  r.transmittance = T;
  return r;
}

ConeResult trace_cone_lit(vec3 apex, vec3 lit, int dir, int l0, float t0, float t1) {
  return march_lit(apex, lit, XYZ(P.dirs[dir]), dir, kTanHalf, false, kMaxSteps, l0, t0, t1);
}

// The queries' rays (GiConfig::query_rays). A wide cone over-darkens a
// surface it grazes: its samples read the half-covered voxels beside it as
// a new layer at every step (T <- T (1 - a)), so a cone from a tunnel's
// wall over the top of the opposite wall, whose rays escape in part (40% at
// one pixel), let 2.6% through, and the tunnel near its mouth got 0.57 of
// the exact sky (issue 25, bench_gi visibility). A ray narrow enough
// (voxels at most 1/8 of its distance: the width of a cone of tan 1/16)
// reads the ground beside it as it is, 0.89 of the exact sky there with 8
// rays per cone. With 4 rays per cone, tan 1/8 saw 0.72 and tan 1/16 0.84;
// 16 rays of tan 1/16 0.88: the width matters more than the count. Their
// mean stands for the cone: light, sky and transmittance. Rays skip blocks
// of empty voxels (empty_run: 6 times faster, figures within 0.002), but not
// through injected lights, which live in the air.
GI_CONST float kRayTan = 0.0625f;
GI_CONST int kMaxRaySteps = 640;
int query_rays() { return P.iparams2.x; }

ConeResult trace_rays_lit(vec3 apex, vec3 lit, int dir, int l0, float t0) {
  ConeResult r = no_light();
  int n = query_rays();
  bool skip = (gi_flags() & kFlagLightVolume) == 0;
  for (int k = 0; k < n; ++k) {
    vec3 d = XYZ(P.rays[dir * kMaxQueryRays + k]);
    ConeResult one = march_lit(apex, lit, d, dir, kRayTan, skip, kMaxRaySteps, l0, t0, 1e30f);
    r.src += one.src;
    r.sky += one.sky;
    r.d += one.d;
    r.b1 += one.b1;
    r.b2 += one.b2;
    r.transmittance += one.transmittance;
  }
  float w = 1.0f / float(n);
  r.src *= w;
  r.sky *= w;
  r.d *= w;
  r.b1 *= w;
  r.b2 *= w;
  r.transmittance *= w;
  return r;
}

// Shadow cones toward exact point lights: a cone of half-angle
// atan(kShadowTan) from apex (starting at t0, level l0 or coarser) to the
// light, opacity only (the three facing faces blended for the light's own
// direction), composited as the 16 cones are; returns the transmittance.
// Blending the 16 wide cones' transmittances by the light's direction
// instead lit points in shadow and shaded lit ones: the Cornell box's point
// light had a mean error of 42% that way, 37% with no shadows at all.
GI_CONST float kShadowTan = 0.1f;

float sample_alpha(int l, vec3 u, vec3 d, vec3 apex) {
  ivec3 c0 = cell_low(u);
  vec3 f = u - vec3(c0);
  float a = 0.0f;
  for (int k = 0; k < 8; ++k) {
    ivec3 c = c0 + corner_offset(k);
    float w = corner_weight(f, corner_offset(k));
    if (w > 0.0f && corner_ahead(l, c, d, apex)) a += w * blend_alpha(voxel_index(l, c), d);
  }
  return a;
}

float shadow_transmittance(vec3 apex, vec3 target, int l0, float t0) {
  vec3 to = target - apex;
  float dist = length(to);
  if (dist <= t0) return 1.0f;
  vec3 d = to / dist;
  float T = 1.0f;
  float t = t0;
  float base = level_size(l0);
  for (int step = 0; step < kMaxSteps && t < dist; ++step) {
    vec3 u = vec3(0.0f);
    int l = march_level(apex + t * d, max(cone_voxel_width(t, d, kShadowTan), base), l0, u);
    if (l == gi_k()) break;
    float a = min(sample_alpha(l, u, d, apex), 1.0f);
    T *= sqrt(1.0f - a);  // half a voxel's opacity, as in trace_cone_lit
    t += 0.5f * level_size(l);
    if (T < 1e-4f) return 0.0f;
  }
  return T;
}

// Shadow cone transmittance toward each exact point light from `from`.
struct LightVisibility {
  float v[8];  // kGiMaxPointLights
};
LightVisibility light_visibility(vec3 from, int l0, float t0) {
  LightVisibility vis;
  for (int i = 0; i < 8; ++i) vis.v[i] = i < gi_lights() ? shadow_transmittance(from, XYZ(P.light_pos[i]), l0, t0) : 0.0f;
  return vis;
}

// Irradiance of the exact point lights at x with normal n: I cos / r^2 (r
// at least min_r) times their visibility.
vec3 point_light_irradiance(vec3 x, vec3 n, float min_r, LightVisibility vis) {
  vec3 e = vec3(0.0f);
  for (int i = 0; i < gi_lights(); ++i) {
    vec3 to = XYZ(P.light_pos[i]) - x;
    float r2 = max(dot(to, to), min_r * min_r);
    float c = dot(n, to) * inversesqrt(max(dot(to, to), 1e-12f));
    if (c > 0.0f) e += (c / r2 * vis.v[i]) * XYZ(P.light_int[i]);
  }
  return e;
}

// The whole cone (no end).
ConeResult trace_cone_range(vec3 apex, int dir, int l0, float t0, float t1) {
  return trace_cone_lit(apex, apex, dir, l0, t0, t1);
}
ConeResult trace_cone(vec3 apex, int dir, int l0, float t0) { return trace_cone_lit(apex, apex, dir, l0, t0, 1e30f); }

// Cosine weights of the 16 directions for normal n, normalised so that a
// uniform radiance L gives irradiance pi L exactly; returns their sum.
float cosine_sum(vec3 n) {
  float sum = 0.0f;
  for (int i = 0; i < 16; ++i) sum += max(0.0f, dot(n, XYZ(P.dirs[i])));
  return sum;
}

vec3 face_axis_normal(int f) {
  vec3 n = vec3(0.0f);
  n[f / 2] = (f % 2 == 0) ? 1.0f : -1.0f;
  return n;
}

// Every kernel runs items pc.first .. pc.first + pc.count - 1, one per
// invocation (gid counts from 0 in each dispatch).

// Kernel 1: precombined opacity along every direction, item = voxel * 16 + direction (once per upload).
void kernel_alpha(int gid) {
  if (gid >= pc.count) return;
  int item = pc.first + gid;
  alpha_store(item, blend_alpha(item / 16, XYZ(P.dirs[item % 16])));
}

// Kernel 2: precombined light along every direction, item = surface voxel * 16 + direction.
void kernel_precombine(int gid) {
  if (gid >= pc.count) return;
  int item = pc.first + gid;
  int s = item / 16;
  int dir = item % 16;
  ivec4 sp = surf_pos_load(s);
  int voxel = voxel_index(sp.w, IXYZ(sp));
  vec3 d = XYZ(P.dirs[dir]);
  for (int ch = 0; ch < 3; ++ch) pre_store((s * 16 + dir) * 3 + ch, vec4(blend_light(s, voxel, d, ch), 0.0f));
}

// Where the voxel centre's cones start: one voxel out, or with the near/far
// split (flag kFlagNearFar) at ts = P.fparams2.x voxels of the level.
float far_start(int l) { return ((gi_flags() & kFlagNearFar) != 0 ? P.fparams2.x : 1.0f) * level_size(l); }

// Kernel 5: the first half of a lighting update of level pc.level: the
// cone along each direction from each updated surface voxel's centre, from
// the previous frame's buffers; items pc.first .. + pc.count of 0 .. 16 c
// (c = the level's updated voxels), direction-major. One invocation per
// cone rather than per voxel gives a GPU 16 times the threads to fill its
// cores (a level update has a few thousand surface voxels). Direction-major,
// so that neighbouring invocations (SIMD lanes) march neighbouring voxels'
// cones along one direction, which take alike steps, as the per-voxel
// kernel's lanes did. Lavapipe times it as before (bench_gi timing).
void kernel_cones(int gid) {
  if (gid >= pc.count) return;
  int item = pc.first + gid;
  int c = P.surf[pc.level].y;
  int s = P.surf[pc.level].x + item % c;
  int dir = item / c;
  ivec4 sp = surf_pos_load(s);
  ConeResult cr = trace_cone(voxel_centre(sp.w, IXYZ(sp)), dir, sp.w, far_start(sp.w));
  int slot = (s * 16 + dir) * 3;
  cone_store(slot + 0, vec4(cr.src, cr.sky));
  cone_store(slot + 1, vec4(cr.d, cr.transmittance));
  cone_store(slot + 2, vec4(cr.b1, 0.0f));
}

// Sky only reaches air open to it. The cones' opacity cannot promise that:
// a wall thinner than a coarse voxel is half transparent there, so a
// sealed room with 0.4 m walls got 5% of the sky's light through them
// (issue 25). So the host floods each level's air from the outside
// (build_gi_layout: coarsest level from its box's faces, each finer one
// from the faces of its box where the coarser level is open, through
// voxels less than half solid) and marks what it reaches (sky_open); a
// cone's sky counts only from open air. Face f of a surface voxel looks
// into the air of its neighbour on that side.
// The voxel whose air face f of voxel c of level l looks into.
int face_air_voxel(int l, ivec3 c, int f) {
  ivec3 nb = c;
  nb[f / 2] += (f % 2 == 0) ? 1 : -1;
  if (any(lessThan(nb, ivec3(0))) || any(greaterThanEqual(nb, ivec3(gi_n())))) return voxel_index(l, c);
  return voxel_index(l, nb);
}
bool face_sky_open(int l, ivec3 c, int f) { return sky_open(face_air_voxel(l, c, f)); }
// The voxel of level l holding p (outside the level's box: open).
bool point_sky_open(int l, vec3 p) {
  vec3 u = vec3(0.0f);
  if (!level_coords(l, p, u)) return true;
  return sky_open(voxel_index(l, ivec3(floor(u + vec3(0.5f)))));
}

// Light cannot get into air sealed from the sky through its walls, and a
// pocket with no point light and no glowing face inside is black: the host
// marks its voxels dark (mark_dark, from the flood above), and faces and
// queries there get no light at all. Without it a room sealed by 0.4 m
// walls showed 0.037 of radiance where the path tracer shows none: coarse
// voxels mix both sides of a wall, so the outside's light came through.
// A point is dark when the air among the eight voxels around it (by
// centres, as the trilinear samples) is all dark: the voxel holding it may
// be the wall's own, where a point on a room's corner falls on a voxel
// face.
bool point_dark(int l, vec3 p) {
  vec3 u = vec3(0.0f);
  if (!level_coords(l, p, u)) return false;
  ivec3 c0 = cell_low(u);
  bool air = false;
  for (int k = 0; k < 8; ++k) {
    int flags = vmap_flags(voxel_index(l, c0 + corner_offset(k)));
    if ((flags & kVoxelAir) == 0) continue;
    if ((flags & kVoxelDark) == 0) return false;
    air = true;
  }
  return air;
}

// A cone from sealed air (open = 0) must end on the pocket's walls, but
// the cascades let it through thin walls at coarse levels with light left
// (transmittance T): it then saw 1 - T of its walls. Its light is scaled by
// 1 / (1 - T), as if the rest were walls like those it saw (at most 4
// times: a cone that saw under a quarter is not extrapolated further).
// Cones from open air keep T for the sky.
float sealed_gain(float open, float T) { return open > 0.0f ? 1.0f : 1.0f / max(1.0f - T, 0.25f); }

// Kernel 3: the second half of a lighting update of surface voxels
// pc.first .. + pc.count, after kernel 5 traced their 16 cones: direct
// light (sky, point lights, emission), first bounce (from D) and second
// bounce (from B1) of each face, all at once.
// Near/far split (flag kFlagNearFar, split distance ts = P.fparams2.x voxels
// of the level): the 16 cones from the voxel's centre start at ts (the
// "far" part, shared by the six faces, as the talk's far cones traced once
// per voxel); each face then marches the "near" part of every cone on its
// side (n . d > 0) from its own apex (voxel centre + half a voxel along n,
// from half a voxel to the plane normal to d where the far part starts) and
// composites the far part behind it: L = L_near + T_near * L_far. Without
// the flag the centre's cones start at one voxel and are shared whole.
void kernel_update(int gid) {
  if (gid >= pc.count) return;
  int s = pc.first + gid;
  ivec4 sp = surf_pos_load(s);
  int l = sp.w;
  vec3 apex = voxel_centre(l, IXYZ(sp));
  bool split = (gi_flags() & kFlagNearFar) != 0;
  float vs = level_size(l);
  float ts = far_start(l);
  // One shadow cone per light from the centre, shared by the faces as the
  // cones are (6 times fewer marches than per face; the same error).
  LightVisibility vis = light_visibility(apex, l, vs);
  for (int f = 0; f < 6; ++f) {
    vec4 albedo = attr_load((s * 6 + f) * 3 + 0);
    vec3 n = XYZ(attr_load((s * 6 + f) * 3 + 1));
    vec3 emission = XYZ(attr_load((s * 6 + f) * 3 + 2));
    if (albedo.w <= 0.0f || sealed_dark(face_air_voxel(l, IXYZ(sp), f))) {
      for (int ch = 0; ch < 3; ++ch) light_store((s * 6 + f) * 3 + ch, vec4(0.0f));
      continue;
    }
    if (dot(n, n) < 0.5f) n = face_axis_normal(f);
    float wsum = cosine_sum(n);
    vec3 es = vec3(0.0f);
    vec3 ed = vec3(0.0f);
    vec3 eb = vec3(0.0f);
    vec3 apex_f = apex + (0.5f * vs) * n;
    float open = face_sky_open(l, IXYZ(sp), f) ? 1.0f : 0.0f;
    for (int i = 0; i < 16; ++i) {
      float c = max(0.0f, dot(n, XYZ(P.dirs[i])));
      if (c <= 0.0f) continue;
      vec4 far_src = cone_load((s * 16 + i) * 3 + 0);
      vec3 src = XYZ(far_src) + (open * far_src.w) * XYZ(P.sky[i]);
      vec4 far_d = cone_load((s * 16 + i) * 3 + 1);
      vec3 gd = XYZ(far_d);
      vec3 gb1 = XYZ(cone_load((s * 16 + i) * 3 + 2));
      if (split) {
        ConeResult nr = trace_cone_range(apex_f, i, l, 0.5f * vs, ts - 0.5f * vs * c);
        float w = c * sealed_gain(open, nr.transmittance * far_d.w);
        es += w * (nr.src + (open * nr.sky) * XYZ(P.sky[i]) + nr.transmittance * src);
        ed += w * (nr.d + nr.transmittance * gd);
        eb += w * (nr.b1 + nr.transmittance * gb1);
      } else {
        float w = c * sealed_gain(open, far_d.w);
        es += w * src;
        ed += w * gd;
        eb += w * gb1;
      }
    }
    vec3 rho = XYZ(albedo) / wsum;
    vec3 lights = point_light_irradiance(apex_f, n, 0.5f * vs, vis);
    light_store((s * 6 + f) * 3 + 0, vec4(emission + rho * es + (XYZ(albedo) / kPi) * lights, 0.0f));
    light_store((s * 6 + f) * 3 + 1, vec4(rho * ed, 0.0f));
    light_store((s * 6 + f) * 3 + 2, vec4(rho * eb, 0.0f));
  }
}

// The optional third bounce: where the second bounce is as strong as the
// first, extrapolate one more (B2 * B2 / B1, at most B2), scaled by boost.
vec3 third_bounce(vec3 b1, vec3 b2) {
  vec3 ratio = min(b2 / max(b1, vec3(1e-12f)), vec3(1.0f));
  return P.fparams.y * b2 * ratio;
}

// Kernel 4: irradiance at query points pc.first .. + pc.count (pc.level =
// bounces 1..3), each cone traced as query_rays narrow rays where the
// apex's air is open to the sky (trace_rays_lit): qin[2i] = position
// (relative to the lattice origin), qin[2i + 1] = unit normal; writes
// qout[i] = irradiance rgb, w = the level traced from (-1 outside every
// level: sky only).
void kernel_query(int gid) {
  if (gid >= pc.count) return;
  int q = pc.first + gid;
  vec3 p = XYZ(qin_load(2 * q));
  vec3 n = XYZ(qin_load(2 * q + 1));
  int l0 = 0;
  vec3 u = vec3(0.0f);
  while (l0 < gi_k() && !level_coords(l0, p, u)) ++l0;
  if (l0 == gi_k()) l0 = gi_k() - 1;
  float s = level_size(l0);
  vec3 apex = p + (P.fparams.z * s) * n;
  if (point_dark(l0, apex)) {
    qout_store(q, vec4(0.0f, 0.0f, 0.0f, float(l0)));
    return;
  }
  float open = point_sky_open(l0, apex) ? 1.0f : 0.0f;
  float wsum = cosine_sum(n);
  vec3 e = vec3(0.0f);
  int bounces = pc.level;
  // Rays where the sky can reach; in sealed air the cones, whose light the
  // sealed gain makes whole (the rays lost light at a thin-walled room's
  // corner, through walls one fine voxel thick).
  bool rays = query_rays() > 0 && open > 0.0f;
  for (int i = 0; i < 16; ++i) {
    float c = max(0.0f, dot(n, XYZ(P.dirs[i])));
    if (c <= 0.0f) continue;
    ConeResult cr = rays ? trace_rays_lit(apex, p, i, l0, 0.5f * s) : trace_cone_lit(apex, p, i, l0, 0.5f * s, 1e30f);
    vec3 l = cr.src + (open * cr.sky) * XYZ(P.sky[i]) + cr.d;
    if (bounces >= 2) l += cr.b1;
    if (bounces >= 3) l += cr.b2 + third_bounce(cr.b1, cr.b2);
    e += (c * sealed_gain(open, cr.transmittance)) * l;
  }
  vec3 lights = point_light_irradiance(p, n, 0.5f * s, light_visibility(apex, l0, 0.5f * s));
  qout_store(q, vec4(e * (kPi / wsum) + lights, float(l0)));
}
