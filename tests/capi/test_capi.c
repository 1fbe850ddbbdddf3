/* The C API (capi/ldc.h) exercised from C: every call, its size queries, its
 * refusals, and the contract breaks it survives (dead handles, impossible
 * sizes, overlapping calls from two threads). Compiled as C11; run by ctest
 * (label capi) and under ASan + UBSan by scripts/sanitize.sh (and once by
 * hand under TSan). Usage: ldc_capi_test [scratch directory]. */
#define _POSIX_C_SOURCE 200809L /* nanosleep */

#include "capi/ldc.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int g_failures = 0;
static int g_checks = 0;
static const char* g_case = "";

#define CHECK(cond)                                                                     \
  do {                                                                                  \
    ++g_checks;                                                                         \
    if (!(cond)) {                                                                      \
      fprintf(stderr, "%s:%d: [%s] CHECK failed: %s (last error: %s)\n", __FILE__,     \
              __LINE__, g_case, #cond, ldc_last_error());                               \
      ++g_failures;                                                                     \
    }                                                                                   \
  } while (0)
#define CHECK_STATUS(call, expected) CHECK((call) == (expected))

static char g_dir[1024] = ".";

/* A small landscape: 16 x 16 m at h = 0.25 m (cheap under ASan). */
static ldc_world* small_landscape(void) {
  ldc_terrain_config t;
  ldc_terrain_config_default(&t);
  t.size_x = 16.0;
  t.size_y = 16.0;
  t.cell_size = 0.25;
  t.arches = 1;
  ldc_world* w = NULL;
  CHECK_STATUS(ldc_world_create_terrain(&t, &w), LDC_OK);
  return w;
}

/* The ground height under (x, y): a ray cast straight down from high above. */
static double ground_z(ldc_world* w, double x, double y) {
  ldc_ray r = {{x, y, 100.0}, {0.0, 0.0, -1.0}, INFINITY};
  ldc_ray_hit h;
  if (ldc_world_ray_cast(w, &r, 1, &h) != LDC_OK || !h.hit) return NAN;
  return h.point[2];
}

static void version_matches_the_header(void) {
  g_case = "version_matches_the_header";
  CHECK(strcmp(ldc_version_string(), LDC_VERSION_STRING) == 0);
  CHECK(ldc_version() == LDC_VERSION);
  CHECK(ldc_format_version() == LDC_FORMAT_VERSION);
  CHECK(strcmp(ldc_status_name(LDC_OK), "ok") == 0);
  CHECK(strcmp(ldc_status_name(LDC_BUFFER_TOO_SMALL), "buffer too small") == 0);
  CHECK(strcmp(ldc_status_name(LDC_INVALID_ARGUMENT), "invalid argument") == 0);
  CHECK(strcmp(ldc_status_name(LDC_INVALID_HANDLE), "invalid handle") == 0);
  CHECK(strcmp(ldc_status_name(LDC_BUSY), "busy") == 0);
  CHECK(strcmp(ldc_status_name((ldc_status)12345), "unknown status") == 0);
  CHECK(sizeof(ldc_status) == 4 && sizeof(ldc_brush_shape) == 4 && sizeof(ldc_edit_op) == 4);
}

static void null_handles_are_refused_by_name(void) {
  g_case = "null_handles_are_refused_by_name";
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(NULL, &info), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "world is NULL") != NULL);
  CHECK_STATUS(ldc_world_save(NULL, "x.ldc"), LDC_INVALID_ARGUMENT);
  CHECK_STATUS(ldc_world_destroy(NULL), LDC_OK);
  CHECK_STATUS(ldc_cascades_destroy(NULL), LDC_OK);
}

static void thread_cap_is_set_and_lifted(void) {
  g_case = "thread_cap_is_set_and_lifted";
  const int32_t uncapped = ldc_max_threads();
  CHECK(uncapped >= 1);
  CHECK_STATUS(ldc_set_max_threads(1), LDC_OK);
  CHECK(ldc_max_threads() == 1);
  CHECK_STATUS(ldc_set_max_threads(-2), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "-2") != NULL);
  CHECK(ldc_max_threads() == 1); /* a refused call changes nothing */
  CHECK_STATUS(ldc_set_max_threads(0), LDC_OK);
  CHECK(ldc_max_threads() == uncapped);
}

static void bad_world_config_is_refused(void) {
  g_case = "bad_world_config_is_refused";
  ldc_world_config c;
  ldc_world_config_default(&c);
  CHECK(c.chunk_size == 32 && c.cell_size == 0.2);
  c.chunk_size = 33;
  ldc_world* w = NULL;
  CHECK_STATUS(ldc_world_create(&c, &w), LDC_INVALID_ARGUMENT);
  CHECK(w == NULL);
  CHECK(strstr(ldc_last_error(), "33") != NULL);
  ldc_world_config_default(&c);
  c.chunk_dims[0] = 2;
  CHECK_STATUS(ldc_world_create(&c, &w), LDC_OK);
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(w, &info), LDC_OK);
  CHECK(info.chunks_empty == 2 && info.points == 0);
  ldc_world_destroy(w);
}

static void missing_file_is_named(void) {
  g_case = "missing_file_is_named";
  ldc_world* w = NULL;
  CHECK(ldc_world_load("no-such-world.ldc", &w) != LDC_OK);
  CHECK(w == NULL);
  CHECK(strstr(ldc_last_error(), "no-such-world.ldc") != NULL);
}

static void save_and_load_keep_the_world(ldc_world* w) {
  g_case = "save_and_load_keep_the_world";
  char path[1200];
  snprintf(path, sizeof path, "%s/capi_world.ldc", g_dir);
  CHECK_STATUS(ldc_world_save(w, path), LDC_OK);
  ldc_world* back = NULL;
  CHECK_STATUS(ldc_world_load(path, &back), LDC_OK);
  ldc_world_info a, b;
  CHECK_STATUS(ldc_world_get_info(w, &a), LDC_OK);
  CHECK_STATUS(ldc_world_get_info(back, &b), LDC_OK);
  CHECK(a.points == b.points && a.points > 0);
  CHECK(a.chunks_mixed == b.chunks_mixed && a.cell_size == b.cell_size);
  ldc_world_destroy(back);
  remove(path);
}

