// Transparent huge pages for the sampler's largest buffers. Every first touch of a 4 KiB page is a fault,
// and on virtual machines a fault is slow (docs/design.md §2.9). A buffer larger than glibc's largest mmap
// threshold (32 MiB) is mapped afresh, and faulted in again, by every call: the footprint cache from n of
// about 110,000 up.
#pragma once

#include <cstddef>
#include <vector>

namespace kdm::gen {

/// Asks the system to back the 2 MiB-aligned pages inside [p, p + bytes) with huge pages when they are
/// first touched (Linux madvise; a no-op elsewhere, where transparent huge pages are off, or when the range
/// holds no whole aligned 2 MiB page). Advice only: the buffer and its contents stay the same either way.
/// Memory already touched keeps its pages. Thread-safe.
void advise_huge_pages(void* p, std::size_t bytes) noexcept;

/// A vector of n copies of `value` whose storage, when the vector allocates it, is advised for huge pages
/// before its first touch. For the grids of ρ and R, the largest buffers of a run on an image density
/// (docs/design.md §2.9).
template <class T>
std::vector<T> vector_on_huge_pages(std::size_t n, const T& value) {
  std::vector<T> v;
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
  v.assign(n, value);
  return v;
}

/// v.resize(n), with new storage (if it needs any) advised for huge pages before its first touch.
template <class T>
void resize_on_huge_pages(std::vector<T>& v, std::size_t n) {
  if (v.capacity() < n) {
    std::vector<T> grown;
    grown.reserve(n);
    advise_huge_pages(grown.data(), n * sizeof(T));
    grown.assign(v.begin(), v.end());
    v.swap(grown);
  }
  v.resize(n);
}

}  // namespace kdm::gen
