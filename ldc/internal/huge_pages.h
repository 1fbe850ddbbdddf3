// Advice for a large array about to be filled: back it with transparent huge
// pages. Where Linux's THP setting is "madvise" (as on the VMs we measure
// on), a fresh array is otherwise faulted in 4 KiB at a time, at tens of
// microseconds a fault there: voxelize()'s 52 MB occupancy grid of the bunny
// at 256 voxels took 12,800 faults, about half of the call. Only the whole
// 2 MiB pages inside the block are advised, and the caller fills all of it,
// so no memory is added; where THP is "always" or "never", or off Linux,
// nothing changes. The library's allocator stays the caller's: this advises
// memory already allocated, before it is touched.
#pragma once

#include <cstddef>
#include <vector>

namespace ldc::detail {

inline constexpr size_t kHugePageBytes = size_t(2) << 20;

// madvise(MADV_HUGEPAGE) on the 2 MiB pages inside [data, data + bytes);
// blocks under two huge pages are left alone.
void advise_huge_pages(const void* data, size_t bytes);

// Capacity for n elements, advised before the caller fills them (assign,
// resize): call it on a vector that holds nothing yet.
template <class T>
void reserve_on_huge_pages(std::vector<T>& v, size_t n) {
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
}

// v.assign(n, value) on an empty vector, its block advised first.
template <class T>
void assign_on_huge_pages(std::vector<T>& v, size_t n, const T& value = T{}) {
  reserve_on_huge_pages(v, n);
  v.assign(n, value);
}

}  // namespace ldc::detail