static void dig_build_and_paint_change_the_solid(ldc_world* w) {
  g_case = "dig_build_and_paint_change_the_solid";
  const double gz = ground_z(w, 8.0, 8.0);
  CHECK(!isnan(gz));
  const double below[3] = {8.0, 8.0, gz - 0.5};
  CHECK(ldc_world_inside(w, below) == 1);
  ldc_brush dig = {0};
  dig.shape = LDC_BRUSH_SPHERE;
  dig.centre[0] = 8.0, dig.centre[1] = 8.0, dig.centre[2] = gz;
  dig.radius = 1.5;
  ldc_edit_result r;
  CHECK_STATUS(ldc_world_edit(w, &dig, LDC_EDIT_SUBTRACT, &r), LDC_OK);
  CHECK(r.version == 1 && r.chunks_changed > 0);
  CHECK(ldc_world_inside(w, below) == 0);

  ldc_brush box = {0};
  box.shape = LDC_BRUSH_BOX;
  box.centre[0] = 4.0, box.centre[1] = 4.0, box.centre[2] = gz + 6.0;
  box.half_extents[0] = box.half_extents[1] = box.half_extents[2] = 0.6;
  box.material = 2;
  CHECK_STATUS(ldc_world_edit(w, &box, LDC_EDIT_BUILD, NULL), LDC_OK); /* the 0.2 spelling of LDC_EDIT_UNION */
  CHECK(ldc_world_inside(w, box.centre) == 1);

  ldc_brush paint = {0};
  paint.shape = LDC_BRUSH_CAPSULE;
  paint.a[0] = 2.0, paint.a[1] = 12.0, paint.a[2] = gz;
  paint.b[0] = 6.0, paint.b[1] = 12.0, paint.b[2] = gz;
  paint.radius = 8.0;
  paint.material = 3;
  CHECK_STATUS(ldc_world_edit(w, &paint, LDC_EDIT_PAINT, &r), LDC_OK);
  CHECK(r.version == 3);
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(w, &info), LDC_OK);
  CHECK(info.edit_version == 3);
}

static void bad_brush_leaves_the_world_unchanged(ldc_world* w) {
  g_case = "bad_brush_leaves_the_world_unchanged";
  ldc_world_info before, after;
  CHECK_STATUS(ldc_world_get_info(w, &before), LDC_OK);
  ldc_brush b = {0};
  b.shape = LDC_BRUSH_SPHERE;
  b.radius = -1.0;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_SUBTRACT, NULL), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "radius") != NULL);
  b.radius = 1.0;
  b.shape = (ldc_brush_shape)7;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_SUBTRACT, NULL), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "brush shape 7") != NULL);
  b.shape = LDC_BRUSH_SPHERE;
  CHECK_STATUS(ldc_world_edit(w, &b, (ldc_edit_op)9, NULL), LDC_INVALID_ARGUMENT);
  CHECK_STATUS(ldc_world_get_info(w, &after), LDC_OK);
  CHECK(after.edit_version == before.edit_version && after.points == before.points);
}

static void dirty_chunks_are_taken_once(ldc_world* w) {
  g_case = "dirty_chunks_are_taken_once";
  size_t n = 0;
  CHECK_STATUS(ldc_world_take_dirty(w, NULL, 0, &n), LDC_OK); /* size query keeps the list */
  CHECK(n > 0);
  ldc_dirty_chunk one;
  size_t m = 0;
  if (n > 1) {
    CHECK_STATUS(ldc_world_take_dirty(w, &one, 1, &m), LDC_BUFFER_TOO_SMALL);
    CHECK(m == n);
  }
  ldc_dirty_chunk* all = calloc(n, sizeof *all);
  CHECK_STATUS(ldc_world_take_dirty(w, all, n, &m), LDC_OK);
  CHECK(m == n);
  size_t data = 0;
  for (size_t i = 0; i < m; ++i) {
    CHECK((all[i].flags & LDC_DIRTY_MESH) != 0);
    if (all[i].flags & LDC_DIRTY_DATA) {
      ++data;
      CHECK(all[i].version >= 1 && all[i].version <= 3);
      CHECK(all[i].node_lo[0] < all[i].node_hi[0]);
    }
    if (i > 0) { /* sorted by (z, y, x) */
      const int32_t* a = all[i - 1].chunk;
      const int32_t* b = all[i].chunk;
      CHECK(a[2] < b[2] || (a[2] == b[2] && (a[1] < b[1] || (a[1] == b[1] && a[0] < b[0]))));
    }
  }
  CHECK(data > 0);
  free(all);
  CHECK_STATUS(ldc_world_take_dirty(w, NULL, 0, &n), LDC_OK);
  CHECK(n == 0);
}

/* Meshes every chunk of the box; returns the total triangle count. */
static size_t mesh_every_chunk(ldc_world* w) {
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(w, &info), LDC_OK);
  size_t triangles = 0;
  for (int z = 0; z < info.chunk_dims[2]; ++z)
    for (int y = 0; y < info.chunk_dims[1]; ++y)
      for (int x = 0; x < info.chunk_dims[0]; ++x) {
        const int32_t c[3] = {info.chunk_origin[0] + x, info.chunk_origin[1] + y, info.chunk_origin[2] + z};
        ldc_mesh_buffers b = {0};
        CHECK_STATUS(ldc_world_mesh_chunk(w, c, &b), LDC_OK);
        if (b.triangle_count == 0) continue;
        const size_t nv = b.vertex_count, nt = b.triangle_count;
        b.positions = malloc(nv * 3 * sizeof(float));
        b.normals = malloc(nv * 3 * sizeof(float));
        b.vertex_materials = malloc(nv * sizeof(uint16_t));
        b.indices = malloc(nt * 3 * sizeof(uint32_t));
        b.triangle_materials = NULL; /* not wanted */
        b.vertex_capacity = nv;
        b.triangle_capacity = nt - 1;
        CHECK_STATUS(ldc_world_mesh_chunk(w, c, &b), LDC_BUFFER_TOO_SMALL);
        b.triangle_capacity = nt;
        CHECK_STATUS(ldc_world_mesh_chunk(w, c, &b), LDC_OK);
        for (size_t i = 0; i < 3 * nt; ++i) CHECK(b.indices[i] < nv);
        for (size_t i = 0; i < nv; ++i) {
          const float* n = b.normals + 3 * i;
          CHECK(fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0f) < 1e-3f);
          CHECK(b.positions[3 * i + 2] > info.box_min[2] - 1.0 && b.positions[3 * i + 2] < info.box_max[2] + 1.0);
        }
        triangles += nt;
        free(b.positions), free(b.normals), free(b.vertex_materials), free(b.indices);
      }
  return triangles;
}

static void chunk_meshes_follow_the_edits(ldc_world* w) {
  g_case = "chunk_meshes_follow_the_edits";
  const size_t before = mesh_every_chunk(w);
  CHECK(before > 1000);
  ldc_brush b = {0};
  b.shape = LDC_BRUSH_SPHERE;
  b.centre[0] = 12.0, b.centre[1] = 4.0, b.centre[2] = ground_z(w, 12.0, 4.0) + 3.0;
  b.radius = 1.2;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_UNION, NULL), LDC_OK); /* a floating ball: more triangles */
  const size_t after = mesh_every_chunk(w);
  CHECK(after > before);
  const int32_t outside[3] = {1000, 0, 0};
  ldc_mesh_buffers e = {0};
  CHECK_STATUS(ldc_world_mesh_chunk(w, outside, &e), LDC_OK);
  CHECK(e.vertex_count == 0 && e.triangle_count == 0);
}

