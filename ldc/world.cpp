#include "ldc/world.h"

#include <atomic>
#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

#include "ldc/internal/lattice_range.h"
#include "ldc/internal/ray_math.h"
#include "ldc/internal/vec_text.h"

namespace ldc {

const char* axis_name(int a) {
  static const char* names[] = {"x", "y", "z"};
  return (a >= 0 && a < 3) ? names[a] : "?";
}

const char* chunk_kind_name(ChunkKind kind) {
  switch (kind) {
    case ChunkKind::kEmpty: return "empty";
    case ChunkKind::kSolid: return "solid";
    case ChunkKind::kMixed: return "mixed";
  }
  return "?";
}

// ---------------------------------------------------------------------------
// RayFamily

RayFamily RayFamily::uniform(bool inside) {
  RayFamily f;
  f.uniform_inside_ = inside;
  return f;
}

bool RayFamily::starts_inside(int ray) const {
  if (is_uniform()) return uniform_inside_;
  if (!inside_.empty()) return (inside_[static_cast<size_t>(ray) >> 6] >> (ray & 63)) & 1u;
  const uint32_t code = ray_code(ray);
  if (code < kOnePoint) return code == kEmptyInside;
  return (points_[first_point(ray)].normal & kPointExitBit) != 0;
}

// Popcounts over the codes of the rays of `ray`'s row before it when the
// row spans two words (C = 64; smaller rows take row_prefix's one-word path).
RayFamily::RowPrefix RayFamily::wide_row_prefix(int ray) const {
  RowPrefix r;
  size_t bit = size_t(ray / size_) * size_ * 2;
  const size_t end = size_t(ray) * 2;
  while (bit < end) {
    const size_t n = std::min<size_t>(64 - (bit & 63), end - bit);
    uint64_t x = codes_[bit >> 6] >> (bit & 63);
    if (n < 64) x &= (uint64_t{1} << n) - 1;
    const RowPrefix part = code_counts(x);
    r.single += part.single, r.several += part.several;
    bit += n;
  }
  return r;
}

uint32_t RayFamily::several_count(int ray) const {
  return several_[row_several(size_t(ray / size_)) + row_prefix(ray).several];
}

uint32_t RayFamily::first_point(int ray) const { return first_point(ray, {}); }

uint32_t RayFamily::first_point(int ray, std::span<uint32_t> counts) const {
  if (is_uniform()) {
    std::fill(counts.begin(), counts.end(), 0u);
    return 0;
  }
  if (!first_.empty()) {
    for (size_t k = 0; k < counts.size(); ++k) counts[k] = first_[size_t(ray) + k + 1] - first_[size_t(ray) + k];
    return first_[size_t(ray)];
  }
  const size_t row = size_t(ray / size_);
  const RowPrefix before = row_prefix(ray);
  const uint8_t* several = several_.data() + row_several(row);
  uint32_t begin = row_first(row) + before.single;
  for (uint32_t k = 0; k < before.several; ++k) begin += *several++;
  for (size_t k = 0; k < counts.size(); ++k) {
    const uint32_t code = ray_code(ray + int(k));
    counts[k] = code < kOnePoint ? 0u : code == kOnePoint ? 1u : *several++;
  }
  return begin;
}

RayPoints RayReader::next() {
  const RayFamily& f = family_;
  const int ray = ray_++;
  if (f.is_uniform()) return {f.uniform_inside_, {}};
  uint32_t n = 0;
  if (!f.first_.empty()) {
    n = f.first_[size_t(ray) + 1] - f.first_[size_t(ray)];
  } else {
    const uint32_t code = f.ray_code(ray);
    n = code < RayFamily::kOnePoint ? 0u : code == RayFamily::kOnePoint ? 1u : f.several_[several_++];
  }
  const std::span<const PackedPoint> points(f.points_.data() + first_, n);
  first_ += n;
  return {f.starts_inside(ray, points), points};
}

RayPoints RayReader::next_at(int ray) {
  assert(ray >= ray_);
  const RayFamily& f = family_;
  if (!f.is_uniform() && f.first_.empty()) {
    for (; ray_ < ray; ++ray_) {
      const uint32_t code = f.ray_code(ray_);
      first_ += code < RayFamily::kOnePoint ? 0u : code == RayFamily::kOnePoint ? 1u : f.several_[several_++];
    }
  } else if (!f.is_uniform()) {
    first_ = f.first_[size_t(ray)];
  }
  ray_ = ray;
  return next();
}

std::span<const PackedPoint> RayFamily::points(int ray) const {
  uint32_t count = 0;
  const uint32_t first = first_point(ray, std::span<uint32_t>(&count, 1));
  return std::span<const PackedPoint>(points_.data() + first, count);
}

std::vector<uint64_t> RayFamily::start_bits() const {
  if (is_uniform()) return {};
  if (!inside_.empty()) return inside_;
  const int rays = int(size_) * size_;
  std::vector<uint64_t> bits((size_t(rays) + 63) / 64, 0);
  uint32_t first = 0;
  for (int r = 0; r < rays; ++r) {
    const uint32_t n = point_count(r);
    if (starts_inside(r, std::span<const PackedPoint>(points_.data() + first, n))) bits[size_t(r) >> 6] |= uint64_t{1} << (r & 63);
    first += n;
  }
  return bits;
}

size_t RayFamily::memory_bytes() const {
  return codes_.capacity() * sizeof(uint64_t) + several_.capacity() +
         first_.capacity() * sizeof(uint32_t) + rows_.capacity() * sizeof(uint16_t) +
         inside_.capacity() * sizeof(uint64_t) + points_.capacity() * sizeof(PackedPoint);
}

std::string RayFamily::check_structure() const {
  if (is_uniform()) return {};
  const size_t c = size_, rays = c * c;
  if (!first_.empty()) {
    if (inside_.size() != (rays + 63) / 64) return "start-bit array has the wrong size";
    if (first_.size() != rays + 1 || first_[0] != 0 || first_[rays] != points_.size()) {
      return "ray offsets do not cover the point array";
    }
    for (size_t r = 0; r < rays; ++r) {
      if (first_[r + 1] < first_[r]) return "ray offsets decrease at ray " + std::to_string(r);
    }
    return {};
  }
  if (!inside_.empty() && inside_.size() != (rays + 63) / 64) return "start-bit array has the wrong size";
  if (codes_.size() != (2 * rays + 63) / 64 || rows_.size() != 2 * (c + 1)) {
    return "count arrays have the wrong size";
  }
  for (uint8_t n : several_) {
    if (n < 2) return "a ray coded as holding several points holds fewer than two";
  }
  for (size_t row = 0; row < c; ++row) {
    uint32_t end = row_first(row);
    size_t several = row_several(row);
    for (size_t r = row * c; r < (row + 1) * c; ++r) {
      const uint32_t code = ray_code(int(r));
      if (code == kSeveral && several >= several_.size()) return "several-point counts run out at ray " + std::to_string(r);
      end += code < kOnePoint ? 0u : code == kOnePoint ? 1u : several_[several];
      several += code == kSeveral;
      if (!inside_.empty() && code < kOnePoint && bool(code & 1u) != bool((inside_[r >> 6] >> (r & 63)) & 1u)) {
        return "an empty ray's code and start bit disagree at ray " + std::to_string(r);
      }
    }
    if (row_first(row + 1) != end) return "row offsets disagree with counts at row " + std::to_string(row);
    if (row_several(row + 1) != several) return "several-point offsets disagree with codes at row " + std::to_string(row);
  }
  if (row_first(0) != 0 || row_first(c) != points_.size()) return "row offsets do not cover the point array";
  if (row_several(0) != 0 || row_several(c) != several_.size()) return "several-point offsets do not cover the counts";
  return {};
}

RayFamilyWriter::RayFamilyWriter(int chunk_size) : chunk_size_(chunk_size) {
  const size_t rays = static_cast<size_t>(chunk_size) * chunk_size;
  first_.reserve(rays + 1);
  inside_.assign((rays + 63) / 64, 0);
}

void RayFamilyWriter::begin_ray(bool starts_inside) {
  assert(rays_ < chunk_size_ * chunk_size_);
  first_.push_back(static_cast<uint32_t>(points_.size()));
  if (starts_inside) {
    inside_[static_cast<size_t>(rays_) >> 6] |= uint64_t{1} << (rays_ & 63);
    any_inside_ = true;
  } else {
    any_outside_ = true;
  }
  ++rays_;
}

// The compact form's arrays from the per-ray offsets; keeps the start bits
// only where a ray's first point disagrees with its start.
void RayFamilyWriter::fill_compact(RayFamily& f) {
  const size_t c = size_t(chunk_size_), rays = c * c;
  f.codes_.assign((2 * rays + 63) / 64, 0);
  f.rows_.resize(2 * (c + 1));
  bool starts_agree = true;
  for (size_t r = 0; r < rays; ++r) {
    if (r % c == 0) f.rows_[2 * (r / c)] = uint16_t(first_[r]), f.rows_[2 * (r / c) + 1] = uint16_t(f.several_.size());
    const uint32_t n = first_[r + 1] - first_[r];
    const bool inside = (inside_[r >> 6] >> (r & 63)) & 1u;
    uint64_t code = inside ? RayFamily::kEmptyInside : RayFamily::kEmptyOutside;
    if (n > 0) {
      code = n == 1 ? RayFamily::kOnePoint : RayFamily::kSeveral;
      if (n > 1) f.several_.push_back(uint8_t(n));
      starts_agree = starts_agree && inside == ((points_[first_[r]].normal & kPointExitBit) != 0);
    }
    f.codes_[r >> 5] |= code << ((r & 31) * 2);
  }
  f.rows_[2 * c] = uint16_t(first_[rays]);
  f.rows_[2 * c + 1] = uint16_t(f.several_.size());
  f.several_.shrink_to_fit();
  if (!starts_agree) f.inside_ = std::move(inside_);
}

RayFamily RayFamilyWriter::finish() {
  const int c = chunk_size_;
  assert(rays_ == c * c);
  if (points_.empty() && !(any_inside_ && any_outside_)) return RayFamily::uniform(any_inside_);
  RayFamily f;
  f.size_ = static_cast<uint8_t>(c);
  first_.push_back(static_cast<uint32_t>(points_.size()));
  uint32_t most = 0;
  for (int r = 0; r < c * c; ++r) most = std::max(most, first_[r + 1] - first_[r]);
  if (most <= 255 && points_.size() <= 65535) {  // the compact form's offsets are 16-bit
    fill_compact(f);
  } else {
    f.first_ = std::move(first_);
    f.inside_ = std::move(inside_);
  }
  points_.shrink_to_fit();
  f.points_ = std::move(points_);
  return f;
}

// ---------------------------------------------------------------------------
// Chunk

bool Chunk::is_uniform(bool* inside) const {
  for (const RayFamily& f : axis) {
    if (!f.is_uniform()) return false;
  }
  bool in = axis[0].uniform_inside();
  if (axis[1].uniform_inside() != in || axis[2].uniform_inside() != in) return false;
  if (inside) *inside = in;
  return true;
}

size_t Chunk::point_count() const {
  return axis[0].point_count() + axis[1].point_count() + axis[2].point_count();
}

size_t Chunk::memory_bytes() const {
  return sizeof(Chunk) + axis[0].memory_bytes() + axis[1].memory_bytes() +
         axis[2].memory_bytes();
}

// ---------------------------------------------------------------------------
// World

namespace {

bool is_allowed_chunk_size(int c) { return c == 8 || c == 16 || c == 32 || c == 64; }

Status check_world_config(const WorldConfig& config) {
  const Lattice& lat = config.lattice;
  if (!(lat.cell_size > 0.0) || !std::isfinite(lat.cell_size)) {
    return {ErrorCode::kInvalidArgument,
            "world: cell_size = " + std::to_string(lat.cell_size) + " must be finite and > 0"};
  }
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(lat.origin[a])) {
      return {ErrorCode::kInvalidArgument,
              std::string("world: origin.") + axis_name(a) + " is not finite"};
    }
  }
  if (!is_allowed_chunk_size(config.chunk_size)) {
    return {ErrorCode::kInvalidArgument, "world: chunk_size = " +
                                             std::to_string(config.chunk_size) +
                                             " must be 8, 16, 32 or 64"};
  }
  int64_t slots = 1;
  for (int a = 0; a < 3; ++a) {
    int64_t dim = config.chunk_dims[a];
    if (dim < 1) {
      return {ErrorCode::kInvalidArgument, std::string("world: chunk_dims.") + axis_name(a) +
                                               " = " + std::to_string(dim) + " must be >= 1"};
    }
    int64_t lo = int64_t{config.chunk_origin[a]} * config.chunk_size;
    int64_t hi = (int64_t{config.chunk_origin[a]} + dim) * config.chunk_size;
    if (lo < -kMaxNodeCoordinate || hi > kMaxNodeCoordinate) {
      return {ErrorCode::kTooLarge,
              std::string("world: node range on ") + axis_name(a) + " [" + std::to_string(lo) +
                  ", " + std::to_string(hi) + ") exceeds +-" + std::to_string(kMaxNodeCoordinate)};
    }
    slots *= dim;
    if (slots > kMaxChunkSlots) {
      return {ErrorCode::kTooLarge, "world: more than " + std::to_string(kMaxChunkSlots) +
                                        " chunk slots requested"};
    }
  }
  return detail::check_lattice_range(config, "world");
}

}  // namespace

