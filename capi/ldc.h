/* ldc.h: the C API of ldc, for engines and language bindings (C#, Rust,
 * Unity native plugins, Godot extensions) that need a plain C ABI.
 *
 * Link target: ldc::c (libldc_c.so, a shared library: FFI loaders need one;
 * the static ldc modules are linked in and only the ldc_* functions below
 * are exported; it depends on libstdc++ and libtbb like any C++ library).
 *
 * Conventions
 *  - Units: metres for positions, lengths and radii; world coordinates are
 *    the lattice's (z up for the default landscape). Chunk and node
 *    coordinates are integers on the world's lattice (see ldc/world.h).
 *  - Every fallible call returns an ldc_status; LDC_OK (0) is success. On
 *    failure, ldc_last_error() gives a message naming the bad value, file or
 *    field; the outputs and the world are left unchanged (an edit that fails
 *    changes nothing).
 *  - Handles (ldc_world, ldc_cascades) are opaque; create them with the
 *    *_create / *_load calls and free them with the matching *_destroy
 *    (which accept NULL). The library never keeps a pointer to a caller's
 *    buffer after a call returns.
 *  - Handles are checked, not trusted. A handle's value is not an address:
 *    it packs a type tag (a magic number), a slot index and the slot's
 *    generation into a process-wide table that is never freed, so the
 *    library never reads freed memory to check one. A destroyed handle
 *    (destroy twice, use after destroy), a value the library never returned
 *    and a handle of the other type all give LDC_INVALID_HANDLE. Destroy
 *    changes the slot's generation, and a slot whose generation would wrap is
 *    never reused, so an old handle never names a newer object. At most
 *    2^20 handles of each type (2^14 on 32-bit systems) are live at once
 *    (LDC_TOO_LARGE beyond).
 *  - Caller-owned buffers: calls that return arrays take a pointer and a
 *    capacity (in elements) and write the needed count. Pass NULL with
 *    capacity 0 to ask for the count only: the call returns LDC_OK and
 *    writes nothing else. NULL with a non-zero capacity is refused
 *    (LDC_INVALID_ARGUMENT): it is more likely a failed allocation than a
 *    size query. A non-NULL buffer that is too small gives
 *    LDC_BUFFER_TOO_SMALL with the needed count written, and nothing else
 *    changes (ldc_world_take_dirty keeps its list). A capacity (or a ray
 *    count) whose size in bytes no array can have (over PTRDIFF_MAX) gives
 *    LDC_TOO_LARGE. The library never writes past the capacity it is given,
 *    but it cannot tell whether the buffer really is that large: overstating
 *    a capacity corrupts memory, as it would with memcpy.
 *  - Thread safety: each world has an atomic in-use count. A world takes any
 *    number of reading calls at a time (ldc_world_get_info,
 *    ldc_world_inside, ldc_world_save) or one other call: every other call
 *    on a world changes it (edits, and ray casts, meshing and path queries,
 *    which bring the world's caches up to date). A call that would overlap
 *    another in a conflicting way neither waits nor races: it returns
 *    LDC_BUSY at once and changes nothing (retry, or lock around the world
 *    if several threads use it). So does destroying a handle another thread
 *    is using. A cascades handle takes one call at a time; its calls also
 *    read its world (an edit of the world meanwhile gets LDC_BUSY), and its
 *    destroy changes the world. Other handles may be used concurrently.
 *    Heavy calls (building, meshing, batched ray casts, voxelizing) run in
 *    parallel internally (TBB). ldc_last_error() is per thread.
 *  - No exceptions or C++ types cross this header; out of memory is
 *    reported as LDC_TOO_LARGE. Enums are 32 bits wide (the *_MAX_ENUM
 *    entries); a value outside an enum's list is refused by name.
 *
 * Versioning: LDC_C_API_VERSION changes when a declaration here changes
 * incompatibly; structs only grow at the end, behind a new API version. The
 * library version is in ldc/version.h (LDC_VERSION_STRING) and at run time
 * in ldc_version_string(); compare them to detect a header/library mismatch.
 */
#ifndef LDC_CAPI_LDC_H
#define LDC_CAPI_LDC_H

#include <stddef.h>
#include <stdint.h>

#include "ldc/version.h"