/* FNV-1a of one chunk's mesh (counts, positions, indices, materials). */
static uint64_t mesh_hash(ldc_world* w, const int32_t c[3]) {
  ldc_mesh_buffers b = {0};
  CHECK_STATUS(ldc_world_mesh_chunk(w, c, &b), LDC_OK);
  uint64_t h = 1469598103934665603ull ^ (uint64_t)b.vertex_count * 31u ^ (uint64_t)b.triangle_count;
  if (b.triangle_count == 0) return h;
  b.positions = malloc(b.vertex_count * 3 * sizeof(float));
  b.indices = malloc(b.triangle_count * 3 * sizeof(uint32_t));
  b.triangle_materials = malloc(b.triangle_count * sizeof(uint16_t));
  b.vertex_capacity = b.vertex_count, b.triangle_capacity = b.triangle_count;
  CHECK_STATUS(ldc_world_mesh_chunk(w, c, &b), LDC_OK);
  const unsigned char* parts[3] = {(const unsigned char*)b.positions, (const unsigned char*)b.indices,
                                   (const unsigned char*)b.triangle_materials};
  const size_t sizes[3] = {b.vertex_count * 3 * sizeof(float), b.triangle_count * 3 * sizeof(uint32_t),
                           b.triangle_count * sizeof(uint16_t)};
  for (int p = 0; p < 3; ++p)
    for (size_t i = 0; i < sizes[p]; ++i) h = (h ^ parts[p][i]) * 1099511628211ull;
  free(b.positions), free(b.indices), free(b.triangle_materials);
  return h;
}

/* Every chunk whose mesh an edit changes is in the dirty list with LDC_DIRTY_MESH. */
static void changed_meshes_are_flagged_dirty(ldc_world* w) {
  g_case = "changed_meshes_are_flagged_dirty";
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(w, &info), LDC_OK);
  const size_t chunks = (size_t)info.chunk_dims[0] * info.chunk_dims[1] * info.chunk_dims[2];
  uint64_t* before = calloc(chunks, sizeof *before);
  size_t n = 0;
  ldc_world_take_dirty(w, NULL, 0, &n);
  ldc_dirty_chunk* skip = calloc(n + 1, sizeof *skip);
  CHECK_STATUS(ldc_world_take_dirty(w, skip, n, &n), LDC_OK); /* start from a clean list */
  free(skip);
  for (size_t i = 0; i < chunks; ++i) {
    const int32_t c[3] = {info.chunk_origin[0] + (int32_t)(i % info.chunk_dims[0]),
                          info.chunk_origin[1] + (int32_t)(i / info.chunk_dims[0] % info.chunk_dims[1]),
                          info.chunk_origin[2] + (int32_t)(i / info.chunk_dims[0] / info.chunk_dims[1])};
    before[i] = mesh_hash(w, c);
  }
  /* A dig on a chunk corner (h = 0.25, C = 32: chunks are 8 m) touches up to eight chunks. */
  ldc_brush b = {0};
  b.shape = LDC_BRUSH_SPHERE;
  b.centre[0] = 8.0, b.centre[1] = 8.0, b.centre[2] = ground_z(w, 8.5, 8.5);
  b.radius = 1.0;
  b.material = 1;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_UNION, NULL), LDC_OK);
  ldc_world_take_dirty(w, NULL, 0, &n);
  ldc_dirty_chunk* dirty = calloc(n + 1, sizeof *dirty);
  CHECK_STATUS(ldc_world_take_dirty(w, dirty, n, &n), LDC_OK);
  size_t changed = 0;
  for (size_t i = 0; i < chunks; ++i) {
    const int32_t c[3] = {info.chunk_origin[0] + (int32_t)(i % info.chunk_dims[0]),
                          info.chunk_origin[1] + (int32_t)(i / info.chunk_dims[0] % info.chunk_dims[1]),
                          info.chunk_origin[2] + (int32_t)(i / info.chunk_dims[0] / info.chunk_dims[1])};
    if (mesh_hash(w, c) == before[i]) continue;
    ++changed;
    int flagged = 0;
    for (size_t k = 0; k < n; ++k) {
      flagged |= dirty[k].chunk[0] == c[0] && dirty[k].chunk[1] == c[1] && dirty[k].chunk[2] == c[2] &&
                 (dirty[k].flags & LDC_DIRTY_MESH);
    }
    CHECK(flagged);
  }
  CHECK(changed >= 2);
  free(before);
  free(dirty);
}

static void ray_casts_find_the_ground(ldc_world* w) {
  g_case = "ray_casts_find_the_ground";
  ldc_ray rays[3] = {
      {{3.0, 3.0, 50.0}, {0.0, 0.0, -1.0}, INFINITY},
      {{3.0, 3.0, 50.0}, {0.0, 0.0, 1.0}, INFINITY}, /* up: misses */
      {{3.0, 3.0, 50.0}, {0.0, 0.0, -2.0}, 1.0},     /* too short */
  };
  ldc_ray_hit hits[3];
  CHECK_STATUS(ldc_world_ray_cast(w, rays, 3, hits), LDC_OK);
  CHECK(hits[0].hit == 1 && hits[0].normal[2] > 0.0f && hits[0].point[2] < 20.0);
  CHECK(fabs(hits[0].distance - (50.0 - hits[0].point[2])) < 1e-9);
  CHECK(hits[1].hit == 0 && hits[2].hit == 0);
  rays[1].direction[2] = 0.0;
  CHECK_STATUS(ldc_world_ray_cast(w, rays, 3, hits), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "1") != NULL);
  CHECK_STATUS(ldc_world_ray_cast(w, NULL, 0, NULL), LDC_OK);
}

static void paths_cross_the_landscape(ldc_world* w) {
  g_case = "paths_cross_the_landscape";
  ldc_nav_config nav;
  ldc_nav_config_default(&nav);
  CHECK(nav.agent_height == 2.0 && nav.max_nodes == 2048);
  nav.agent_radius = 0.25;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_OK);
  const double from[3] = {3.0, 5.0, ground_z(w, 3.0, 5.0) + 0.3};
  const double to[3] = {13.0, 11.0, ground_z(w, 13.0, 11.0) + 0.3};
  ldc_path_info info;
  CHECK_STATUS(ldc_world_find_path(w, from, to, NULL, 0, &info), LDC_OK);
  CHECK(info.corner_count >= 2 && info.length > 0.0);
  double small[3];
  if (info.corner_count > 1) {
    CHECK_STATUS(ldc_world_find_path(w, from, to, small, 1, &info), LDC_BUFFER_TOO_SMALL);
  }
  double* corners = malloc(info.corner_count * 3 * sizeof(double));
  CHECK_STATUS(ldc_world_find_path(w, from, to, corners, info.corner_count, &info), LDC_OK);
  CHECK(fabs(corners[0] - from[0]) < 1.0 && fabs(corners[1] - from[1]) < 1.0);
  free(corners);
  const double sky[3] = {8.0, 8.0, 90.0};
  CHECK_STATUS(ldc_world_find_path(w, sky, to, NULL, 0, &info), LDC_NOT_FOUND);
  CHECK(nav.filters == (LDC_NAV_FILTER_LOW_HANGING | LDC_NAV_FILTER_LEDGES | LDC_NAV_FILTER_LOW_HEIGHT));
  nav.filters = 8u;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "filters") != NULL);
  nav.filters = LDC_NAV_FILTER_LEDGES;
  nav.max_slope_degrees = 95.0;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "max_slope") != NULL);
  /* The navigation data follows edits: a deep pit under the goal leaves no floor near it. */
  ldc_brush pit = {0};
  pit.shape = LDC_BRUSH_BOX;
  pit.centre[0] = to[0], pit.centre[1] = to[1], pit.centre[2] = to[2] - 3.0;
  pit.half_extents[0] = pit.half_extents[1] = 3.0;
  pit.half_extents[2] = 12.0;
  CHECK_STATUS(ldc_world_edit(w, &pit, LDC_EDIT_SUBTRACT, NULL), LDC_OK);
  ldc_path_info after;
  const ldc_status s = ldc_world_find_path(w, from, to, NULL, 0, &after);
  CHECK(s == LDC_NOT_FOUND || (s == LDC_OK && after.status != LDC_PATH_COMPLETE));
}

