// The tile-set allocator hook (kdm/runtime/allocator.h).
#include "kdm/runtime/allocator.h"

namespace kdm {
namespace {

AllocatorHooks g_tileset_hooks;  // written only by set_tileset_allocator (documented: not during loads)

}  // namespace

void set_tileset_allocator(const AllocatorHooks& hooks) {
  g_tileset_hooks = (hooks.allocate && hooks.deallocate) ? hooks : AllocatorHooks{};
}

AllocatorHooks tileset_allocator() {
  return g_tileset_hooks;
}

void detail::tileset_allocation_refused() {
  throw std::bad_alloc();
}

}  // namespace kdm