#if defined(_WIN32)
#  if defined(LDC_C_BUILDING)
#    define LDC_C_API __declspec(dllexport)
#  else
#    define LDC_C_API __declspec(dllimport)
#  endif
#else
#  define LDC_C_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define LDC_C_API_VERSION 2

/* ------------------------------------------------------------------------ */
/* Status and version                                                        */

typedef enum ldc_status {
  LDC_OK = 0,
  LDC_INVALID_ARGUMENT = 1, /* a value out of its documented range, a NULL handle */
  LDC_PARSE_ERROR = 2,      /* a file does not follow its format */
  LDC_IO_ERROR = 3,         /* a file could not be opened, read or written */
  LDC_CORRUPT_DATA = 4,     /* checksum mismatch, inconsistent counts */
  LDC_TOO_LARGE = 5,        /* beyond the configured limits, or out of memory */
  LDC_UNSUPPORTED = 6,      /* a valid request not handled (e.g. another .ldc version) */
  LDC_CANCELLED = 7,
  LDC_INTERNAL = 8,         /* a bug in ldc: please report it with the message */
  LDC_BUFFER_TOO_SMALL = 9, /* a caller buffer is too small: the needed count was written */
  LDC_NOT_FOUND = 10,       /* e.g. no walkable floor near a path's start or goal */
  LDC_INVALID_HANDLE = 11,  /* a handle destroyed already, or never made by ldc */
  LDC_BUSY = 12,            /* the handle is in use by an overlapping call on another thread: retry */
  LDC_STATUS_MAX_ENUM = 0x7fffffff /* keeps every enum 32 bits wide (not a status) */
} ldc_status;

/* "ok", "invalid argument", ... (static strings). */
LDC_C_API const char* ldc_status_name(ldc_status status);
/* The message of the last failed call on this thread ("" if none). Valid
 * until the next failing ldc call on the same thread. */
LDC_C_API const char* ldc_last_error(void);
/* The library's version, e.g. "0.2.0" (LDC_VERSION_STRING of the build). */
LDC_C_API const char* ldc_version_string(void);
/* LDC_VERSION of the build (major * 10000 + minor * 100 + patch). */
LDC_C_API int ldc_version(void);
/* The .ldc file format version this library reads and writes. */
LDC_C_API int ldc_format_version(void);

/* Threads. The library's parallel work runs on TBB, one thread per core by
 * default. This caps it at `max_threads` for the whole process (TBB's
 * global_control: it also caps other TBB users in the process); 0 lifts the
 * cap. An engine that must share cores with its own job system calls this
 * once at start-up. [0 .. 4096] */
LDC_C_API ldc_status ldc_set_max_threads(int32_t max_threads);
/* The number of threads the library's parallel work may use now. */
LDC_C_API int32_t ldc_max_threads(void);

/* ------------------------------------------------------------------------ */
/* Worlds                                                                    */

typedef struct ldc_world ldc_world;

typedef struct ldc_world_config {
  double origin[3];      /* world position of lattice node (0,0,0) [m] */
  double cell_size;      /* h [m] [> 0] [default 0.2] */
  int32_t chunk_size;    /* C [8, 16, 32 or 64 cells] [default 32] */
  int32_t chunk_origin[3]; /* first chunk of the world's box [chunks] [default 0] */
  int32_t chunk_dims[3];   /* chunks per axis [>= 1] [default 1] */
} ldc_world_config;

typedef struct ldc_terrain_config {
  uint32_t seed;         /* same seed, same landscape [default 1] */
  double size_x, size_y; /* extent [m] [> 0] [default 48 x 48] */
  double base_height;    /* mean ground height above z = 0 [m] [> 0] [default 6] */
  double relief;         /* hill amplitude [m] [>= 0] [default 5] */
  double cave_radius;    /* cave tunnels [m] [>= 0, 0 = none] [default 1.1] */
  int32_t arches;        /* rock arches [0 .. 64] [default 3] */
  double cell_size;      /* h [m] [> 0] [default 0.2] */
} ldc_terrain_config;

/* Fill a config with the library's defaults. */
LDC_C_API void ldc_world_config_default(ldc_world_config* config);
LDC_C_API void ldc_terrain_config_default(ldc_terrain_config* config);