/* Two platforms 3 m apart (tops at z = 1, nothing below), platform A crossed by
 * a strip of material 1 from side to side. */
static ldc_world* two_platforms(void) {
  ldc_world_config c;
  ldc_world_config_default(&c);
  c.chunk_dims[0] = 4; /* 25.6 x 12.8 x 6.4 m at h = 0.2 */
  c.chunk_dims[1] = 2;
  ldc_world* w = NULL;
  CHECK_STATUS(ldc_world_create(&c, &w), LDC_OK);
  if (!w) return NULL;
  ldc_brush b = {0};
  b.shape = LDC_BRUSH_BOX;
  b.centre[1] = 4.0, b.centre[2] = 0.6;
  b.half_extents[0] = 3.9, b.half_extents[1] = 3.9, b.half_extents[2] = 0.4;
  b.centre[0] = 4.0;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_UNION, NULL), LDC_OK);
  b.centre[0] = 15.0;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_UNION, NULL), LDC_OK);
  ldc_brush strip = {0}; /* paints platform A's top between x = 3.5 and 4.5 */
  strip.shape = LDC_BRUSH_BOX;
  strip.centre[0] = 4.0, strip.centre[1] = 4.0, strip.centre[2] = 1.0;
  strip.half_extents[0] = 0.5, strip.half_extents[1] = 5.0, strip.half_extents[2] = 0.3;
  strip.material = 1;
  CHECK_STATUS(ldc_world_edit(w, &strip, LDC_EDIT_PAINT, NULL), LDC_OK);
  return w;
}

static ldc_path_status path_status(ldc_world* w, const double from[3], const double to[3]) {
  ldc_path_info info;
  const ldc_status s = ldc_world_find_path(w, from, to, NULL, 0, &info);
  CHECK(s == LDC_OK);
  return s == LDC_OK ? info.status : LDC_PATH_STATUS_MAX_ENUM;
}

static void nav_filters_and_links(void) {
  g_case = "nav_filters_and_links";
  ldc_world* w = two_platforms();
  if (!w) return;
  ldc_nav_config nav;
  ldc_nav_config_default(&nav);
  CHECK(nav.material_areas == NULL && nav.material_area_count == 0);
  const uint8_t areas[2] = {0, 1}; /* material 1 in area 1 */
  nav.material_areas = areas;
  nav.material_area_count = 2;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_OK);
  const double west[3] = {1.5, 4.0, 1.0}, east[3] = {6.5, 4.0, 1.0}, far[3] = {17.0, 4.0, 1.0};
  CHECK(path_status(w, west, east) == LDC_PATH_COMPLETE);

  /* A filter that excludes area 1: the strip cuts platform A in two. */
  ldc_nav_filter filter;
  ldc_nav_filter_default(&filter);
  CHECK(filter.include_flags == 0xFFFF && filter.exclude_flags == 0 && filter.area_cost_count == 0);
  const uint16_t flags[2] = {1, 2};
  filter.area_flags = flags;
  filter.area_flag_count = 2;
  filter.exclude_flags = 2;
  CHECK_STATUS(ldc_world_set_nav_filter(w, &filter), LDC_OK);
  CHECK(path_status(w, west, east) != LDC_PATH_COMPLETE);
  CHECK_STATUS(ldc_world_set_nav_filter(w, NULL), LDC_OK); /* back to the default */
  CHECK(path_status(w, west, east) == LDC_PATH_COMPLETE);
  /* Bad filters are refused by field, and change nothing. */
  const double costs[2] = {1.0, 0.0};
  filter.area_costs = costs;
  filter.area_cost_count = 2;
  CHECK_STATUS(ldc_world_set_nav_filter(w, &filter), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "area_costs[1]") != NULL);
  filter.area_cost_count = 65;
  CHECK_STATUS(ldc_world_set_nav_filter(w, &filter), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "area_cost_count") != NULL);
  filter.area_cost_count = 2;
  filter.area_costs = NULL;
  CHECK_STATUS(ldc_world_set_nav_filter(w, &filter), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "area_costs is NULL") != NULL);
  CHECK_STATUS(ldc_world_set_nav_filter(NULL, NULL), LDC_INVALID_ARGUMENT);
  CHECK(path_status(w, west, east) == LDC_PATH_COMPLETE);

  /* A link joins the platforms; removing it splits them again. */
  CHECK(path_status(w, west, far) == LDC_PATH_UNREACHABLE);
  ldc_nav_link link;
  ldc_nav_link_default(&link);
  CHECK(link.bidirectional == 1 && link.cost < 0.0 && link.flags == 1 && link.radius == 1.0);
  link.a[0] = 7.0, link.a[1] = 4.0, link.a[2] = 1.0;
  link.b[0] = 12.0, link.b[1] = 4.0, link.b[2] = 1.0;
  uint32_t id = 99;
  CHECK_STATUS(ldc_world_add_nav_link(w, &link, &id), LDC_OK);
  ldc_path_info info;
  CHECK_STATUS(ldc_world_find_path(w, west, far, NULL, 0, &info), LDC_OK);
  CHECK(info.status == LDC_PATH_COMPLETE && info.length > 15.0 && info.length < 16.5);
  int32_t attached = -1;
  CHECK_STATUS(ldc_world_nav_link_attached(w, id, &attached), LDC_OK);
  CHECK(attached == 1);
  /* Links outlive a rebuild of the navigation data (a new config). */
  nav.agent_radius = 0.4;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_OK);
  CHECK(path_status(w, west, far) == LDC_PATH_COMPLETE);
  /* A link off every floor is kept but unused. */
  ldc_nav_link stray = link;
  stray.b[2] = 6.0;
  stray.radius = 0.5;
  uint32_t stray_id = 0;
  CHECK_STATUS(ldc_world_add_nav_link(w, &stray, &stray_id), LDC_OK);
  CHECK(stray_id != id);
  CHECK_STATUS(ldc_world_nav_link_attached(w, stray_id, &attached), LDC_OK);
  CHECK(attached == 0);
  CHECK_STATUS(ldc_world_remove_nav_link(w, id), LDC_OK);
  CHECK(path_status(w, west, far) == LDC_PATH_UNREACHABLE);
  CHECK_STATUS(ldc_world_remove_nav_link(w, id), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "id") != NULL);
  CHECK_STATUS(ldc_world_nav_link_attached(w, id, &attached), LDC_INVALID_ARGUMENT);
  /* Bad links are refused by field. */
  link.radius = 0.0;
  CHECK_STATUS(ldc_world_add_nav_link(w, &link, &id), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "link->radius") != NULL);
  link.radius = 1.0;
  link.a[1] = NAN;
  CHECK_STATUS(ldc_world_add_nav_link(w, &link, &id), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "link->a") != NULL);
  link.a[1] = 4.0;
  link.bidirectional = 2;
  CHECK_STATUS(ldc_world_add_nav_link(w, &link, &id), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "bidirectional") != NULL);
  CHECK_STATUS(ldc_world_add_nav_link(w, NULL, &id), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "link is NULL") != NULL);
  CHECK(path_status(w, west, far) == LDC_PATH_UNREACHABLE); /* none of them was added */
  /* Material areas are checked like the rest of the config. */
  const uint8_t bad_areas[2] = {0, 64};
  nav.material_areas = bad_areas;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "material_areas[1]") != NULL);
  nav.material_areas = NULL;
  CHECK_STATUS(ldc_world_set_nav_config(w, &nav), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "material_areas is NULL") != NULL);
  ldc_world_destroy(w);
}

