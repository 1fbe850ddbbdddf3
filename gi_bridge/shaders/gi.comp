#version 450
// The GPU side of gi_bridge: bindings and entry points around gi_common.glsl.
// Compiled five times with -DGI_KERNEL=1..5 (alpha, precombine, update, query, cones).
layout(local_size_x = 64) in;

#define GI_CONST const
#define GI_INLINE
#define OUT(T) out T
#define INOUT(T) inout T
#define XYZ(v) (v).xyz
#define IXYZ(v) (v).xyz

layout(std140, binding = 0) uniform Params {
  vec4 dirs[16];
  vec4 sky[16];
  vec4 light_pos[8];
  vec4 light_int[8];
  vec4 fparams;   // x level 0 voxel size, y third bounce boost, z query offset (voxels), w unused
  ivec4 iparams;  // x N, y K, z flags, w exact point lights
  vec4 fparams2;  // x near/far split distance (voxels of the updated level), yzw unused
  ivec4 iparams2;  // x rays per cone of the queries (GiConfig::query_rays), yzw unused
  ivec4 lo[16];
  ivec4 surf[16];  // per level x first updated surface voxel, y their count
  vec4 rays[256];  // cone i's query rays at i * 16 + k (unit xyz)
} P;

layout(push_constant) uniform Push {
  int first;
  int count;
  int level;
  int pad;
} pc;

layout(std430, binding = 1) readonly buffer Occ { float v[]; } occ_buf;
layout(std430, binding = 2) buffer Alpha { float v[]; } alpha_buf;
layout(std430, binding = 3) readonly buffer VMap { int v[]; } vmap_buf;
layout(std430, binding = 4) readonly buffer SurfPos { ivec4 v[]; } surf_pos_buf;
layout(std430, binding = 5) readonly buffer Attr { vec4 v[]; } attr_buf;
layout(std430, binding = 6) readonly buffer LightPrev { vec4 v[]; } light_prev_buf;
layout(std430, binding = 7) writeonly buffer LightNext { vec4 v[]; } light_next_buf;
layout(std430, binding = 8) buffer Pre { vec4 v[]; } pre_buf;
layout(std430, binding = 9) readonly buffer QIn { vec4 v[]; } qin_buf;
layout(std430, binding = 10) writeonly buffer QOut { vec4 v[]; } qout_buf;
layout(std430, binding = 11) readonly buffer FSrc { int v[]; } fsrc_buf;
layout(std430, binding = 12) readonly buffer PLight { vec4 v[]; } plight_buf;
layout(std430, binding = 13) buffer Cones { vec4 v[]; } cone_buf;

float occ_load(int i) { return occ_buf.v[i]; }
float alpha_load(int i) { return alpha_buf.v[i]; }
void alpha_store(int i, float a) { alpha_buf.v[i] = a; }
int vmap_load(int i) { return vmap_buf.v[i]; }
ivec4 surf_pos_load(int i) { return surf_pos_buf.v[i]; }
vec4 attr_load(int i) { return attr_buf.v[i]; }
int fsrc_load(int i) { return fsrc_buf.v[i]; }
vec4 light_load(int i) { return light_prev_buf.v[i]; }
void light_store(int i, vec4 v) { light_next_buf.v[i] = v; }
vec4 pre_load(int i) { return pre_buf.v[i]; }
void pre_store(int i, vec4 v) { pre_buf.v[i] = v; }
vec4 qin_load(int i) { return qin_buf.v[i]; }
void qout_store(int i, vec4 v) { qout_buf.v[i] = v; }
vec4 plight_load(int i) { return plight_buf.v[i]; }
vec4 cone_load(int i) { return cone_buf.v[i]; }
void cone_store(int i, vec4 v) { cone_buf.v[i] = v; }

#include "gi_common.glsl"

void main() {
  int gid = int(gl_GlobalInvocationID.x);
#if GI_KERNEL == 1
  kernel_alpha(gid);
#elif GI_KERNEL == 2
  kernel_precombine(gid);
#elif GI_KERNEL == 3
  kernel_update(gid);
#elif GI_KERNEL == 4
  kernel_query(gid);
#else
  kernel_cones(gid);
#endif
}
