// libFuzzer target: bytes -> a chain of brush edits (every op and brush
// shape, hostile numbers included) on a small world. After each edit the
// world must pass validate(); a refused edit must say why and leave the world
// exactly as it was. Now and then an edit is undone, or the world is combined
// with an earlier snapshot of itself by boolean(), and checked again.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "csg/csg.h"

namespace {

// Reads the input a byte at a time; zeros once it runs out.
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool more() const { return at_ < size_; }
  uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  // A coordinate in [-3, 3] m, on a grid of 1/64 m (so lattice nodes and
  // cell faces are hit exactly), or now and then a hostile value.
  double coordinate() {
    uint8_t tag = byte();
    if (tag == 255) return hostile();
    return (int(tag) - 128) * (3.0 / 128.0) + (byte() % 8) / 64.0;
  }
  double length() {
    uint8_t tag = byte();
    if (tag == 255) return hostile();
    return 0.01 + tag * (1.5 / 254.0);
  }
  double hostile() {
    switch (byte() % 6) {
      case 0: return std::numeric_limits<double>::quiet_NaN();
      case 1: return std::numeric_limits<double>::infinity();
      case 2: return -1.0;
      case 3: return 0.0;
      case 4: return 1e9;
      default: return 1e-12;
    }
  }

 private:
  const uint8_t* data_;
  size_t size_, at_ = 0;
};

ldc::Brush read_brush(Bytes& in) {
  const uint8_t shape = in.byte() % 5;
  const uint16_t material = in.byte() % 4;
  glm::dvec3 a(in.coordinate(), in.coordinate(), in.coordinate());
  glm::dvec3 b(in.coordinate(), in.coordinate(), in.coordinate());
  double r = in.length();
  ldc::Brush brush;
  switch (shape) {
    case 0: brush = ldc::Brush::sphere(a, r, material); break;
    case 1: brush = ldc::Brush::box(a, glm::dvec3(r, in.length(), in.length()), material); break;
    case 2: brush = ldc::Brush::capsule(a, b, r, material); break;
    case 3: brush = ldc::Brush::cylinder(a, b, r, material); break;
    default: {
      ldc::NoiseSphere n{.radius = r, .amplitude = in.byte() / 280.0, .frequency = 0.5 + in.byte() / 64.0,
                         .seed = in.byte()};
      brush = ldc::Brush::noisy_sphere(a, n, material);
    }
  }
  if (std::holds_alternative<ldc::Primitive>(brush.shape) && in.byte() % 4 == 0) {
    brush.transform() = glm::rotate(brush.transform(), in.byte() * 0.05, glm::dvec3(1.0, 0.5, 0.25));
  }
  return brush;
}

ldc::World slab() {
  ldc::Primitive p;
  p.shape = ldc::Primitive::Shape::kBox;
  p.half_extents = glm::dvec3(2.0, 2.0, 0.75);
  ldc::GridConfig grid{.cell_size = 0.25, .chunk_size = 8, .use_origin = true, .origin = glm::dvec3(-2.55, -2.45, -1.5)};
  return ldc::build_from_primitive(p, grid).value();
}

void require_valid(const ldc::World& w, const char* after) {
  ldc::ValidationReport r = ldc::validate(w);
  if (r.ok) return;
  std::fprintf(stderr, "invalid world after %s: %s\n", after, r.summary().c_str());
  std::abort();
}

// The same chunk objects: a refused edit must not have touched anything.
bool same_world(const ldc::World& a, const ldc::World& b) {
  if (a.chunk_origin() != b.chunk_origin() || a.chunk_dims() != b.chunk_dims()) return false;
  bool same = true;
  a.for_each_chunk([&](const glm::ivec3& c, ldc::ChunkKind kind, const ldc::Chunk* data) {
    same = same && b.chunk_kind(c) == kind && b.chunk(c) == data;
  });
  return same;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const ldc::World start = slab();
  Bytes in(data, size);
  ldc::WorldEditor editor(start);
  std::vector<ldc::EditReceipt> receipts;
  std::vector<ldc::World> snapshots{start};
  for (int step = 0; step < 24 && in.more(); ++step) {
    const uint8_t action = in.byte();
    if (action % 16 == 0 && !receipts.empty()) {  // undo the latest edit
      if (!editor.undo(receipts.back()).ok()) std::abort();  // reverse order always works
      receipts.pop_back();
      require_valid(editor.world(), "undo");
      continue;
    }
    if (action % 16 == 1) {  // boolean with an earlier snapshot
      const ldc::World& other = snapshots[in.byte() % snapshots.size()];
      auto op = static_cast<ldc::BooleanOp>(in.byte() % 3);
      ldc::Result<ldc::World> r = ldc::boolean(editor.world(), other, op);
      if (!r.ok()) std::abort();  // same lattice: must succeed
      require_valid(r.value(), "boolean");
      continue;
    }
    const ldc::EditOp op = static_cast<ldc::EditOp>(in.byte() % 4);
    std::vector<ldc::WorldEditor::Edit> batch{{read_brush(in), op}};
    if (action % 16 == 2) batch.push_back({read_brush(in), static_cast<ldc::EditOp>(in.byte() % 4)});
    const ldc::World before = editor.world();
    const uint64_t version = editor.version();
    ldc::Result<ldc::EditReceipt> r = editor.apply_batch(batch);
    if (!r.ok()) {
      if (r.status().message().empty() || editor.version() != version || !same_world(before, editor.world())) {
        std::fprintf(stderr, "a refused edit changed the world or gave no reason\n");
        std::abort();
      }
      continue;
    }
    require_valid(editor.world(), ldc::edit_op_name(op));
    receipts.push_back(std::move(r).value());
    if (snapshots.size() < 4) snapshots.push_back(editor.world());
  }
  (void)editor.take_dirty();
  return 0;
}