/* An empty world (no solid) on the given lattice. */
LDC_C_API ldc_status ldc_world_create(const ldc_world_config* config, ldc_world** out);
/* The procedural landscape (ldc/terrain.h); config NULL = the default
 * landscape (48 x 48 m, h = 0.2 m: about 0.3 s on 2 cores). */
LDC_C_API ldc_status ldc_world_create_terrain(const ldc_terrain_config* config, ldc_world** out);
/* Loads a .ldc file (every checksum and chunk verified). */
LDC_C_API ldc_status ldc_world_load(const char* path, ldc_world** out);
/* Writes the world as a .ldc file (zstd level 3). */
LDC_C_API ldc_status ldc_world_save(const ldc_world* world, const char* path);
/* Frees the world, its meshes and navigation data. Cascades made from it
 * stay valid handles but refuse updates (destroy them too). NULL is fine
 * (LDC_OK). LDC_INVALID_HANDLE for a world destroyed already; LDC_BUSY,
 * freeing nothing, while another thread's call uses the world or one of its
 * cascades. (It returned void before 0.3: callers that ignore the status
 * still link and run.) */
LDC_C_API ldc_status ldc_world_destroy(ldc_world* world);

typedef struct ldc_world_info {
  double origin[3];
  double cell_size;        /* h [m] */
  int32_t chunk_size;      /* C [cells] */
  int32_t chunk_origin[3]; /* [chunks] */
  int32_t chunk_dims[3];   /* [chunks] */
  double box_min[3], box_max[3]; /* the region the world can hold [m] */
  uint64_t chunks_empty, chunks_solid, chunks_mixed;
  uint64_t points;         /* surface points stored */
  uint64_t memory_bytes;   /* held by the world's chunks */
  uint64_t edit_version;   /* edits applied so far */
} ldc_world_info;

LDC_C_API ldc_status ldc_world_get_info(const ldc_world* world, ldc_world_info* out);
/* 1 when the point [m] is inside the solid, 0 when not, and 0 when it
 * cannot answer (a NULL or non-finite point, an invalid or busy handle;
 * ldc_last_error() then says which). */
LDC_C_API int ldc_world_inside(const ldc_world* world, const double point[3]);

/* ------------------------------------------------------------------------ */
/* Brush edits and dirty chunks                                              */

typedef enum ldc_brush_shape {
  LDC_BRUSH_SPHERE = 0,  /* centre, radius */
  LDC_BRUSH_BOX = 1,     /* centre, half_extents (axis-aligned) */
  LDC_BRUSH_CAPSULE = 2, /* a, b (segment ends), radius */
  LDC_BRUSH_SHAPE_MAX_ENUM = 0x7fffffff
} ldc_brush_shape;

typedef enum ldc_edit_op {
  LDC_EDIT_SUBTRACT = 0,  /* world minus the brush (dig) */
  LDC_EDIT_UNION = 1,     /* world union the brush (build; new surface takes its material) */
  LDC_EDIT_PAINT = 2,     /* surface inside the brush takes its material */
  LDC_EDIT_INTERSECT = 3, /* keep only what is inside the brush */
  /* The 0.2 spellings, deprecated (removed after 0.3): */
  LDC_EDIT_DIG = LDC_EDIT_SUBTRACT,
  LDC_EDIT_BUILD = LDC_EDIT_UNION,
  LDC_EDIT_OP_MAX_ENUM = 0x7fffffff
} ldc_edit_op;

typedef struct ldc_brush {
  ldc_brush_shape shape;
  double centre[3];       /* sphere, box [m] */
  double half_extents[3]; /* box [m] [> 0] */
  double a[3], b[3];      /* capsule segment [m] */
  double radius;          /* sphere, capsule [m] [> 0] */
  uint16_t material;      /* for build and paint [default 0] */
} ldc_brush;

typedef struct ldc_edit_result {
  uint64_t version;         /* the edit's number (1, 2, ...) */
  uint64_t chunks_changed;  /* chunks whose data changed */
} ldc_edit_result;

/* Applies one brush edit (touches only the chunks the brush overlaps). On
 * error the world is unchanged. `out` may be NULL. */
LDC_C_API ldc_status ldc_world_edit(ldc_world* world, const ldc_brush* brush, ldc_edit_op op,
                                    ldc_edit_result* out);