namespace detail {

double min_cell_size_at(double magnitude) {
  const double ulp = std::nextafter(magnitude, INFINITY) - magnitude;
  return std::max(kMinCellUlps * ulp, kMinLatticeCellSize);
}

Status check_lattice_range(const WorldConfig& config, std::string_view what) {
  const std::string prefix = std::string(what) + ": ";
  const double h = config.lattice.cell_size;
  const glm::dvec3 node_lo = glm::dvec3(config.chunk_origin) * double(config.chunk_size);
  const glm::dvec3 node_hi = glm::dvec3(config.chunk_origin + config.chunk_dims) * double(config.chunk_size);
  const glm::dvec3 lo = config.lattice.origin + h * node_lo, hi = config.lattice.origin + h * node_hi;
  if (!is_finite(lo) || !is_finite(hi)) {
    return {ErrorCode::kInvalidArgument, prefix + "the lattice's box " + vec_text(lo) + " .. " + vec_text(hi) +
                                             " is not finite (cell size " + number_g(h) + " m)"};
  }
  const glm::dvec3 reach = glm::max(glm::abs(lo), glm::abs(hi));
  const double magnitude = std::max(reach.x, std::max(reach.y, reach.z));
  if (magnitude > kMaxLatticeCoordinate) {
    return {ErrorCode::kTooLarge, prefix + "the lattice's box " + vec_text(lo) + " .. " + vec_text(hi) +
                                      " reaches " + number_g(magnitude) + " m, past the limit of " +
                                      number_g(kMaxLatticeCoordinate) + " m"};
  }
  const double least = min_cell_size_at(magnitude);
  if (h < least) {
    return {ErrorCode::kInvalidArgument,
            prefix + "cell size " + number_g(h) + " m is below the limit of " + number_g(least) +
                " m for coordinates up to " + number_g(magnitude) + " m (" + number_g(kMinCellUlps) +
                " units in the last place there, and at least " + number_g(kMinLatticeCellSize) +
                " m): doubles cannot place points within such a cell"};
  }
  return {};
}

}  // namespace detail

