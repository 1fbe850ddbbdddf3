// ldc bake (issue 23): the offline bake of a large world, sharded for a batch
// scheduler (a Slurm job array, a Kubernetes Indexed Job), and its merge.
//
//   ldc bake WORLD --out DIR --shard i/N [--products mesh,nav,voxels] [--lods N] [--mesh-format glb|drc]
//   ldc bake --merge DIR
//
// Work units are chunk columns (x, y) holding at least one chunk that may be
// mixed (read from the source's kinds where it knows them cheaply: the
// procedural solid's box test, a store log's chunks, an .ldc world's kinds).
// Every shard computes the same unit list and the same cut into N ranges of
// equal cost (cost = possibly-mixed chunks of the column), so no shard talks
// to another. Each unit's products are computed from a window of the unit's
// column plus one chunk column around it (the whole z range), so a unit's
// bytes depend on the unit and the world only, never on N or on which shard
// baked it: the merged bake equals a one-process bake byte for byte.
#include <algorithm>
#include <atomic>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "common.h"
#include "contour/contour.h"
#include "ldc/internal/crc32.h"
#include "ldc/io.h"
#include "ldc/lod.h"
#include "ldc/store.h"
#include "meshio/meshio.h"
#include "nav/nav.h"
#include "voxelize/voxelize.h"

namespace ldc::tool {
namespace {

namespace fs = std::filesystem;

constexpr const char* kShardFormat = "ldc-bake-shard 1";
constexpr const char* kIndexFormat = "ldc-bake-index 1";

struct BakeArgs {
  std::string world;
  std::string out;
  std::string shard;
  std::string products = "mesh,nav,voxels";
  std::string mesh_format = "glb";  // or drc (Draco)
  int lods = 1;
  std::string merge;
  std::string terrain_size;  // procedural world without a file
  double cell_size = 0.5;
  int chunk_size = 32;
  uint32_t seed = 1;
};

// An .ldc world as a chunk source.
class WorldSource final : public ChunkSource {
 public:
  explicit WorldSource(World world) : world_(std::move(world)) {
    layout_.lattice = world_.lattice();
    layout_.chunk_size = world_.chunk_size();
    layout_.box.chunk_origin = world_.chunk_origin();
    layout_.box.chunk_dims = world_.chunk_dims();
  }
  const SourceLayout& layout() const override { return layout_; }
  Result<StoredChunk> read(const glm::ivec3& chunk) const override {
    if (!layout_.box.contains(chunk)) return StoredChunk{};
    StoredChunk s;
    s.kind = world_.chunk_kind(chunk);
    if (s.kind == ChunkKind::kMixed) s.data = world_.chunk_shared(chunk);
    return s;
  }
  const World& world() const { return world_; }