static void cascades_voxelize_a_level(ldc_world* w) {
  g_case = "cascades_voxelize_a_level";
  ldc_cascade_config c;
  ldc_cascade_config_default(&c);
  c.levels = 2;
  c.resolution = 16;
  c.voxel_size = 0.5;
  ldc_cascades* cas = NULL;
  CHECK_STATUS(ldc_cascades_create(w, &c, &cas), LDC_OK);
  const double camera[3] = {8.0, 8.0, ground_z(w, 8.0, 8.0)};
  ldc_cascade_update u;
  CHECK_STATUS(ldc_cascades_update_level(cas, 0, camera, &u), LDC_OK);
  CHECK(u.level == 0 && u.full == 1 && u.voxels == 16 * 16 * 16 && u.box_dims[0] == 16);
  CHECK_STATUS(ldc_cascades_update_level(cas, 2, camera, &u), LDC_INVALID_ARGUMENT);
  ldc_gbuffer_buffers g = {0};
  CHECK_STATUS(ldc_cascades_read_level(cas, 0, &g), LDC_OK);
  CHECK(g.texel_count == 6 * 16 * 16 * 16);
  g.occupancy = malloc(g.texel_count);
  g.albedo = malloc(g.texel_count * sizeof(uint32_t));
  g.texel_capacity = g.texel_count;
  CHECK_STATUS(ldc_cascades_read_level(cas, 0, &g), LDC_OK);
  size_t solid = 0, seen = 0;
  for (size_t i = 0; i < g.texel_count; ++i) {
    solid += g.occupancy[i] > 0;
    seen += (g.albedo[i] >> 24) > 0;
  }
  CHECK(solid > 0 && solid < g.texel_count && seen > 0);
  /* An edit under the camera is picked up by the next update. */
  ldc_brush b = {0};
  b.shape = LDC_BRUSH_SPHERE;
  b.centre[0] = camera[0], b.centre[1] = camera[1], b.centre[2] = camera[2];
  b.radius = 2.0;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_SUBTRACT, NULL), LDC_OK);
  CHECK_STATUS(ldc_cascades_update_level(cas, 0, camera, &u), LDC_OK);
  CHECK(u.full == 0 && u.voxels > 0);
  free(g.occupancy);
  free(g.albedo);
  ldc_cascades_destroy(cas);
}

static void cascades_outliving_their_world_refuse_updates(void) {
  g_case = "cascades_outliving_their_world_refuse_updates";
  ldc_world_config wc;
  ldc_world_config_default(&wc);
  ldc_world* w = NULL;
  CHECK_STATUS(ldc_world_create(&wc, &w), LDC_OK);
  ldc_cascade_config c;
  ldc_cascade_config_default(&c);
  c.levels = 1;
  c.resolution = 8;
  ldc_cascades* cas = NULL;
  CHECK_STATUS(ldc_cascades_create(w, &c, &cas), LDC_OK);
  ldc_world_destroy(w);
  const double camera[3] = {0, 0, 0};
  CHECK_STATUS(ldc_cascades_update_level(cas, 0, camera, NULL), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "destroyed") != NULL);
  ldc_gbuffer_buffers b; /* what was voxelized can still be read */
  memset(&b, 0, sizeof b);
  CHECK_STATUS(ldc_cascades_read_level(cas, 0, &b), LDC_OK);
  CHECK(b.texel_count == 6u * 8u * 8u * 8u);
  ldc_cascades_destroy(cas);
}

/* ------------------------------------------------------------------------ */
/* Contract breaks (issue 24): each gives a status, never a crash.          */

/* One chunk (6.4 m at h = 0.2) with a slab of ground: edits take milliseconds. */
static ldc_world* small_slab(void) {
  ldc_world_config c;
  ldc_world_config_default(&c);
  ldc_world* w = NULL;
  CHECK_STATUS(ldc_world_create(&c, &w), LDC_OK);
  if (!w) return NULL;
  ldc_brush slab = {0};
  slab.shape = LDC_BRUSH_BOX;
  slab.centre[0] = 3.2, slab.centre[1] = 3.2, slab.centre[2] = 1.0;
  slab.half_extents[0] = slab.half_extents[1] = 2.5, slab.half_extents[2] = 0.7;
  CHECK_STATUS(ldc_world_edit(w, &slab, LDC_EDIT_UNION, NULL), LDC_OK);
  return w;
}

/* One level of 8^3 voxels over `w`, checked. */
static ldc_cascades* small_cascades(ldc_world* w) {
  ldc_cascade_config cc;
  ldc_cascade_config_default(&cc);
  cc.levels = 1;
  cc.resolution = 8;
  ldc_cascades* cas = NULL;
  CHECK_STATUS(ldc_cascades_create(w, &cc, &cas), LDC_OK);
  return cas;
}

static int names_a_dead_handle(void) { return strstr(ldc_last_error(), "not a live") != NULL; }

static void destroying_a_world_twice_is_refused(void) {
  g_case = "destroying_a_world_twice_is_refused";
  ldc_world* w = small_slab();
  if (!w) return;
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
  CHECK_STATUS(ldc_world_destroy(w), LDC_INVALID_HANDLE);
  CHECK(strstr(ldc_last_error(), "ldc_world_destroy") != NULL && names_a_dead_handle());
}