void ContentStamp::renew() {
  static std::atomic<uint64_t> next{1};
  value_.store(next.fetch_add(1, std::memory_order_relaxed), std::memory_order_relaxed);
}

World::World() : World(WorldConfig{}) {}

World::World(const WorldConfig& config) : config_(config) {
  size_t slots = static_cast<size_t>(config.chunk_dims.x) * config.chunk_dims.y *
                 config.chunk_dims.z;
  kinds_.assign(slots, ChunkKind::kEmpty);
  chunks_.resize(slots);
}

Result<World> World::create(const WorldConfig& config) {
  Status s = check_world_config(config);
  if (!s.ok()) return s;
  return World(config);
}

WorldBox World::box() const {
  return {lattice().node_position(node_min()), lattice().node_position(node_end())};
}

bool World::contains_chunk(const glm::ivec3& c) const {
  glm::ivec3 r = c - config_.chunk_origin;
  return r.x >= 0 && r.y >= 0 && r.z >= 0 && r.x < config_.chunk_dims.x &&
         r.y < config_.chunk_dims.y && r.z < config_.chunk_dims.z;
}

size_t World::chunk_slot(const glm::ivec3& c) const {
  glm::ivec3 r = c - config_.chunk_origin;
  return (static_cast<size_t>(r.z) * config_.chunk_dims.y + r.y) * config_.chunk_dims.x + r.x;
}