 private:
  World world_;
  SourceLayout layout_;
};

struct BakeWorld {
  std::string id;  // what the manifests record: the same text means the same world
  std::shared_ptr<const ChunkSource> source;
  // Whether a chunk may be mixed (cheap; false only when it certainly is not).
  std::function<bool(const glm::ivec3&)> maybe_mixed;
};

std::function<bool(const glm::ivec3&)> implicit_classifier(const ImplicitSource& src) {
  const SourceLayout layout = src.layout();
  const WorldBox bounds = src.solid().bounds();
  return [&src, layout, bounds](const glm::ivec3& c) {
    const glm::dvec3 lo = layout.lattice.node_position(c * layout.chunk_size);
    const glm::dvec3 hi = layout.lattice.node_position((c + 1) * layout.chunk_size);
    if (hi.x < bounds.min.x || hi.y < bounds.min.y || hi.z < bounds.min.z || lo.x > bounds.max.x ||
        lo.y > bounds.max.y || lo.z > bounds.max.z)
      return false;
    return src.solid().classify(WorldBox{lo, hi}) == ImplicitSolid::BoxClass::kUnknown;
  };
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
  size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  return s.substr(i);
}

bool ends_with(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  std::string tail = s.substr(s.size() - suffix.size());
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  return tail == suffix;
}

Result<BakeWorld> describe_source(const std::string& description) {
  Result<std::shared_ptr<const ChunkSource>> src = source_from_description(description);
  if (!src.ok()) return src.status();
  BakeWorld w;
  w.id = description;
  w.source = src.value();
  if (auto imp = std::dynamic_pointer_cast<const ImplicitSource>(w.source)) {
    w.maybe_mixed = implicit_classifier(*imp);
  } else {
    auto s = w.source;
    w.maybe_mixed = [s](const glm::ivec3& c) {
      Result<StoredChunk> r = s->read(c);
      return !r.ok() || r.value().kind == ChunkKind::kMixed;
    };
  }
  return w;
}

Result<BakeWorld> open_bake_world(const BakeArgs& a) {
  if (!a.terrain_size.empty()) {
    if (!a.world.empty())
      return Status(ErrorCode::kInvalidArgument, "give either WORLD or --terrain-size, not both");
    std::vector<double> size;
    if (!parse_numbers(a.terrain_size, &size) || size.size() != 2)
      return Status(ErrorCode::kInvalidArgument, "--terrain-size: expected X,Y in metres, got '" + a.terrain_size + "'");
    TerrainConfig config;
    config.seed = a.seed;
    config.size_x = size[0];
    config.size_y = size[1];
    if (Status s = check_terrain(config); !s.ok()) return s;
    return describe_source(terrain_source_description(config, a.cell_size, a.chunk_size));
  }
  if (a.world.empty()) return Status(ErrorCode::kInvalidArgument, "give WORLD (a .ldcs store, an .ldc world, a description file or text) or --terrain-size X,Y");
  std::error_code ec;
  if (ends_with(a.world, ".ldcs")) {
    Result<Store> store = open_store(a.world);
    if (!store.ok()) return store.status();
    BakeWorld w;
    const ChunkLogStats st = store.value().log->stats();
    w.id = store.value().log->base_description() + " | store sequence=" + std::to_string(st.sequence) +
           " live_chunks=" + std::to_string(st.live_chunks);
    std::function<bool(const glm::ivec3&)> base_test;
    if (auto imp = std::dynamic_pointer_cast<const ImplicitSource>(store.value().base)) base_test = implicit_classifier(*imp);
    auto keep = std::make_shared<Store>(std::move(store.value()));
    w.source = keep->source;
    w.maybe_mixed = [keep, base_test](const glm::ivec3& c) {
      Result<std::optional<StoredChunk>> f = keep->log->find(c);
      if (!f.ok()) return true;
      if (f.value().has_value()) return f.value()->kind == ChunkKind::kMixed;
      if (base_test) return base_test(c);
      Result<StoredChunk> r = keep->base->read(c);
      return !r.ok() || r.value().kind == ChunkKind::kMixed;
    };
    return w;
  }
  if (has_ldc_extension(a.world)) {
    Result<std::string> bytes = read_file(a.world);
    if (!bytes.ok()) return bytes.status();
    Result<World> world = deserialize_world(bytes.value(), a.world);
    if (!world.ok()) return world.status();
    char crc[16];
    std::snprintf(crc, sizeof crc, "%08x",
                  detail::crc32(reinterpret_cast<const uint8_t*>(bytes.value().data()), bytes.value().size()));
    BakeWorld w;
    w.id = "ldc-world crc32=" + std::string(crc) + " bytes=" + std::to_string(bytes.value().size());
    auto src = std::make_shared<const WorldSource>(std::move(world.value()));
    w.source = src;
    w.maybe_mixed = [src](const glm::ivec3& c) {
      return src->layout().box.contains(c) && src->world().chunk_kind(c) == ChunkKind::kMixed;
    };
    return w;
  }
  if (fs::is_regular_file(a.world, ec)) {
    Result<std::string> text = read_file(a.world, 1 << 20);
    if (!text.ok()) return text.status();
    return describe_source(trim(text.value()));
  }
  if (a.world.rfind("ldc-terrain", 0) == 0) return describe_source(trim(a.world));
  return Status(ErrorCode::kIoError, a.world + ": no such file (WORLD is a .ldcs store, an .ldc world, a file holding a world description, or the description text)");
}

struct Products {
  bool mesh = false, nav = false, voxels = false;
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    if (mesh) n.push_back("mesh");
    if (nav) n.push_back("nav");
    if (voxels) n.push_back("voxels");
    return n;
  }
};

Result<Products> parse_products(const std::string& text) {
  Products p;
  size_t start = 0;
  while (start <= text.size()) {
    size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item == "mesh") p.mesh = true;
    else if (item == "nav") p.nav = true;
    else if (item == "voxels") p.voxels = true;
    else return Status(ErrorCode::kInvalidArgument, "--products: unknown product '" + item + "' (expected mesh, nav, voxels)");
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return p;
}

struct Unit {
  glm::ivec2 column{0};
  int64_t cost = 0;
};

// Every column of the source's box with a chunk that may be mixed, in chunk
// order (y, then x), with its cost; the same list in every shard.
std::vector<Unit> plan_units(const BakeWorld& w) {
  const SourceBox box = w.source->layout().box;
  const int nx = box.chunk_dims.x, ny = box.chunk_dims.y;
  std::vector<int64_t> cost(size_t(nx) * size_t(ny), 0);
  tbb::parallel_for(0, ny, [&](int y) {
    for (int x = 0; x < nx; ++x)
      for (int z = 0; z < box.chunk_dims.z; ++z)
        if (w.maybe_mixed(box.chunk_origin + glm::ivec3(x, y, z))) ++cost[size_t(y) * nx + x];
  });
  std::vector<Unit> units;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x)
      if (int64_t c = cost[size_t(y) * nx + x]; c > 0)
        units.push_back({glm::ivec2(box.chunk_origin.x + x, box.chunk_origin.y + y), c});
  return units;
}

// Unit k goes to the shard whose equal-cost range holds the middle of its
// cost: contiguous ranges, balanced by mixed chunks, identical in every shard.
int shard_of(int64_t before, int64_t cost, int64_t total, int n) {
  const long double mid = (long double)before + (long double)cost / 2.0L;
  int s = int(mid * n / (long double)total);
  return std::clamp(s, 0, n - 1);
}

struct FileEntry {
  std::string name;  // relative to the shard folder (and to the merged folder)
  uint64_t bytes = 0;
  uint32_t crc = 0;
};

std::string hex32(uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "%08x", v);
  return b;
}

