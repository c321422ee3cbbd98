// C++ timings for benchmarks/python_overhead.py: the work of kdm.sample and of a query without Python
// around it, timed in the same process and build, so the Python layer's overhead is what differs.
#include <chrono>
#include <vector>

#include "bindings.h"
#include "kdm/generator/sampler.h"
#include "runtime_query.h"

namespace kdm::python {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Wall seconds of gen::sample for n uniform points on the torus (kdm sample's defaults).
double time_sample(std::int64_t n, std::uint64_t seed, int threads) {
  gen::SamplerOptions o;
  o.n = n;
  o.seed = seed;
  o.threads = threads;
  py::gil_scoped_release release;
  const auto t0 = std::chrono::steady_clock::now();
  const gen::SampleResult r = gen::sample(o);
  return seconds_since(t0);
}

/// Wall seconds of a constant-density query of the rectangle: (query_all into a new vector, as kdm query
/// runs it; query_points into a buffer reused from an earlier call, as runtime_benchmark does).
py::tuple time_query(const TilesetHandle& tiles, double x1, double y1, double scale, bool smooth) {
  QueryParams q;
  q.x1 = x1, q.y1 = y1, q.scale = scale;
  q.mode = smooth ? QueryMode::kSmooth : QueryMode::kStable;
  double all = 0, reused = 0;
  std::size_t count = 0;
  {
    py::gil_scoped_release release;
    auto t0 = std::chrono::steady_clock::now();
    std::vector<QueryPoint> fresh;
    tools::query_all(*tiles.set, q, fresh);
    all = seconds_since(t0);
    count = fresh.size();
    std::vector<QueryPoint> buffer(count + 1);  // touched before the timing
    QueryCursor cursor;
    std::size_t written = 0, total = 0;
    t0 = std::chrono::steady_clock::now();
    while (query_points(*tiles.set, q, buffer.data() + total, buffer.size() - total, &written, &cursor) ==
           Status::kBufferFull)
      total += written;
    reused = seconds_since(t0);
  }
  return py::make_tuple(all, reused, count);
}

}  // namespace

void bind_timing(py::module_& m) {
  m.def("time_sample", &time_sample, py::arg("n"), py::arg("seed"), py::arg("threads"));
  m.def("time_query", &time_query, py::arg("tileset"), py::arg("x1"), py::arg("y1"), py::arg("scale"),
        py::arg("smooth"));
}

}  // namespace kdm::python