ChunkKind World::chunk_kind(const glm::ivec3& c) const {
  return contains_chunk(c) ? kinds_[chunk_slot(c)] : ChunkKind::kEmpty;
}

const Chunk* World::chunk(const glm::ivec3& c) const {
  return contains_chunk(c) ? chunks_[chunk_slot(c)].get() : nullptr;
}

std::shared_ptr<const Chunk> World::chunk_shared(const glm::ivec3& c) const {
  return contains_chunk(c) ? chunks_[chunk_slot(c)] : nullptr;
}

Status World::grow_to_include(const glm::ivec3& lo, const glm::ivec3& hi) {
  WorldConfig grown = config_;
  grown.chunk_origin = glm::min(config_.chunk_origin, lo);
  grown.chunk_dims = glm::max(config_.chunk_origin + config_.chunk_dims, hi) - grown.chunk_origin;
  if (grown.chunk_origin == config_.chunk_origin && grown.chunk_dims == config_.chunk_dims) return {};
  Status s = check_world_config(grown);
  if (!s.ok()) return s;
  World bigger(grown);
  for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk*) {
    size_t to = bigger.chunk_slot(ch), from = chunk_slot(ch);
    bigger.kinds_[to] = kind;
    bigger.chunks_[to] = chunks_[from];
  });
  config_ = grown;
  kinds_ = std::move(bigger.kinds_);
  chunks_ = std::move(bigger.chunks_);
  stamp_.renew();
  return {};
}

