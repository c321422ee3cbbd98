// The replaced operator new and delete behind allocation_counter.h. The replacement pairs malloc with free
// on purpose; GCC's mismatch warning cannot see that both sides are replaced.
#include "allocation_counter.h"

#include <atomic>
#include <cstdlib>
#include <new>

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

namespace {
std::atomic<long> g_allocations{0};
std::atomic<std::size_t> g_largest{0};
}  // namespace

// Every replaceable form that allocates with malloc is replaced, so that no form left to the library
// (or to a sanitizer's allocator) is ever freed by a replaced delete.
namespace {
void* counted_malloc(std::size_t size) noexcept {
  ++g_allocations;
  for (std::size_t largest = g_largest.load();
       size > largest && !g_largest.compare_exchange_weak(largest, size);) {
  }
  return std::malloc(size ? size : 1);
}
}  // namespace

void* operator new(std::size_t size) {
  if (void* p = counted_malloc(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = counted_malloc(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return counted_malloc(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return counted_malloc(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

long kdm::testing::allocations() {
  return g_allocations.load();
}

std::size_t kdm::testing::largest_allocation() {
  return g_largest.load();
}

void kdm::testing::reset_largest_allocation() {
  g_largest.store(0);
}
