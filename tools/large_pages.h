// The tool's allocation of large blocks on transparent huge pages
// (large_pages.cpp replaces operator new with it).
#pragma once

#include <cstddef>

namespace ldc::tool {

// Blocks from this size (a huge page) up are aligned to it, rounded up to
// whole huge pages and advised onto them. Raising it to 8 or 32 MiB kept
// less of the speed (a landscape's contouring 31% and 2% faster, against
// 37% at 2 MiB) for the same peak memory at 8 MiB.
inline constexpr std::size_t kLargeBlock = std::size_t(2) << 20;

// malloc below kLargeBlock; above, aligned_alloc(kLargeBlock) rounded up to
// whole huge pages and madvise(MADV_HUGEPAGE). Null when out of memory.
// Freed with free().
void* allocate_block(std::size_t n);

}  // namespace ldc::tool
