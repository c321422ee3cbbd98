// Counts heap allocations made by a test binary, to prove queries make none: a test that links
// allocation_counter.cpp replaces operator new and reads the count around the code it measures.
#pragma once

namespace kdm::testing {

/// Calls of operator new so far in this process.
long allocations();

}  // namespace kdm::testing