/* Flags of a dirty chunk. */
#define LDC_DIRTY_DATA 1u /* the chunk's rays changed (re-voxelize, re-upload collision) */
#define LDC_DIRTY_MESH 2u /* the chunk's mesh may have changed (re-fetch it) */

typedef struct ldc_dirty_chunk {
  int32_t chunk[3];    /* chunk coordinate */
  uint32_t flags;      /* LDC_DIRTY_DATA | LDC_DIRTY_MESH */
  uint64_t version;    /* the last edit that changed it (0 for mesh-only entries) */
  int32_t node_lo[3];  /* LDC_DIRTY_DATA: box of lattice nodes that changed */
  int32_t node_hi[3];  /* exclusive */
} ldc_dirty_chunk;

/* The chunks changed since the last call, sorted by (z, y, x), and clears
 * the list. Mesh-only entries are neighbours whose mesh shares vertices
 * with the change. A size query (out NULL) does not clear the list. The
 * world's own meshes, navigation data and cascades are kept up to date
 * whether or not this is called. */
LDC_C_API ldc_status ldc_world_take_dirty(ldc_world* world, ldc_dirty_chunk* out, size_t capacity,
                                          size_t* count);

/* ------------------------------------------------------------------------ */
/* Meshing (dual contouring, contour/contour.h)                              */

/* Caller buffers for one chunk's mesh. Set the pointers and capacities
 * (elements: vertices, triangles); NULL pointers with 0 capacities ask for
 * the counts only. Positions are world coordinates [m] as floats; normals
 * unit; indices index this chunk's vertices (counter-clockwise seen from
 * outside). Any of normals, vertex_materials and triangle_materials may be
 * NULL when not wanted. */
typedef struct ldc_mesh_buffers {
  float* positions;             /* 3 per vertex */
  float* normals;               /* 3 per vertex */
  uint16_t* vertex_materials;   /* 1 per vertex */
  uint32_t* indices;            /* 3 per triangle */
  uint16_t* triangle_materials; /* 1 per triangle */
  size_t vertex_capacity;
  size_t triangle_capacity;
  size_t vertex_count;          /* out */
  size_t triangle_count;        /* out */
} ldc_mesh_buffers;

/* The mesh of one chunk (its cells plus copies of the neighbour vertices its
 * triangles use, so it renders on its own without cracks). The world keeps
 * all chunk meshes: the first call meshes the whole world (in parallel);
 * later calls re-mesh only what edits changed. A chunk with no surface (or
 * outside the box) has 0 vertices. */
LDC_C_API ldc_status ldc_world_mesh_chunk(ldc_world* world, const int32_t chunk[3],
                                          ldc_mesh_buffers* buffers);

/* ------------------------------------------------------------------------ */
/* Ray casts (ldc/query.h)                                                   */

typedef struct ldc_ray {
  double origin[3];     /* [m] [finite] */
  double direction[3];  /* any non-zero length [finite] */
  double max_distance;  /* [m] [>= 0; INFINITY or a large number for unbounded] */
} ldc_ray;

typedef struct ldc_ray_hit {
  int32_t hit;            /* 1 when the ray hit within max_distance */
  int32_t started_inside; /* the origin was inside: distance 0 */
  double distance;        /* along the normalised direction [m] */
  double point[3];        /* [m] */
  float normal[3];        /* unit, out of the solid */
  uint16_t material;
} ldc_ray_hit;

/* Casts `count` rays (in parallel) into hits[0 .. count). Every ray is
 * checked first: an error names the first bad ray and writes no hit. A count
 * no array can hold gives LDC_TOO_LARGE. */
LDC_C_API ldc_status ldc_world_ray_cast(ldc_world* world, const ldc_ray* rays, size_t count,
                                        ldc_ray_hit* hits);

/* ------------------------------------------------------------------------ */
/* Navigation (nav/nav.h)                                                    */