static void a_destroyed_world_is_refused_by_every_call(void) {
  g_case = "a_destroyed_world_is_refused_by_every_call";
  ldc_world* w = small_slab();
  if (!w) return;
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(w, &info), LDC_INVALID_HANDLE);
  CHECK(strstr(ldc_last_error(), "ldc_world_get_info: world is not a live world handle") != NULL);
  ldc_brush b = {0};
  b.shape = LDC_BRUSH_SPHERE;
  b.radius = 1.0;
  CHECK_STATUS(ldc_world_edit(w, &b, LDC_EDIT_SUBTRACT, NULL), LDC_INVALID_HANDLE);
  ldc_ray r = {{1.0, 1.0, 5.0}, {0.0, 0.0, -1.0}, INFINITY};
  ldc_ray_hit h;
  CHECK_STATUS(ldc_world_ray_cast(w, &r, 1, &h), LDC_INVALID_HANDLE);
  const int32_t chunk[3] = {0, 0, 0};
  ldc_mesh_buffers m = {0};
  CHECK_STATUS(ldc_world_mesh_chunk(w, chunk, &m), LDC_INVALID_HANDLE);
  size_t n = 0;
  CHECK_STATUS(ldc_world_take_dirty(w, NULL, 0, &n), LDC_INVALID_HANDLE);
  CHECK_STATUS(ldc_world_save(w, "never-written.ldc"), LDC_INVALID_HANDLE);
  const double p[3] = {3.2, 3.2, 1.0};
  CHECK(ldc_world_inside(w, p) == 0);
  CHECK(strstr(ldc_last_error(), "ldc_world_inside") != NULL && names_a_dead_handle());
  ldc_cascade_config cc;
  ldc_cascade_config_default(&cc);
  ldc_cascades* cas = NULL;
  CHECK_STATUS(ldc_cascades_create(w, &cc, &cas), LDC_INVALID_HANDLE);
  CHECK(cas == NULL);
}

/* A slot freed by a destroy may hold the next world: the old handle still names nothing. */
static void a_stale_handle_never_names_a_newer_world(void) {
  g_case = "a_stale_handle_never_names_a_newer_world";
  ldc_world_config c;
  ldc_world_config_default(&c);
  ldc_world* old = NULL;
  CHECK_STATUS(ldc_world_create(&c, &old), LDC_OK);
  CHECK_STATUS(ldc_world_destroy(old), LDC_OK);
  ldc_world* fresh[4] = {NULL, NULL, NULL, NULL};
  for (int i = 0; i < 4; ++i) {
    CHECK_STATUS(ldc_world_create(&c, &fresh[i]), LDC_OK);
    CHECK(fresh[i] != old);
  }
  ldc_world_info info;
  CHECK_STATUS(ldc_world_get_info(old, &info), LDC_INVALID_HANDLE);
  for (int i = 0; i < 4; ++i) {
    CHECK_STATUS(ldc_world_get_info(fresh[i], &info), LDC_OK);
    CHECK_STATUS(ldc_world_destroy(fresh[i]), LDC_OK);
  }
}

/* Values the library never returned, and a cascades handle passed as a world. */
static void forged_and_wrong_type_handles_are_refused(void) {
  g_case = "forged_and_wrong_type_handles_are_refused";
  ldc_world* w = small_slab();
  if (!w) return;
  ldc_cascades* cas = small_cascades(w);
  ldc_world_info info;
  int on_the_stack = 0;
  ldc_world* forged[4] = {(ldc_world*)cas, (ldc_world*)(uintptr_t)0x1234, (ldc_world*)&on_the_stack,
                          (ldc_world*)(uintptr_t)(~(uintptr_t)0)};
  for (int i = 0; i < 4; ++i) {
    CHECK_STATUS(ldc_world_get_info(forged[i], &info), LDC_INVALID_HANDLE);
    CHECK_STATUS(ldc_world_destroy(forged[i]), LDC_INVALID_HANDLE);
  }
  const double camera[3] = {3.2, 3.2, 1.0};
  CHECK_STATUS(ldc_cascades_update_level((ldc_cascades*)w, 0, camera, NULL), LDC_INVALID_HANDLE);
  CHECK(strstr(ldc_last_error(), "not a live cascades handle") != NULL);
  CHECK_STATUS(ldc_world_get_info(w, &info), LDC_OK); /* the real ones still work */
  CHECK_STATUS(ldc_cascades_update_level(cas, 0, camera, NULL), LDC_OK);
  CHECK_STATUS(ldc_cascades_destroy(cas), LDC_OK);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
}

static void destroying_cascades_twice_is_refused(void) {
  g_case = "destroying_cascades_twice_is_refused";
  ldc_world* w = small_slab();
  if (!w) return;
  ldc_cascades* cas = small_cascades(w);
  CHECK_STATUS(ldc_cascades_destroy(cas), LDC_OK);
  CHECK_STATUS(ldc_cascades_destroy(cas), LDC_INVALID_HANDLE);
  ldc_gbuffer_buffers g = {0};
  CHECK_STATUS(ldc_cascades_read_level(cas, 0, &g), LDC_INVALID_HANDLE);
  /* Cascades outliving their world: destroyed once, then refused. */
  cas = small_cascades(w);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
  CHECK_STATUS(ldc_cascades_read_level(cas, 0, &g), LDC_OK);
  CHECK_STATUS(ldc_cascades_destroy(cas), LDC_OK);
  CHECK_STATUS(ldc_cascades_destroy(cas), LDC_INVALID_HANDLE);
}

/* ray_cast with count SIZE_MAX gave LDC_INTERNAL (std::length_error); no rays are read. */
static void a_ray_count_no_array_can_hold_is_too_large(void) {
  g_case = "a_ray_count_no_array_can_hold_is_too_large";
  ldc_world* w = small_slab();
  if (!w) return;
  ldc_ray r = {{1.0, 1.0, 5.0}, {0.0, 0.0, -1.0}, INFINITY};
  ldc_ray_hit h;
  CHECK_STATUS(ldc_world_ray_cast(w, &r, SIZE_MAX, &h), LDC_TOO_LARGE);
  CHECK(strstr(ldc_last_error(), "count") != NULL);
  CHECK_STATUS(ldc_world_ray_cast(w, &r, SIZE_MAX / sizeof(ldc_ray) + 1, &h), LDC_TOO_LARGE);
  CHECK_STATUS(ldc_world_ray_cast(w, &r, 1, &h), LDC_OK);
  CHECK(h.hit == 1);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
}

