// What the sources of the Python module kdm._kdm share: each binds one topic (densities, the sampler, tile
// sets, queries, stippling, the analysis, C++ timings for the benchmark) through its bind_* function, and
// they raise the same errors and return numpy arrays the same way.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kdm/runtime/tileset.h"

namespace kdm::python {

namespace py = pybind11;

/// A file that cannot be read or written: raised as OSError (pybind11 would make a std::runtime_error a
/// RuntimeError), or as the subclass of OSError that `error_number` names, as Python's open() raises it
/// (ENOENT: FileNotFoundError). The message is the command line's one line.
struct FileError : std::runtime_error {
  explicit FileError(const std::string& message, int error = 0)
      : std::runtime_error(message), error_number(error) {}
  int error_number;  ///< an errno value, or 0 for a plain OSError
};

/// A FileError for the file `path` that could not be read: with the errno of why, where the file system
/// tells it (a missing file, a directory, no permission), so that `except FileNotFoundError` catches a
/// missing file as it does for open().
FileError read_error(const std::string& path, const std::string& message);

/// A long call's progress callback: raises a pending signal's exception (Ctrl-C's KeyboardInterrupt) in
/// the call, which then stops at its next step instead of running to its end. Takes the GIL.
inline void stop_on_signal(double /*progress*/) {
  py::gil_scoped_acquire held;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

/// A tile set's .kdmt bytes, kept once known: the file or bytes it was loaded from, or what the baker or
/// a first to_bytes() encoded (at zstd's level 19 that takes 20 s for the built-in set's 14 MB, and a
/// pickle asks for them every time).
struct EncodedTileset {
  std::mutex mutex;
  std::vector<std::uint8_t> bytes;  ///< empty until known; never changed after
};

/// A loaded tile set as Python holds it: shared, immutable, so queries run on it with the GIL released.
struct TilesetHandle {
  std::shared_ptr<const Tileset> set;
  std::uint32_t format_version = 0;  ///< of the file it came from (the current one when baked or built in)
  std::shared_ptr<EncodedTileset> encoded = std::make_shared<EncodedTileset>();
};

/// A numpy array of `shape` that takes over `values` (moved, not copied): the vector is freed when the
/// last array viewing it is.
template <class T>
py::array_t<T> owning_array(std::vector<T>&& values, const std::vector<py::ssize_t>& shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), owner);
}

/// Tileset::builtin(), or MemoryError (std::bad_alloc) where memory ran out while it was decoded.
const Tileset& builtin_tileset();

/// Throws std::invalid_argument("`name` must be ...") unless `value` is finite and at least `min`
/// (above it when `strict`).
void check_number(const char* name, double value, double min, bool strict);

void bind_density(py::module_& m);
void bind_sampler(py::module_& m);
void bind_tileset(py::module_& m);
void bind_query(py::module_& m);
void bind_stipple(py::module_& m);
void bind_analysis(py::module_& m);
void bind_timing(py::module_& m);

}  // namespace kdm::python