void World::set_chunk(const glm::ivec3& c, std::shared_ptr<const Chunk> data) {
  assert(contains_chunk(c));
  bool inside = false;
  if (!data || data->is_uniform(&inside)) {
    set_uniform_chunk(c, data ? inside : false);
    return;
  }
  size_t slot = chunk_slot(c);
  kinds_[slot] = ChunkKind::kMixed;
  chunks_[slot] = std::move(data);
  stamp_.renew();
}

void World::set_uniform_chunk(const glm::ivec3& c, bool solid) {
  assert(contains_chunk(c));
  size_t slot = chunk_slot(c);
  kinds_[slot] = solid ? ChunkKind::kSolid : ChunkKind::kEmpty;
  chunks_[slot].reset();
  stamp_.renew();
}

void World::for_each_chunk(
    const std::function<void(const glm::ivec3&, ChunkKind, const Chunk*)>& fn) const {
  const glm::ivec3 d = config_.chunk_dims;
  size_t slot = 0;
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x, ++slot)
        fn(config_.chunk_origin + glm::ivec3(x, y, z), kinds_[slot], chunks_[slot].get());
}

// Start state of a ray's segment in one chunk along the axis.
bool World::ray_starts_inside(int axis, const glm::ivec2& uv, int chunk_along) const {
  const int c = config_.chunk_size;
  glm::ivec3 node(0);
  node[axis] = chunk_along * c;
  node[axis_u(axis)] = uv.x;
  node[axis_v(axis)] = uv.y;
  glm::ivec3 ch = chunk_of_node(node);
  ChunkKind kind = chunk_kind(ch);
  if (kind != ChunkKind::kMixed) return kind == ChunkKind::kSolid;
  int ray = detail::ray_index(node, axis, c);
  return chunk(ch)->axis[axis].starts_inside(ray);
}