typedef struct ldc_nav_config {
  int32_t up_axis;          /* 0 x, 1 y, 2 z [default 2] */
  double agent_height;      /* [m] [> 0] [default 2] */
  double agent_radius;      /* [m] [>= 0] [default 0.6] */
  double max_climb;         /* [m] [>= 0] [default 0.9] */
  double max_slope_degrees; /* [0 .. 89] [default 45] */
  int32_t max_nodes;        /* A* node budget [16 .. 1 << 20] [default 2048] */
  double search_half_extents[3]; /* how far from start/goal a floor is looked for [m] [default 2, 2, 4] */
  uint32_t filters;         /* Recast's span filters, LDC_NAV_FILTER_* bits [default: all three] */
  /* Areas, as Recast's area ids: the floors of material m are in area
   * material_areas[m] (materials past the count: area 0). The filter
   * (ldc_nav_filter) gives each area a cost and flags; a material a filter
   * must tell apart needs an area of its own. Copied by
   * ldc_world_set_nav_config. [each 0 .. 63] [count 0 .. 65536]
   * [default NULL, 0: everything in area 0] */
  const uint8_t* material_areas;
  uint32_t material_area_count;
} ldc_nav_config;

/* NavConfig's filter_* fields (nav/nav.h). */
#define LDC_NAV_FILTER_LOW_HANGING 1u /* steep floors just above walkable ones are walkable */
#define LDC_NAV_FILTER_LEDGES 2u      /* floors beside a drop deeper than max_climb are not */
#define LDC_NAV_FILTER_LOW_HEIGHT 4u  /* floors under less than agent_height are not */

LDC_C_API void ldc_nav_config_default(ldc_nav_config* config);
/* Sets the agent; the navigation data is rebuilt at the next path query
 * (off-mesh links stay: they are added to the new data). */
LDC_C_API ldc_status ldc_world_set_nav_config(ldc_world* world, const ldc_nav_config* config);

/* Which ground a path may use and what it costs, by area (the config's
 * material_areas), as Detour's dtQueryFilter. A floor is usable when its
 * area's flags share a bit with include_flags and none with exclude_flags;
 * a metre on it costs its area's cost. Off-mesh links are matched by their
 * own flags. The start and goal snap only to usable floors. */
typedef struct ldc_nav_filter {
  const double* area_costs;    /* by area; areas past the count cost 1 [each finite, >= 0.01] */
  uint32_t area_cost_count;    /* [0 .. 64] */
  const uint16_t* area_flags;  /* by area; areas past the count have flags 1 */
  uint32_t area_flag_count;    /* [0 .. 64] */
  uint16_t include_flags;      /* [default 0xFFFF] */
  uint16_t exclude_flags;      /* [default 0] */
} ldc_nav_filter;

LDC_C_API void ldc_nav_filter_default(ldc_nav_filter* filter);
/* The filter of later ldc_world_find_path calls (copied); NULL resets it to
 * the default (every area usable at cost 1). */
LDC_C_API ldc_status ldc_world_set_nav_filter(ldc_world* world, const ldc_nav_filter* filter);

/* An off-mesh link: a jump, a ladder, a teleporter. Each end snaps to the
 * nearest walkable floor within `radius`; a link with an end on no floor is
 * kept but unused until an edit puts a floor there. */
typedef struct ldc_nav_link {
  double a[3], b[3];      /* ends [m] [finite] */
  double cost;            /* of taking it, in metres of cost-1 ground [finite; < 0: the straight distance] [default -1] */
  double radius;          /* [m] [> 0, <= 100] [default 1] */
  int32_t bidirectional;  /* 1: both ways; 0: from a to b only [default 1] */
  uint16_t flags;         /* matched by the filter's include / exclude flags [default 1] */
} ldc_nav_link;

LDC_C_API void ldc_nav_link_default(ldc_nav_link* link);
/* Adds a link to the world's navigation (kept across edits and nav config
 * changes); its id goes to *id_out. Ids are never reused. */
LDC_C_API ldc_status ldc_world_add_nav_link(ldc_world* world, const ldc_nav_link* link, uint32_t* id_out);
/* Removes link `id`; LDC_INVALID_ARGUMENT for an unknown id. */
LDC_C_API ldc_status ldc_world_remove_nav_link(ldc_world* world, uint32_t id);
/* *attached = 1 when both ends of link `id` found a walkable floor (builds or
 * updates the navigation data first, as a path query does), 0 when not. */
LDC_C_API ldc_status ldc_world_nav_link_attached(ldc_world* world, uint32_t id, int32_t* attached);

