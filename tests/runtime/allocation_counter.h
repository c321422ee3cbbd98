// Counts heap allocations made by a test binary, to prove queries make none: a test that links
// allocation_counter.cpp replaces operator new and reads the count around the code it measures.
#pragma once

#include <cstddef>

namespace kdm::testing {

/// Calls of operator new so far in this process.
long allocations();
/// The largest single request to operator new since the last reset_largest_allocation() (or the start).
std::size_t largest_allocation();
void reset_largest_allocation();

}  // namespace kdm::testing