bool World::inside_node(const glm::ivec3& node) const {
  const int c = config_.chunk_size;
  glm::ivec3 ch = chunk_of_node(node);
  ChunkKind kind = chunk_kind(ch);
  if (kind != ChunkKind::kMixed) return kind == ChunkKind::kSolid;
  const RayFamily& f = chunk(ch)->axis[0];
  int ray = detail::ray_index(node, 0, c);
  uint32_t node_steps = static_cast<uint32_t>(node.x - ch.x * c) * depth_steps_per_cell(c);
  bool in = f.starts_inside(ray);
  for (const PackedPoint& p : f.points(ray)) {
    if (p.depth > node_steps) break;
    in = !in;
  }
  return in;
}

bool World::inside(const glm::dvec3& p) const {
  const int c = config_.chunk_size;
  const double steps = depth_steps_per_cell(c);
  glm::dvec3 q = lattice().to_lattice(p);
  int votes = 0;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(q[a])) return false;
    glm::ivec3 node;
    node[a] = static_cast<int>(std::floor(std::clamp(q[a], -1e9, 1e9)));
    node[axis_u(a)] = static_cast<int>(std::lround(std::clamp(q[axis_u(a)], -1e9, 1e9)));
    node[axis_v(a)] = static_cast<int>(std::lround(std::clamp(q[axis_v(a)], -1e9, 1e9)));
    glm::ivec3 ch = chunk_of_node(node);
    ChunkKind kind = chunk_kind(ch);
    bool in = kind == ChunkKind::kSolid;
    if (kind == ChunkKind::kMixed) {
      const RayFamily& f = chunk(ch)->axis[a];
      int ray = detail::ray_index(node, a, c);
      double local = (q[a] - double(ch[a]) * c) * steps;
      in = f.starts_inside(ray);
      for (const PackedPoint& pt : f.points(ray)) {
        if (pt.depth > local) break;
        in = !in;
      }
    }
    votes += in ? 1 : 0;
  }
  return votes >= 2;
}

std::vector<SurfacePoint> World::ray_points(int axis, const glm::ivec2& uv) const {
  std::vector<SurfacePoint> out;
  const int c = config_.chunk_size;
  glm::ivec3 node(0);
  node[axis_u(axis)] = uv.x;
  node[axis_v(axis)] = uv.y;
  for (int k = 0; k < config_.chunk_dims[axis]; ++k) {
    int along = config_.chunk_origin[axis] + k;
    node[axis] = along * c;
    glm::ivec3 ch = chunk_of_node(node);
    const Chunk* data = chunk(ch);
    if (!data) continue;
    int ray = detail::ray_index(node, axis, c);
    for (const PackedPoint& p : data->axis[axis].points(ray)) {
      out.push_back(decode_point(p, c, along * c));
    }
  }
  return out;
}

std::vector<Span> World::ray_spans(int axis, const glm::ivec2& uv) const {
  std::vector<SurfacePoint> pts = ray_points(axis, uv);
  std::vector<Span> spans;
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    if (pts[i].enter && !pts[i + 1].enter) {
      spans.push_back({pts[i], pts[i + 1]});
      ++i;
    }
  }
  return spans;
}