uint32_t crc_of(const std::string& bytes) {
  return detail::crc32(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

std::string chunk_name(const glm::ivec3& c) {
  return std::to_string(c.x) + "_" + std::to_string(c.y) + "_" + std::to_string(c.z);
}

struct UnitResult {
  std::vector<FileEntry> files;
  size_t mixed_chunks = 0;
  double seconds[4] = {0, 0, 0, 0};  // window, mesh, nav, voxels
  uint64_t bytes[3] = {0, 0, 0};     // mesh, nav, voxels
  Status status;
};

Status write_product(const fs::path& dir, const std::string& name, const std::string& bytes, UnitResult& r, int product) {
  Status s = write_file_atomically((dir / name).string(), bytes);
  if (!s.ok()) return s;
  r.files.push_back({name, bytes.size(), crc_of(bytes)});
  r.bytes[product] += bytes.size();
  return Status();
}

// The unit's column and `margin` chunk columns around it, the whole z range.
using WindowFn = std::function<Result<World>(int margin)>;

// Each chunk of the unit's column as a mesh (.glb or .drc), at level 0
// ("mesh/<chunk>.glb") and at levels 1 .. lods - 1 ("mesh/lod<k>/<chunk>.glb", from the window
// coarsened to every 2^k-th ray: ldc/lod.h). A chunk's mesh reads about ten
// cells around it, so coarse chunks of 8 cells take a window of two chunk
// columns around the unit (contour_chunk refuses a reach into a cut face).
// Empty meshes write no file.
Status bake_meshes(const World& w, const WindowFn& window, const Unit& u, int z0, int z1, int lods,
                   const std::string& format, const fs::path& dir, UnitResult& r) {
  for (int level = 0; level < lods; ++level) {
    std::optional<World> coarse;
    if (level > 0) {
      std::optional<World> wide;
      if ((w.chunk_size() >> level) < 16) {
        Result<World> two = window(2);
        if (!two.ok()) return two.status();
        wide = std::move(two).value();
      }
      Result<World> made = coarsen(wide ? *wide : w, level);
      if (!made.ok()) return made.status();
      coarse = std::move(made).value();
    }
    const World& at_level = coarse ? *coarse : w;
    const std::string folder = level == 0 ? "mesh/" : "mesh/lod" + std::to_string(level) + "/";
    for (int z = z0; z < z1; ++z) {
      const glm::ivec3 c(u.column, z);
      Result<ChunkMesh> m = contour_chunk(at_level, c);
      if (!m.ok()) return m.status();
      if (m.value().mesh.triangles.empty()) continue;
      const std::string name = folder + chunk_name(c) + "." + format;
      // save_mesh writes atomically; its bytes are read back for the checksum.
      if (Status s = save_mesh(m.value().mesh, (dir / name).string()); !s.ok()) return s;
      Result<std::string> bytes = read_file((dir / name).string());
      if (!bytes.ok()) return bytes.status();
      r.files.push_back({name, bytes.value().size(), crc_of(bytes.value())});
      r.bytes[0] += bytes.value().size();
    }
  }
  return Status();
}

// Each mixed chunk's walkable-floor heights, one float per ray column (NaN
// where none), from a nav mesh of the window: "nav/<chunk>.nav".
Status bake_nav(const World& w, const Unit& u, int z0, int z1, const SourceLayout& layout, const fs::path& dir,
                UnitResult& r) {
  const int C = layout.chunk_size;
  const double h = layout.lattice.cell_size;
  Result<NavMesh> nav = NavMesh::build(w, NavConfig{});
  if (!nav.ok()) return nav.status();
  NavQuery query(nav.value());
  for (int z = z0; z < z1; ++z) {
    const glm::ivec3 c(u.column, z);
    if (w.chunk_kind(c) != ChunkKind::kMixed) continue;
    std::vector<float> heights(size_t(C) * C, std::nanf(""));
    bool any = false;
    const double zmid = layout.lattice.node_position(glm::ivec3(0, 0, z * C)).z + 0.5 * C * h;
    for (int v = 0; v < C; ++v)
      for (int uu = 0; uu < C; ++uu) {
        glm::dvec3 pos = layout.lattice.node_position(glm::ivec3(c.x * C + uu, c.y * C + v, z * C));
        pos.z = zmid;
        Result<NavPoint> np = query.nearest_walkable(pos, glm::dvec3(0.49 * h, 0.49 * h, 0.5 * C * h));
        if (np.ok()) {
          heights[size_t(v) * C + uu] = float(np.value().position.z);
          any = true;
        }
      }
    if (!any) continue;
    std::string bytes(heights.size() * sizeof(float), '\0');
    std::memcpy(bytes.data(), heights.data(), bytes.size());
    if (Status s = write_product(dir, "nav/" + chunk_name(c) + ".nav", bytes, r, 1); !s.ok()) return s;
  }
  return Status();
}

// Each mixed chunk's solid occupancy in 2h bricks, a byte each: "voxels/<chunk>.occ".
Status bake_voxels(const World& w, const Unit& u, int z0, int z1, const SourceLayout& layout, const fs::path& dir,
                   UnitResult& r) {
  VoxelConfig config;
  config.voxel_size = 2.0 * layout.lattice.cell_size;
  const int n = layout.chunk_size / 2;
  for (int z = z0; z < z1; ++z) {
    const glm::ivec3 c(u.column, z);
    if (w.chunk_kind(c) != ChunkKind::kMixed) continue;
    VoxelizeOptions options;
    options.box = VoxelBox{c * n, glm::ivec3(n)};
    Result<VoxelGrid> grid = voxelize(w, config, options);
    if (!grid.ok()) return grid.status();
    std::string bytes(grid.value().occupancy.size(), '\0');
    for (size_t i = 0; i < bytes.size(); ++i)
      bytes[i] = char(uint8_t(std::lround(std::clamp(grid.value().occupancy[i], 0.0f, 1.0f) * 255.0f)));
    if (Status s = write_product(dir, "voxels/" + chunk_name(c) + ".occ", bytes, r, 2); !s.ok()) return s;
  }
  return Status();
}

UnitResult bake_unit(const Unit& u, PagedWorld& paged, std::mutex& paged_mutex, const Products& p, int lods,
                     const std::string& mesh_format, const fs::path& dir) {
  UnitResult r;
  const SourceLayout layout = paged.layout();
  const int z0 = layout.box.chunk_origin.z, z1 = z0 + layout.box.chunk_dims.z;
  ScopedTimer tw(nullptr, "");
  const WindowFn window_of = [&](int margin) -> Result<World> {
    std::lock_guard lock(paged_mutex);
    return paged.window(glm::ivec3(u.column.x - margin, u.column.y - margin, z0),
                        glm::ivec3(u.column.x + margin + 1, u.column.y + margin + 1, z1));
  };
  Result<World> window = window_of(1);
  if (!window.ok()) {
    r.status = window.status();
    return r;
  }
  const World& w = window.value();
  r.seconds[0] = tw.seconds();
  for (int z = z0; z < z1; ++z)
    if (w.chunk_kind(glm::ivec3(u.column, z)) == ChunkKind::kMixed) ++r.mixed_chunks;
  // Each product in turn, timed; the first error stops the unit.
  auto run = [&](bool wanted, int slot, auto&& bake) {
    if (!wanted || !r.status.ok()) return;
    ScopedTimer t(nullptr, "");
    r.status = bake();
    r.seconds[slot] = t.seconds();
  };
  run(p.mesh, 1, [&] { return bake_meshes(w, window_of, u, z0, z1, lods, mesh_format, dir, r); });
  run(p.nav, 2, [&] { return bake_nav(w, u, z0, z1, layout, dir, r); });
  run(p.voxels, 3, [&] { return bake_voxels(w, u, z0, z1, layout, dir, r); });
  return r;
}

// --- Manifests ------------------------------------------------------------------

Result<nlohmann::json> read_json(const fs::path& path) {
  Result<std::string> text = read_file(path.string(), uint64_t{1} << 30);
  if (!text.ok()) return text.status();
  nlohmann::json j = nlohmann::json::parse(text.value(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Status(ErrorCode::kCorruptData, path.string() + ": not a JSON object");
  return j;
}

// Checks every file a manifest lists against its size and CRC-32; the error names the file.
Status check_files(const fs::path& shard_dir, const nlohmann::json& manifest, size_t* files_checked) {
  try {
    for (const auto& unit : manifest.at("units"))
      for (const auto& f : unit.at("files")) {
        const std::string name = f.at("name").get<std::string>();
        if (name.empty() || name.find("..") != std::string::npos || name[0] == '/')
          return Status(ErrorCode::kCorruptData, (shard_dir / "manifest.json").string() + ": bad file name '" + name + "'");
        const fs::path path = shard_dir / name;
        Result<std::string> bytes = read_file(path.string());
        if (!bytes.ok()) return Status(ErrorCode::kCorruptData, path.string() + ": missing or unreadable (" + bytes.status().message() + ")");
        if (bytes.value().size() != f.at("bytes").get<uint64_t>() || hex32(crc_of(bytes.value())) != f.at("crc32").get<std::string>())
          return Status(ErrorCode::kCorruptData, path.string() + ": checksum mismatch (the manifest says " +
                                                     std::to_string(f.at("bytes").get<uint64_t>()) + " bytes, crc32 " +
                                                     f.at("crc32").get<std::string>() + "; the file has " +
                                                     std::to_string(bytes.value().size()) + " bytes, crc32 " +
                                                     hex32(crc_of(bytes.value())) + ")");
        if (files_checked) ++*files_checked;
      }
  } catch (const nlohmann::json::exception& e) {
    return Status(ErrorCode::kCorruptData, (shard_dir / "manifest.json").string() + ": malformed manifest (" + e.what() + ")");
  }
  return Status();
}

// Refuses an output folder holding another world's bake (any shard manifest or index).
// lods and mesh_format: 0 / empty skip their checks.
Status check_same_world(const fs::path& out, const std::string& world_id, const std::string& products, int shards,
                        int lods, const std::string& mesh_format) {
  std::error_code ec;
  std::vector<fs::path> manifests;
  if (fs::exists(out / "index.json", ec)) manifests.push_back(out / "index.json");
  if (fs::is_directory(out / "shards", ec))
    for (const auto& e : fs::directory_iterator(out / "shards", ec))
      if (fs::exists(e.path() / "manifest.json", ec)) manifests.push_back(e.path() / "manifest.json");
  std::sort(manifests.begin(), manifests.end());
  for (const fs::path& m : manifests) {
    Result<nlohmann::json> j = read_json(m);
    if (!j.ok()) continue;  // a broken manifest is redone (own shard) or refused at merge
    const std::string other = j.value().value("world", std::string());
    if (other != world_id)
      return Status(ErrorCode::kInvalidArgument, out.string() + " holds another world's bake (" + m.string() +
                                                     " is of world '" + other + "', this bake is of '" + world_id +
                                                     "'); use another --out");
    if (shards > 0 && j.value().contains("shards") && j.value().value("shards", 0) != shards)
      return Status(ErrorCode::kInvalidArgument, out.string() + " holds a bake in " + std::to_string(j.value().value("shards", 0)) +
                                                     " shards, not " + std::to_string(shards) + " (" + m.string() + "); use another --out");
    std::string other_products;
    if (j.value().contains("products"))
      for (const auto& pr : j.value()["products"]) other_products += (other_products.empty() ? "" : ",") + pr.get<std::string>();
    if (other_products != products)
      return Status(ErrorCode::kInvalidArgument, out.string() + " holds a bake of other products (" + m.string() +
                                                     ": " + other_products + "; this bake: " + products + ")");
    if (lods > 0 && j.value().value("lods", 1) != lods)
      return Status(ErrorCode::kInvalidArgument, out.string() + " holds a bake of " +
                                                     std::to_string(j.value().value("lods", 1)) + " mesh levels, not " +
                                                     std::to_string(lods) + " (" + m.string() + "); use another --out");
    if (!mesh_format.empty() && j.value().value("mesh_format", std::string("glb")) != mesh_format)
      return Status(ErrorCode::kInvalidArgument, out.string() + " holds a bake of ." +
                                                     j.value().value("mesh_format", std::string("glb")) +
                                                     " meshes, not ." + mesh_format + " (" + m.string() +
                                                     "); use another --out");
  }
  return Status();
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

Result<std::pair<int, int>> parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  auto number = [](const std::string& s, long long* v) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    *v = std::stoll(s);
    return true;
  };
  long long i = 0, n = 0;
  if (slash == std::string::npos || !number(text.substr(0, slash), &i) || !number(text.substr(slash + 1), &n))
    return Status(ErrorCode::kInvalidArgument, "--shard: expected i/N (two whole numbers), got '" + text + "'");
  if (n == 0) return Status(ErrorCode::kInvalidArgument, "--shard " + text + ": N = 0 (the shard count must be at least 1)");
  if (i >= n)
    return Status(ErrorCode::kInvalidArgument, "--shard " + text + ": shard index " + std::to_string(i) +
                                                   " out of range for " + std::to_string(n) + " shards (0 .. " +
                                                   std::to_string(n - 1) + ")");
  return std::make_pair(int(i), int(n));
}

// The shard's finished manifest, when it checks out: prints "skipped" and
// returns true. A manifest that does not check out is removed (with a
// warning) for the shard to be baked again; *refusal is set when the folder
// holds a bake in another shard count.
bool finished_shard(const fs::path& out, const fs::path& dir, int si, int sn, const CommonOptions& common,
                    std::optional<int>* refusal) {
  const std::string cmd = "bake";
  const fs::path manifest_path = dir / "manifest.json";
  std::error_code ec;
  if (!fs::exists(manifest_path, ec)) return false;
  Result<nlohmann::json> m = read_json(manifest_path);
  size_t checked = 0;
  Status s = m.ok() ? check_files(dir, m.value(), &checked) : m.status();
  if (s.ok() && (m.value().value("shards", -1) != sn || m.value().value("shard", -1) != si))
    s = Status(ErrorCode::kCorruptData, manifest_path.string() + " is of shard " +
                                            std::to_string(m.value().value("shard", -1)) + "/" +
                                            std::to_string(m.value().value("shards", -1)));
  if (s.ok()) {
    if (common.json)
      std::printf("%s\n", json_text(with_warnings({{"shard", si}, {"shards", sn}, {"skipped", true}, {"files_checked", checked}})).c_str());
    else
      std::printf("shard %d/%d already baked (%zu files checked against %s); skipped\n", si, sn, checked,
                  manifest_path.string().c_str());
    return true;
  }
  if (m.ok() && m.value().value("shards", sn) != sn) {
    *refusal = fail(cmd, out.string() + " holds a bake in " + std::to_string(m.value().value("shards", 0)) +
                             " shards, not " + std::to_string(sn) + " (" + manifest_path.string() + "); use another --out");
    return false;
  }
  warn(cmd, "re-baking shard " + std::to_string(si) + ": " + s.message());
  fs::remove(manifest_path, ec);
  return false;
}

// Every unit of the world, and this shard's (contiguous ranges of equal cost).
struct ShardPlan {
  std::vector<Unit> all, mine;
  int64_t total_cost = 0, mine_cost = 0;
};

ShardPlan plan_shard(const BakeWorld& world, int si, int sn) {
  ShardPlan plan;
  plan.all = plan_units(world);
  for (const Unit& u : plan.all) plan.total_cost += u.cost;
  int64_t before = 0;
  for (const Unit& u : plan.all) {
    if (shard_of(before, u.cost, plan.total_cost, sn) == si) {
      plan.mine.push_back(u);
      plan.mine_cost += u.cost;
    }
    before += u.cost;
  }
  return plan;
}

// The shard's units baked in parallel (one window each), with a progress bar.
std::vector<UnitResult> bake_units(const BakeArgs& a, const BakeWorld& world, const ShardPlan& plan,
                                   const Products& products, const fs::path& dir, const CommonOptions& common) {
  ProgressBar bar(!common.quiet);
  PagedWorld paged(world.source);
  std::mutex paged_mutex, progress_mutex;
  std::vector<UnitResult> results(plan.mine.size());
  std::atomic<size_t> done{0};
  tbb::parallel_for(size_t(0), plan.mine.size(), [&](size_t k) {
    results[k] = bake_unit(plan.mine[k], paged, paged_mutex, products, a.lods, a.mesh_format, dir);
    const size_t d = ++done;
    std::lock_guard lock(progress_mutex);
    bar.context()->report_progress("bake", double(d) / double(plan.mine.size()));
  }, tbb::simple_partitioner());
  bar.finish();
  return results;
}

// What the shard's units wrote, summed; the units with their files for the manifest.
struct ShardTotals {
  nlohmann::json units = nlohmann::json::array();
  size_t files = 0, mixed = 0;
  uint64_t bytes[3] = {0, 0, 0};     // mesh, nav, voxels
  double seconds[4] = {0, 0, 0, 0};  // window, mesh, nav, voxels (CPU, summed over units)
};

Result<ShardTotals> shard_totals(const ShardPlan& plan, const std::vector<UnitResult>& results) {
  ShardTotals t;
  for (size_t k = 0; k < plan.mine.size(); ++k) {
    const UnitResult& r = results[k];
    const Unit& u = plan.mine[k];
    if (!r.status.ok())
      return Status(r.status.code(), "column " + std::to_string(u.column.x) + "," + std::to_string(u.column.y) + ": " +
                                         r.status.message());
    nlohmann::json fl = nlohmann::json::array();
    for (const FileEntry& f : r.files) fl.push_back({{"name", f.name}, {"bytes", f.bytes}, {"crc32", hex32(f.crc)}});
    t.units.push_back({{"column", {u.column.x, u.column.y}}, {"cost", u.cost}, {"files", fl}});
    t.files += r.files.size();
    t.mixed += r.mixed_chunks;
    for (int i = 0; i < 3; ++i) t.bytes[i] += r.bytes[i];
    for (int i = 0; i < 4; ++i) t.seconds[i] += r.seconds[i];
  }
  return t;
}

nlohmann::json shard_manifest(const BakeArgs& a, const BakeWorld& world, const ShardPlan& plan, const ShardTotals& t,
                              const Products& products, int si, int sn) {
  const SourceLayout layout = world.source->layout();
  return {{"format", kShardFormat},
          {"world", world.id},
          {"shard", si},
          {"shards", sn},
          {"products", products.names()},
          {"lods", a.lods},
          {"mesh_format", a.mesh_format},
          {"chunk_size", layout.chunk_size},
          {"cell_size", layout.lattice.cell_size},
          {"units_total", plan.all.size()},
          {"cost_total", plan.total_cost},
          {"units", t.units}};
}

// What the shard did, as text or --json: units, files, bytes per product, times.
struct ShardTimes {
  double total = 0, plan = 0, bake_wall = 0;
};

void print_shard_report(const ShardPlan& plan, const ShardTotals& sum, const SourceLayout& layout, int si, int sn,
                        const ShardTimes& times, const fs::path& manifest_path, const CommonOptions& common) {
  const double chunk_m = layout.chunk_size * layout.lattice.cell_size;
  const double km2 = double(plan.mine.size()) * chunk_m * chunk_m * 1e-6;
  if (!common.json) {
    std::printf("baked shard %d/%d: %zu of %zu columns, %zu mixed chunks, %zu files (mesh %" PRIu64 " B, nav %" PRIu64
                " B, voxels %" PRIu64 " B) in %.2f s\n  manifest: %s\n",
                si, sn, plan.mine.size(), plan.all.size(), sum.mixed, sum.files, sum.bytes[0], sum.bytes[1],
                sum.bytes[2], times.total, manifest_path.string().c_str());
    return;
  }
  nlohmann::json report = {{"shard", si},
                           {"shards", sn},
                           {"skipped", false},
                           {"units", plan.mine.size()},
                           {"units_total", plan.all.size()},
                           {"cost", plan.mine_cost},
                           {"mixed_chunks", sum.mixed},
                           {"files", sum.files},
                           {"area_km2", km2},
                           {"bytes", {{"mesh", sum.bytes[0]}, {"nav", sum.bytes[1]}, {"voxels", sum.bytes[2]}}},
                           {"seconds",
                            {{"total", times.total},
                             {"plan", times.plan},
                             {"bake_wall", times.bake_wall},
                             {"window_cpu", sum.seconds[0]},
                             {"mesh_cpu", sum.seconds[1]},
                             {"nav_cpu", sum.seconds[2]},
                             {"voxels_cpu", sum.seconds[3]}}}};
  std::printf("%s\n", json_text(with_warnings(report)).c_str());
}

Status check_lods(int lods, int chunk_size) {
  if (lods >= 1 && lods <= max_lod_level(chunk_size) + 1) return Status();
  return Status(ErrorCode::kInvalidArgument,
                "--lods " + std::to_string(lods) + ": 1 .. " + std::to_string(max_lod_level(chunk_size) + 1) +
                    " for chunks of " + std::to_string(chunk_size) +
                    " cells (level k keeps every 2^k-th ray; coarse chunks keep at least 8 cells)");
}

int run_bake(const BakeArgs& a, const CommonOptions& common) {
  const std::string cmd = "bake";
  set_thread_count(common.threads);
  if (a.out.empty()) return fail(cmd, "--out DIR is required (or give --merge DIR)");
  if (a.shard.empty()) return fail(cmd, "--shard i/N is required (0/1 bakes everything in one process)");
  Result<std::pair<int, int>> shard = parse_shard(a.shard);
  if (!shard.ok()) return fail(cmd, shard.status());
  const int si = shard.value().first, sn = shard.value().second;
  Result<Products> products = parse_products(a.products);
  if (!products.ok()) return fail(cmd, products.status());
  ScopedTimer total(nullptr, "");
  Result<BakeWorld> world = open_bake_world(a);
  if (!world.ok()) return fail(cmd, world.status());
  const fs::path out(a.out);
  const SourceLayout layout = world.value().source->layout();
  if (Status s = check_lods(a.lods, layout.chunk_size); !s.ok()) return fail(cmd, s.message());
  const std::string product_list = join(products.value().names());
  if (Status s = check_same_world(out, world.value().id, product_list, sn, a.lods, a.mesh_format); !s.ok())
    return fail(cmd, s);
  const fs::path dir = out / "shards" / std::to_string(si);
  std::optional<int> refusal;
  if (finished_shard(out, dir, si, sn, common, &refusal)) return kExitSuccess;
  if (refusal) return *refusal;
  ScopedTimer tplan(nullptr, "");
  const ShardPlan plan = plan_shard(world.value(), si, sn);
  const double plan_seconds = tplan.seconds();
  std::vector<std::string> folders = {"mesh", "nav", "voxels"};
  for (int level = 1; level < a.lods; ++level) folders.push_back("mesh/lod" + std::to_string(level));
  for (const std::string& sub : folders) {
    std::error_code ec;
    fs::create_directories(dir / sub, ec);
    if (ec) return fail(cmd, (dir / sub).string() + ": cannot create the folder (" + ec.message() + ")");
  }
  ScopedTimer tbake(nullptr, "");
  const std::vector<UnitResult> results = bake_units(a, world.value(), plan, products.value(), dir, common);
  const double bake_seconds = tbake.seconds();
  Result<ShardTotals> t = shard_totals(plan, results);
  if (!t.ok()) return fail(cmd, t.status().message());
  const fs::path manifest_path = dir / "manifest.json";
  const nlohmann::json manifest = shard_manifest(a, world.value(), plan, t.value(), products.value(), si, sn);
  if (Status s = write_file_atomically(manifest_path.string(), json_text(manifest, 1) + "\n"); !s.ok()) return fail(cmd, s);
  print_shard_report(plan, t.value(), layout, si, sn, {total.seconds(), plan_seconds, bake_seconds}, manifest_path,
                     common);
  return kExitSuccess;
}

// --- Merge ----------------------------------------------------------------------

// The merge's helpers return their error as fail() prints it: a message of
// their own, or a Status's to_string() (its code named).

// The shard folders under DIR/shards, by number.
std::optional<std::string> shard_folders(const fs::path& out, std::map<long long, fs::path>& found) {
  std::error_code ec;
  if (!fs::is_directory(out / "shards", ec)) return (out / "shards").string() + ": no shards folder (nothing baked here)";
  for (const auto& e : fs::directory_iterator(out / "shards", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos || name.size() > 9)
      return e.path().string() + ": not a shard folder (expected a shard number)";
    found[std::stoll(name)] = e.path();
  }
  if (found.empty()) return (out / "shards").string() + ": no shards";
  return std::nullopt;
}

// What every shard of one bake agrees on, from the first manifest read.
struct ShardSet {
  std::string world_id;
  std::vector<std::string> products;
  int n = -1, lods = 1;
  std::string mesh_format;
  std::vector<nlohmann::json> manifests;  // in shard order
};

// One shard's manifest against the set (the first one sets it), and its files' checksums.
std::optional<std::string> check_shard_manifest(const nlohmann::json& j, const fs::path& path, long long index,
                                                ShardSet& set) {
  const std::string m = (path / "manifest.json").string();
  if (j.value("format", std::string()) != kShardFormat) return m + ": not a bake shard manifest";
  const int shards = j.value("shards", -1);
  if (shards <= 0) return m + ": N = " + std::to_string(shards) + " (the shard count must be at least 1)";
  if (j.value("shard", -1) != index)
    return m + " says shard " + std::to_string(j.value("shard", -1)) + ", but lies in folder " + std::to_string(index);
  if (set.n < 0) {
    set.n = shards;
    set.world_id = j.value("world", std::string());
    set.products = j.value("products", std::vector<std::string>());
    set.lods = j.value("lods", 1);
    set.mesh_format = j.value("mesh_format", std::string("glb"));
  }
  if (shards != set.n) return m + ": a bake in " + std::to_string(shards) + " shards, the others in " + std::to_string(set.n);
  if (index >= set.n)
    return path.string() + ": shard index " + std::to_string(index) + " out of range for " + std::to_string(set.n) +
           " shards (0 .. " + std::to_string(set.n - 1) + ")";
  if (j.value("world", std::string()) != set.world_id)
    return m + ": shard of another world ('" + j.value("world", std::string()) + "', not '" + set.world_id + "')";
  if (j.value("products", std::vector<std::string>()) != set.products) return m + ": shard of other products";
  if (j.value("lods", 1) != set.lods)
    return m + ": a bake of " + std::to_string(j.value("lods", 1)) + " mesh levels, the others of " +
           std::to_string(set.lods);
  if (j.value("mesh_format", std::string("glb")) != set.mesh_format)
    return m + ": a bake of ." + j.value("mesh_format", std::string("glb")) + " meshes, the others of ." + set.mesh_format;
  if (Status s = check_files(path, j, nullptr); !s.ok()) return s.to_string();
  return std::nullopt;
}

// Every shard's manifest, checked; then that no shard is missing.
std::optional<std::string> read_shard_set(const fs::path& out, const std::map<long long, fs::path>& found,
                                          ShardSet& set) {
  std::error_code ec;
  for (const auto& [index, path] : found) {
    if (!fs::exists(path / "manifest.json", ec))
      return "shard " + std::to_string(index) + " is not finished: " + (path / "manifest.json").string() +
             " is missing (re-run that shard)";
    Result<nlohmann::json> m = read_json(path / "manifest.json");
    if (!m.ok()) return m.status().to_string();
    if (auto error = check_shard_manifest(m.value(), path, index, set)) return error;
    set.manifests.push_back(m.value());
  }
  for (int i = 0; i < set.n; ++i)
    if (!found.count(i))
      return "shard " + std::to_string(i) + "/" + std::to_string(set.n) + " is missing (" +
             (out / "shards" / std::to_string(i)).string() + "); re-run it before merging";
  return std::nullopt;
}

// Each shard's files linked (or copied) to DIR/<name>, its units appended in
// column order (each shard's are contiguous and in order).
std::optional<std::string> link_shard_files(const fs::path& out, const ShardSet& set, nlohmann::json& units,
                                            size_t& files, uint64_t& bytes) {
  std::error_code ec;
  for (int i = 0; i < set.n; ++i) {
    for (const auto& u : set.manifests[size_t(i)].at("units")) {
      units.push_back(u);
      for (const auto& f : u.at("files")) {
        const std::string name = f.at("name").get<std::string>();
        const fs::path target = out / name, source = out / "shards" / std::to_string(i) / name;
        fs::create_directories(target.parent_path(), ec);
        fs::remove(target, ec);
        fs::create_hard_link(source, target, ec);
        if (ec) {
          ec.clear();
          fs::copy_file(source, target, fs::copy_options::overwrite_existing, ec);
          if (ec) return target.string() + ": cannot link or copy (" + ec.message() + ")";
        }
        ++files;
        bytes += f.at("bytes").get<uint64_t>();
      }
    }
  }
  return std::nullopt;
}

int run_merge(const BakeArgs& a, const CommonOptions& common) {
  const std::string cmd = "bake --merge";
  const fs::path out(a.merge);
  std::map<long long, fs::path> found;
  if (auto error = shard_folders(out, found)) return fail(cmd, *error);
  ShardSet set;
  if (auto error = read_shard_set(out, found, set)) return fail(cmd, *error);
  if (Status s = check_same_world(out, set.world_id, join(set.products), set.n, set.lods, set.mesh_format); !s.ok())
    return fail(cmd, s);
  nlohmann::json units = nlohmann::json::array();
  size_t files = 0;
  uint64_t bytes = 0;
  if (auto error = link_shard_files(out, set, units, files, bytes)) return fail(cmd, *error);
  const nlohmann::json& first = set.manifests[0];
  const int64_t units_total = first.value("units_total", int64_t{0});
  if (int64_t(units.size()) != units_total)
    return fail(cmd, "the shards hold " + std::to_string(units.size()) + " columns, the plan " + std::to_string(units_total));
  // The index does not depend on N: the same world baked in any number of
  // shards gives the same index.json, and the same files beside it.
  nlohmann::json index = {{"format", kIndexFormat},
                          {"world", set.world_id},
                          {"products", set.products},
                          {"lods", set.lods},
                          {"mesh_format", set.mesh_format},
                          {"chunk_size", first.value("chunk_size", 0)},
                          {"cell_size", first.value("cell_size", 0.0)},
                          {"units", units}};
  if (Status s = write_file_atomically((out / "index.json").string(), json_text(index, 1) + "\n"); !s.ok()) return fail(cmd, s);
  if (common.json)
    std::printf("%s\n", json_text(with_warnings({{"shards", set.n}, {"units", units.size()}, {"files", files}, {"bytes", bytes}, {"index", (out / "index.json").string()}})).c_str());
  else
    std::printf("merged %d shards: %zu columns, %zu files, %" PRIu64 " bytes, every checksum verified\n  index: %s\n", set.n,
                units.size(), files, bytes, (out / "index.json").string().c_str());
  return kExitSuccess;
}

}  // namespace

void add_bake_command(CLI::App& app, CommonOptions& common) {
  auto a = std::make_shared<BakeArgs>();
  CLI::App* bake = app.add_subcommand(
      "bake", "Offline bake of a large world's per-chunk products, one shard of a job array at a time; --merge checks and indexes them");
  bake->add_option("world", a->world,
                   "World: a .ldcs store, an .ldc world, a file holding a base description "
                   "(terrain_source_description), or that text");
  bake->add_option("--out", a->out, "Output folder (shards go to DIR/shards/i/)");
  bake->add_option("--shard", a->shard, "This process's shard i/N (0/1: the whole world)");
  bake->add_option("--products", a->products, "Products, comma-separated: mesh, nav, voxels")->capture_default_str();
  bake->add_option("--mesh-format", a->mesh_format, "Chunk meshes as glb (binary glTF) or drc (Draco)")
      ->check(CLI::IsMember({"glb", "drc"}))
      ->capture_default_str();
  bake->add_option("--lods", a->lods,
                   "Mesh levels per chunk: 1 = full detail only; N adds levels 1 .. N-1 (every 2^k-th ray) under "
                   "mesh/lod<k>/ (at most 2, 3, 4 for chunks of 16, 32, 64 cells)")
      ->capture_default_str();
  bake->add_option("--merge", a->merge, "Check every shard's manifest in DIR and write DIR/index.json");
  bake->add_option("--terrain-size", a->terrain_size, "Procedural world instead of WORLD: the landscape of X,Y metres");
  bake->add_option("--cell-size", a->cell_size, "With --terrain-size: cell size h [m]")->capture_default_str();
  bake->add_option("--chunk-size", a->chunk_size, "With --terrain-size: chunk size C (8, 16, 32, 64)")->capture_default_str();
  bake->add_option("--seed", a->seed, "With --terrain-size: the landscape's seed")->capture_default_str();
  bake->callback([a, &common] {
    int code;
    if (!a->merge.empty()) {
      code = (a->world.empty() && a->out.empty() && a->shard.empty() && a->terrain_size.empty())
                 ? run_merge(*a, common)
                 : fail("bake", "--merge DIR takes no WORLD, --out, --shard or --terrain-size");
    } else {
      code = run_bake(*a, common);
    }
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