/* NULL with a non-zero capacity was taken as a size query. */
static void a_null_buffer_with_a_capacity_is_refused(void) {
  g_case = "a_null_buffer_with_a_capacity_is_refused";
  ldc_world* w = small_slab();
  if (!w) return;
  size_t n = 0;
  CHECK_STATUS(ldc_world_take_dirty(w, NULL, 5, &n), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "out is NULL with capacity 5") != NULL);
  CHECK_STATUS(ldc_world_take_dirty(w, NULL, 0, &n), LDC_OK);
  CHECK(n > 0); /* the refused call kept the list */
  const int32_t chunk[3] = {0, 0, 0};
  ldc_mesh_buffers m = {0};
  m.vertex_capacity = 10;
  CHECK_STATUS(ldc_world_mesh_chunk(w, chunk, &m), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "NULL with capacities 10 and 0") != NULL);
  const double from[3] = {1.0, 1.0, 2.0}, to[3] = {5.0, 5.0, 2.0};
  ldc_path_info info;
  CHECK_STATUS(ldc_world_find_path(w, from, to, NULL, 4, &info), LDC_INVALID_ARGUMENT);
  CHECK(strstr(ldc_last_error(), "corners is NULL with capacity 4") != NULL);
  ldc_cascades* cas = small_cascades(w);
  ldc_gbuffer_buffers g = {0};
  g.texel_capacity = 7;
  CHECK_STATUS(ldc_cascades_read_level(cas, 0, &g), LDC_INVALID_ARGUMENT);
  CHECK_STATUS(ldc_cascades_destroy(cas), LDC_OK);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
}

/* A capacity larger than any array is a lie the library can see: refused before any write. */
static void a_capacity_no_array_can_have_is_too_large(void) {
  g_case = "a_capacity_no_array_can_have_is_too_large";
  ldc_world* w = small_slab();
  if (!w) return;
  ldc_dirty_chunk one;
  size_t n = 0;
  CHECK_STATUS(ldc_world_take_dirty(w, &one, SIZE_MAX, &n), LDC_TOO_LARGE);
  CHECK_STATUS(ldc_world_take_dirty(w, NULL, 0, &n), LDC_OK);
  CHECK(n > 0); /* nothing was taken */
  const int32_t chunk[3] = {0, 0, 0};
  float positions[3];
  uint32_t indices[3];
  ldc_mesh_buffers m = {0};
  m.positions = positions, m.indices = indices;
  m.vertex_capacity = SIZE_MAX / 4, m.triangle_capacity = 1;
  CHECK_STATUS(ldc_world_mesh_chunk(w, chunk, &m), LDC_TOO_LARGE);
  CHECK(strstr(ldc_last_error(), "vertex_capacity") != NULL);
  m.vertex_capacity = 1, m.triangle_capacity = SIZE_MAX;
  CHECK_STATUS(ldc_world_mesh_chunk(w, chunk, &m), LDC_TOO_LARGE);
  double corners[3];
  const double from[3] = {1.0, 1.0, 2.0}, to[3] = {5.0, 5.0, 2.0};
  ldc_path_info info;
  CHECK_STATUS(ldc_world_find_path(w, from, to, corners, SIZE_MAX / 8, &info), LDC_TOO_LARGE);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
}

/* Two threads on one world. Every call must return LDC_OK or LDC_BUSY. */
enum { kWriterEdits = 40 };
typedef struct shared_world {
  ldc_world* world;
  atomic_int writer_done;
  atomic_int busy_seen;      /* by either thread */
  atomic_int writer_waiting; /* the writer's last try was refused: the reader lets it in */
  int edits_ok;              /* the writer's, read after join */
  int other_status;          /* the first status neither LDC_OK nor LDC_BUSY (0: none) */
  char other_error[256];     /* its message */
  ldc_brush edits[kWriterEdits];
  ldc_edit_op ops[kWriterEdits];
} shared_world;

/* The writer's i-th edit: small digs and builds walking over the slab. */
static void nth_edit(int i, ldc_brush* b, ldc_edit_op* op) {
  memset(b, 0, sizeof *b);
  b->shape = LDC_BRUSH_SPHERE;
  b->centre[0] = 1.0 + 0.37 * (i % 12);
  b->centre[1] = 1.0 + 0.41 * (i % 11);
  b->centre[2] = 1.6;
  b->radius = 0.45;
  b->material = (uint16_t)(i % 3);
  *op = i % 2 ? LDC_EDIT_UNION : LDC_EDIT_SUBTRACT;
}

static void pause_a_little(void) {
  const struct timespec t = {0, 20000}; /* 20 us */
  nanosleep(&t, NULL);
}

static double seconds_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* kWriterEdits edits, each tried again after a pause while the reader holds
 * the world (for at most 60 s in all: a starved writer fails the test, it
 * does not hang). */
static void* edit_through_the_queries(void* arg) {
  shared_world* s = arg;
  const double give_up = seconds_now() + 60.0;
  for (int i = 0; i < kWriterEdits && seconds_now() < give_up; ++i) {
    ldc_brush b;
    ldc_edit_op op;
    nth_edit(i, &b, &op);
    ldc_status st;
    while ((st = ldc_world_edit(s->world, &b, op, NULL)) == LDC_BUSY && seconds_now() < give_up) {
      atomic_fetch_add(&s->busy_seen, 1);
      atomic_store(&s->writer_waiting, 1);
      pause_a_little();
    }
    atomic_store(&s->writer_waiting, 0);
    if (st == LDC_OK) {
      s->edits[s->edits_ok] = b;
      s->ops[s->edits_ok++] = op;
    } else if (s->other_status == 0) {
      s->other_status = (int)st;
      snprintf(s->other_error, sizeof s->other_error, "%s", ldc_last_error());
    }
  }
  atomic_store(&s->writer_done, 1);
  return NULL;
}

typedef struct query_thread {
  shared_world* shared;
  int other_status;
  long calls;
} query_thread;

static void* query_until_done(void* arg) {
  query_thread* q = arg;
  shared_world* s = q->shared;
  const int32_t chunk[3] = {0, 0, 0};
  const double p[3] = {3.2, 3.2, 1.0};
  while (!atomic_load(&s->writer_done)) {
    ldc_world_info info;
    ldc_ray r = {{3.2, 3.2, 6.0}, {0.0, 0.0, -1.0}, INFINITY};
    ldc_ray_hit h;
    ldc_mesh_buffers m = {0};
    const ldc_status statuses[3] = {ldc_world_get_info(s->world, &info), ldc_world_ray_cast(s->world, &r, 1, &h),
                                    ldc_world_mesh_chunk(s->world, chunk, &m)};
    (void)ldc_world_inside(s->world, p);
    for (int i = 0; i < 3; ++i) {
      if (statuses[i] == LDC_BUSY) {
        atomic_fetch_add(&s->busy_seen, 1);
      } else if (statuses[i] != LDC_OK && q->other_status == 0) {
        q->other_status = (int)statuses[i];
      }
    }
    q->calls += 3;
    /* As a game's frame does other work; and a refused writer goes first (else
     * it may starve: LDC_BUSY never queues a call). */
    do {
      pause_a_little();
    } while (atomic_load(&s->writer_waiting) && !atomic_load(&s->writer_done));
  }
  return NULL;
}

/* An edit on one thread while another queries the same world crashed (SEGV in
 * splice_patch). Now the loser of each overlap gets LDC_BUSY, and the world
 * ends as the successful edits alone would have made it. */
