// validate() with progress and a count of the work it did (issue 24: load
// cost bounded by content). The loader reports its world pass as the stage
// "validate"; tests read ValidateWork to check that uniform chunk slots cost
// O(1) (no ray of theirs is visited) without timing anything.
#pragma once

#include <cstddef>

#include "ldc/context.h"
#include "ldc/world.h"

namespace ldc::detail {

struct ValidateWork {
  size_t slots = 0;           // chunk slots checked
  size_t rays_visited = 0;    // ray segments looked at one by one (continuity and chunk checks)
  size_t uniform_faces = 0;   // boundaries between two uniform slots, compared once each
};

// validate(world, options), reporting ("validate", fraction) to ctx (may be
// null) and adding its work to *work (may be null).
ValidationReport validate_with_progress(const World& world, const ValidateOptions& options, Context* ctx,
                                        ValidateWork* work = nullptr);

}  // namespace ldc::detail
