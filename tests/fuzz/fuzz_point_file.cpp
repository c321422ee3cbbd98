// Fuzz target: read_point_sets, the reader of the point files `kdm analyze` takes (text, '#' lines between
// sets, blanks or commas between coordinates, an optional CSV header naming its columns; NumPy .npy), on
// arbitrary bytes. Checks: it either fails with an error naming the file or returns at least one set,
// every set non-empty, all of one dimension (2 or 3), with whole points of finite coordinates, no more
// points than lines (text) or than the bytes hold (.npy, 4 bytes a coordinate at least; its sets, one or
// a (sets, n, dim) array's, of one size), and labels, if any, one a point.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "point_io.h"

namespace {

[[noreturn]] void fail() {
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::istringstream in(text);
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  if (!kdm::tools::read_point_sets(in, "fuzz.txt", sets, error)) {
    if (error.find("fuzz.txt") == std::string::npos) fail();
    return 0;
  }
  if (sets.empty()) fail();
  const bool npy = text.rfind("\x93NUMPY", 0) == 0;
  const std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  std::size_t points = 0;
  for (const kdm::tools::PointSet& set : sets) {
    if (set.dim != sets[0].dim || (set.dim != 2 && set.dim != 3)) fail();
    if (set.coords.empty() || set.coords.size() % set.dim != 0) fail();
    for (double c : set.coords)
      if (!std::isfinite(c)) fail();
    if (!set.classes.empty() && (set.classes.size() != set.size() || set.dim != 2)) fail();
    points += set.size();
    if (npy && set.coords.size() * 4 > size) fail();
  }
  if (!npy && points > lines) fail();
  for (const kdm::tools::PointSet& set : sets)  // .npy: one set, or a (sets, n, dim) array's K of one size
    if (npy && set.size() != sets[0].size()) fail();
  return 0;
}
