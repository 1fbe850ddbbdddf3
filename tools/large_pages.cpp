// The `ldc` tool's operator new: blocks of 2 MiB or more are 2 MiB aligned
// and advised onto transparent huge pages (madvise(MADV_HUGEPAGE)); smaller
// ones come from malloc as before. Why: a large command allocates and
// zero-fills tens of MB of fresh arrays at each step (contouring's chunk
// meshes, simplify_mesh's quadrics and incidence tables), and on the 2-core
// VMs we measure on, Linux's THP setting is "madvise" and a 4 KiB page fault
// is expensive: simplify_mesh spent 108-115 ms of a 1.2 s run zero-filling
// 31 MB. With huge pages (2 threads, interleaved runs, best of 3): `ldc
// contour` of the default landscape 1.42 s -> 0.88 s, `ldc boolean` of spot
// and spot at 256 cells 1.45 -> 1.22 s, of fandisk and a cylinder 1.56 ->
// 1.35 s, `ldc remesh` of the bunny at 256 cells 1.41 -> 1.29 s and at 64
// cells 0.20 -> 0.16 s. Peak memory grows by whole huge pages: 5-15% on
// those, 30% on the landscape's contouring (118 -> 154 MB).
// Where THP is "always" this changes nothing; where it is "never", madvise
// is refused and only the alignment remains. The tool alone replaces
// operator new: a program linking the library keeps its own allocator.
// Under AddressSanitizer the replacement is left out, so that ASan's own
// operator new keeps its new/delete checks.
#include "large_pages.h"

#include <sys/mman.h>

#include <cstdlib>
#include <new>

namespace ldc::tool {

void* allocate_block(std::size_t n) {
  if (n >= kLargeBlock) {
    const std::size_t rounded = (n + kLargeBlock - 1) / kLargeBlock * kLargeBlock;
    void* p = std::aligned_alloc(kLargeBlock, rounded);
    if (p) (void)madvise(p, rounded, MADV_HUGEPAGE);  // advice only: refused where THP is off
    return p;
  }
  return std::malloc(n ? n : 1);
}

}  // namespace ldc::tool

#if !defined(__SANITIZE_ADDRESS__)
namespace {
void* allocate_or_throw(std::size_t n) {
  if (void* p = ldc::tool::allocate_block(n)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return allocate_or_throw(n); }
void* operator new[](std::size_t n) { return allocate_or_throw(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#endif