static void an_edit_overlapping_queries_is_busy_not_a_crash(void) {
  g_case = "an_edit_overlapping_queries_is_busy_not_a_crash";
  shared_world s;
  memset(&s, 0, sizeof s);
  s.world = small_slab();
  if (!s.world) return;
  atomic_init(&s.writer_done, 0);
  atomic_init(&s.busy_seen, 0);
  atomic_init(&s.writer_waiting, 0);
  query_thread q = {&s, 0, 0};
  pthread_t writer, reader;
  CHECK(pthread_create(&reader, NULL, query_until_done, &q) == 0);
  CHECK(pthread_create(&writer, NULL, edit_through_the_queries, &s) == 0);
  pthread_join(writer, NULL);
  pthread_join(reader, NULL);
  CHECK(s.other_status == 0 && q.other_status == 0);
  if (s.other_status) fprintf(stderr, "  the writer's status %d: %s\n", s.other_status, s.other_error);
  CHECK(atomic_load(&s.busy_seen) > 0);
  CHECK(s.edits_ok == kWriterEdits && q.calls > 0);
  /* The world is whole: it saves and loads (every chunk verified), and equals a replay. */
  char path[1200];
  snprintf(path, sizeof path, "%s/capi_threads.ldc", g_dir);
  CHECK_STATUS(ldc_world_save(s.world, path), LDC_OK);
  ldc_world* back = NULL;
  CHECK_STATUS(ldc_world_load(path, &back), LDC_OK);
  remove(path);
  ldc_world* replay = small_slab();
  for (int i = 0; replay && i < s.edits_ok; ++i) {
    CHECK_STATUS(ldc_world_edit(replay, &s.edits[i], s.ops[i], NULL), LDC_OK);
  }
  ldc_world_info a, b, c;
  CHECK_STATUS(ldc_world_get_info(s.world, &a), LDC_OK);
  CHECK_STATUS(ldc_world_get_info(back, &b), LDC_OK);
  CHECK_STATUS(ldc_world_get_info(replay, &c), LDC_OK);
  CHECK(a.edit_version == (uint64_t)s.edits_ok + 1);
  CHECK(a.points == b.points && a.points == c.points && a.chunks_mixed == c.chunks_mixed);
  CHECK_STATUS(ldc_world_destroy(back), LDC_OK);
  CHECK_STATUS(ldc_world_destroy(replay), LDC_OK);
  CHECK_STATUS(ldc_world_destroy(s.world), LDC_OK);
}

typedef struct reader_thread {
  ldc_world* world;
  int not_ok;
} reader_thread;

static void* read_info_many_times(void* arg) {
  reader_thread* r = arg;
  const double p[3] = {3.2, 3.2, 1.0};
  for (int i = 0; i < 2000; ++i) {
    ldc_world_info info;
    r->not_ok += ldc_world_get_info(r->world, &info) != LDC_OK;
    r->not_ok += ldc_world_inside(r->world, p) != 1;
  }
  return NULL;
}

/* Reading calls share a world: never LDC_BUSY between them. */
static void reading_calls_share_a_world(void) {
  g_case = "reading_calls_share_a_world";
  ldc_world* w = small_slab();
  if (!w) return;
  reader_thread r[2] = {{w, 0}, {w, 0}};
  pthread_t t[2];
  for (int i = 0; i < 2; ++i) CHECK(pthread_create(&t[i], NULL, read_info_many_times, &r[i]) == 0);
  for (int i = 0; i < 2; ++i) pthread_join(t[i], NULL);
  CHECK(r[0].not_ok == 0 && r[1].not_ok == 0);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
}

typedef struct user_thread {
  ldc_world* world;
  int other_status; /* the first status not LDC_OK or LDC_BUSY before the refusal */
  long calls;
} user_thread;

/* Reads the world until its handle is refused. */
static void* use_until_refused(void* arg) {
  user_thread* u = arg;
  for (;;) {
    ldc_world_info info;
    const ldc_status st = ldc_world_get_info(u->world, &info);
    ++u->calls;
    if (st == LDC_INVALID_HANDLE) break;
    if (st != LDC_OK && st != LDC_BUSY && u->other_status == 0) u->other_status = (int)st;
  }
  return NULL;
}

/* Destroying a world another thread is using: LDC_BUSY while a call is in
 * flight, then done; the other thread's next call gets LDC_INVALID_HANDLE. */
static void destroying_a_world_in_use_is_busy_then_final(void) {
  g_case = "destroying_a_world_in_use_is_busy_then_final";
  ldc_world* w = small_slab();
  if (!w) return;
  user_thread u = {w, 0, 0};
  pthread_t t;
  CHECK(pthread_create(&t, NULL, use_until_refused, &u) == 0);
  ldc_status st;
  while ((st = ldc_world_destroy(w)) == LDC_BUSY) {
  }
  CHECK_STATUS(st, LDC_OK);
  pthread_join(t, NULL);
  CHECK(u.other_status == 0 && u.calls > 0);
  CHECK_STATUS(ldc_world_destroy(w), LDC_INVALID_HANDLE);
}

int main(int argc, char** argv) {
  if (argc > 1) snprintf(g_dir, sizeof g_dir, "%s", argv[1]);
  version_matches_the_header();
  null_handles_are_refused_by_name();
  bad_world_config_is_refused();
  thread_cap_is_set_and_lifted();
  /* ThreadSanitizer cannot see TBB's own synchronisation (libtbb is not
   * instrumented): a TSan run sets LDC_CAPI_TEST_MAX_THREADS=1. */
  const char* cap = getenv("LDC_CAPI_TEST_MAX_THREADS");
  if (cap && ldc_set_max_threads(atoi(cap)) != LDC_OK) return 1;
  missing_file_is_named();
  ldc_world* w = small_landscape();
  if (!w) return 1;
  save_and_load_keep_the_world(w);
  dig_build_and_paint_change_the_solid(w);
  bad_brush_leaves_the_world_unchanged(w);
  dirty_chunks_are_taken_once(w);
  chunk_meshes_follow_the_edits(w);
  changed_meshes_are_flagged_dirty(w);
  ray_casts_find_the_ground(w);
  paths_cross_the_landscape(w);
  nav_filters_and_links();
  cascades_voxelize_a_level(w);
  CHECK_STATUS(ldc_world_destroy(w), LDC_OK);
  cascades_outliving_their_world_refuse_updates();
  destroying_a_world_twice_is_refused();
  a_destroyed_world_is_refused_by_every_call();
  a_stale_handle_never_names_a_newer_world();
  forged_and_wrong_type_handles_are_refused();
  destroying_cascades_twice_is_refused();
  a_ray_count_no_array_can_hold_is_too_large();
  a_null_buffer_with_a_capacity_is_refused();
  a_capacity_no_array_can_have_is_too_large();
  an_edit_overlapping_queries_is_busy_not_a_crash();
  reading_calls_share_a_world();
  destroying_a_world_in_use_is_busy_then_final();
  if (g_failures) {
    fprintf(stderr, "test_capi: %d checks failed\n", g_failures);
    return 1;
  }
  printf("test_capi: all %d checks passed (ldc %s, C API %d)\n", g_checks, ldc_version_string(), LDC_C_API_VERSION);
  return 0;
}
