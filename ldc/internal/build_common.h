// Pieces every builder shares: choosing the lattice and world box, assembling
// chunk families into a World, and turning cancellation into a Status.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include "ldc/build.h"
#include "ldc/world.h"

namespace ldc::detail {

// Chooses h, the origin and the chunk box for an input with the given world bounds.
// `surface_area` [m^2] estimates the points the build will store, for the
// memory check. Errors name the GridConfig field that is out of range.
Result<WorldConfig> plan_grid(const WorldBox& input_bounds, const GridConfig& grid,
                              double surface_area, const char* what);

// Families of every chunk slot, written by the builders' tasks, then moved into
// the world's chunks (collapsing uniform ones).
class ChunkAssembly {
 public:
  explicit ChunkAssembly(const World& world);
  std::array<RayFamily, 3>& families(size_t slot) { return families_[slot]; }
  void set_uniform(size_t slot, bool solid);
  // Moves every slot into `world`, in parallel. Returns the number of mixed chunks.
  size_t finish(World& world);

 private:
  std::vector<std::array<RayFamily, 3>> families_;
};

// Counts work items done and reports a fraction to the context.
class ProgressCounter {
 public:
  ProgressCounter(Context* ctx, std::string stage, size_t total)
      : ctx_(ctx), stage_(std::move(stage)), total_(total ? total : 1) {}
  void step() {
    size_t done = done_.fetch_add(1) + 1;
    if (ctx_ && (done % 16 == 0 || done == total_)) {
      ctx_->report_progress(stage_, double(done) / double(total_));
    }
  }
  bool cancelled() const { return ctx_ && ctx_->cancelled(); }

 private:
  Context* ctx_;
  std::string stage_;
  size_t total_;
  std::atomic<size_t> done_{0};
};

// Bounds of the box [-half, half] under an affine map: its eight corners'.
inline WorldBox transformed_box_bounds(const glm::dmat4& transform, const glm::dvec3& half) {
  WorldBox b{glm::dvec3(INFINITY), glm::dvec3(-INFINITY)};
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 corner((i & 1) ? half.x : -half.x, (i & 2) ? half.y : -half.y, (i & 4) ? half.z : -half.z);
    glm::dvec3 w(transform * glm::dvec4(corner, 1.0));
    b.min = glm::min(b.min, w);
    b.max = glm::max(b.max, w);
  }
  return b;
}

inline bool boxes_disjoint(const WorldBox& a, const WorldBox& b) {
  for (int k = 0; k < 3; ++k) {
    if (a.max[k] < b.min[k] || a.min[k] > b.max[k]) return true;
  }
  return false;
}

inline Status cancelled_status(const char* what) {
  return {ErrorCode::kCancelled, std::string(what) + ": cancelled"};
}

// Coordinates of chunk slot `slot` of a world (x fastest), as World::for_each_chunk.
inline glm::ivec3 slot_chunk(const World& w, size_t slot) {
  const glm::ivec3 d = w.chunk_dims();
  int x = int(slot % size_t(d.x));
  int y = int((slot / size_t(d.x)) % size_t(d.y));
  int z = int(slot / (size_t(d.x) * size_t(d.y)));
  return w.chunk_origin() + glm::ivec3(x, y, z);
}

// build_from_implicit, then the world's "source" metadata set to `source`.
Result<World> build_implicit_as(const ImplicitSolid& solid, const GridConfig& grid, Context* ctx,
                                BuildReport* report, const std::string& source);

// Writes the build report's figures into the world's metadata.
void record_build_report(World& world, const BuildReport& report);

}  // namespace ldc::detail