typedef enum ldc_path_status {
  LDC_PATH_COMPLETE = 0,     /* reaches the goal */
  LDC_PATH_UNREACHABLE = 1,  /* ends at the start island's point nearest the goal */
  LDC_PATH_OUT_OF_NODES = 2, /* the node budget ran out: ends nearest the goal explored */
  LDC_PATH_STATUS_MAX_ENUM = 0x7fffffff
} ldc_path_status;

typedef struct ldc_path_info {
  ldc_path_status status;
  size_t corner_count;    /* corners of the polyline (start, turns, end) */
  double length;          /* [m] */
  uint64_t nodes_searched;
} ldc_path_info;

/* A walking path from `from` to `to` [m]. The navigation data is built at
 * the first query and updated from the edits since the last one. Corners go
 * to corners[0 .. 3 * corner_count) as x, y, z; corners may be NULL with
 * corner_capacity 0 (the info only). Status LDC_NOT_FOUND when no walkable
 * floor lies near the start or goal. */
LDC_C_API ldc_status ldc_world_find_path(ldc_world* world, const double from[3], const double to[3],
                                         double* corners, size_t corner_capacity, ldc_path_info* info);

/* ------------------------------------------------------------------------ */
/* Voxel cascades (voxelize/voxelize.h)                                      */

typedef struct ldc_cascades ldc_cascades;

typedef struct ldc_cascade_config {
  int32_t levels;      /* K [1 .. 16] [default 6] */
  int32_t resolution;  /* N voxels per axis and level [even, 4 .. 256] [default 32] */
  double voxel_size;   /* level 0's voxel edge [m] [a whole number of cells] [default 0.2] */
} ldc_cascade_config;

LDC_C_API void ldc_cascade_config_default(ldc_cascade_config* config);
/* Cascades on the world's lattice, fed by its edits (materials: the
 * landscape's table). Nothing is voxelized until an update. */
LDC_C_API ldc_status ldc_cascades_create(ldc_world* world, const ldc_cascade_config* config,
                                         ldc_cascades** out);
/* NULL is fine (LDC_OK). LDC_INVALID_HANDLE for cascades destroyed already;
 * LDC_BUSY, freeing nothing, while they or their world are in use on
 * another thread. (It returned void before 0.3.) */
LDC_C_API ldc_status ldc_cascades_destroy(ldc_cascades* cascades);

typedef struct ldc_cascade_update {
  int32_t level;       /* the level updated */
  int32_t shift[3];    /* how far it moved [its voxels] */
  int32_t full;        /* 1 when voxelized whole */
  uint64_t voxels;     /* voxels voxelized */
  double seconds;
  int32_t box_lo[3];   /* the level's voxel box after the update (global voxel coordinates) */
  int32_t box_dims[3];
} ldc_cascade_update;

/* Moves level `level` to the camera [m]: voxelizes what is exposed and what
 * edits changed. `out` may be NULL. */
LDC_C_API ldc_status ldc_cascades_update_level(ldc_cascades* cascades, int32_t level,
                                               const double camera[3], ldc_cascade_update* out);

/* One level's six-face G-buffer, camera-centred, in the GPU formats of
 * voxelize.h (PackedGBuffer): per texel of extent (6N, N, N), x fastest,
 * texel (f*N + x, y, z) = face f of voxel lo + (x, y, z). Capacity in texels
 * (6 N^3 needed). Any pointer may be NULL when not wanted; all NULL with
 * texel_capacity 0 asks for the count. */
typedef struct ldc_gbuffer_buffers {
  uint32_t* albedo;     /* R8G8B8A8_UNORM: rgb albedo, a = surface weight */
  uint32_t* normal;     /* R8G8B8A8_SNORM: xyz normal */
  uint8_t* occupancy;   /* R8_UNORM: face opacity */
  uint32_t* emission;   /* B10G11R11_UFLOAT_PACK32 */
  size_t texel_capacity;
  size_t texel_count;   /* out */
} ldc_gbuffer_buffers;

LDC_C_API ldc_status ldc_cascades_read_level(const ldc_cascades* cascades, int32_t level,
                                             ldc_gbuffer_buffers* buffers);

#ifdef __cplusplus
}  /* extern "C" */
#endif

#endif /* LDC_CAPI_LDC_H */