namespace {

// Inside length (cells) of one ray segment of a chunk (callers walk the
// rays in order with a RayReader: random access sums a row's offsets).
double segment_inside_length(const RayPoints& ray, int chunk_size) {
  const double steps = depth_steps_per_cell(chunk_size);
  bool in = ray.starts_inside;
  double last = 0.0, sum = 0.0;
  for (const PackedPoint& p : ray.points) {
    double d = p.depth / steps;
    if (in) sum += d - last;
    last = d;
    in = !in;
  }
  if (in) sum += chunk_size - last;
  return sum;
}

}  // namespace

double World::volume(int axis) const {
  const int c = config_.chunk_size;
  const double h = lattice().cell_size;
  double cells = 0.0;
  for (size_t slot = 0; slot < kinds_.size(); ++slot) {
    if (kinds_[slot] == ChunkKind::kSolid) cells += double(c) * c * c;
    if (kinds_[slot] != ChunkKind::kMixed) continue;
    const RayFamily& f = chunks_[slot]->axis[axis];
    RayReader rays(f);
    for (int r = 0; r < c * c; ++r) cells += segment_inside_length(rays.next(), c);
  }
  return cells * h * h * h;
}

std::optional<WorldBox> World::solid_bounds() const {
  const int c = config_.chunk_size;
  glm::dvec3 lo(std::numeric_limits<double>::infinity());
  glm::dvec3 hi(-std::numeric_limits<double>::infinity());
  for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* data) {
    if (kind == ChunkKind::kSolid) {
      lo = glm::min(lo, glm::dvec3(ch * c));
      hi = glm::max(hi, glm::dvec3((ch + 1) * c));
    }
    if (!data) return;
    for (int a = 0; a < 3; ++a) {
      const RayFamily& f = data->axis[a];
      RayReader rays(f);
      for (int r = 0; r < c * c; ++r) {
        for (const PackedPoint& p : rays.next().points) {
          glm::dvec3 q = detail::point_lattice_position(ch, a, r, p.depth, c);
          lo = glm::min(lo, q);
          hi = glm::max(hi, q);
        }
      }
    }
  });
  if (!(lo.x <= hi.x)) return std::nullopt;
  return WorldBox{lattice().to_world(lo), lattice().to_world(hi)};
}

WorldStats World::stats() const {
  WorldStats s;
  s.chunks_total = kinds_.size();
  s.memory_bytes = sizeof(World) + kinds_.capacity() * sizeof(ChunkKind) +
                   chunks_.capacity() * sizeof(std::shared_ptr<const Chunk>);
  const size_t rays_per_family = size_t(chunk_size()) * chunk_size();
  for (size_t slot = 0; slot < kinds_.size(); ++slot) {
    switch (kinds_[slot]) {
      case ChunkKind::kEmpty: ++s.chunks_empty; break;
      case ChunkKind::kSolid: ++s.chunks_solid; break;
      case ChunkKind::kMixed: {
        ++s.chunks_mixed;
        const Chunk& ch = *chunks_[slot];
        s.points += ch.point_count();
        s.memory_bytes += ch.memory_bytes() + 2 * sizeof(void*);  // shared_ptr control block
        for (const RayFamily& f : ch.axis) s.rays_stored += f.is_uniform() ? 0 : rays_per_family;
        break;
      }
    }
  }
  s.point_bytes = s.points * sizeof(PackedPoint);
  return s;
}

void World::set_metadata(const std::string& key, const std::string& value) {
  for (auto& kv : metadata_) {
    if (kv.first == key) {
      kv.second = value;
      return;
    }
  }
  metadata_.emplace_back(key, value);
}

std::string World::metadata_value(const std::string& key) const {
  for (const auto& kv : metadata_) {
    if (kv.first == key) return kv.second;
  }
  return {};
}

}  // namespace ldc
