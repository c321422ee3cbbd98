// The full sampler from C++ (CMake target kdm::generator, namespace kdm::gen): exactly n points for a
// density of your own in a bounded box, and three classes of points that keep apart. Compiled and run by
// the tests (tests/generator/CMakeLists.txt) so that it stays true; exit status 0 when its checks hold.
#include <kdm/generator/multiclass.h>
#include <kdm/generator/sampler.h>

#include <cmath>
#include <cstdio>

int main() {
  // A density of your own: a function of normalised coordinates u in [0, 1)^2 (only its shape matters).
  // thread_safe lets the sampler's set-up call it from its threads at once.
  kdm::gen::Density ramp;
  ramp.function = [](const double* u) { return 0.1 + u[0] * u[0]; };
  ramp.thread_safe = true;

  kdm::gen::SamplerOptions options;
  options.n = 5000;                              // exactly this many points
  options.domain = kdm::gen::Domain::kBox;       // walls, not a torus: the ramp's edges do not meet
  options.extent[0] = 2, options.extent[1] = 1;  // a 2:1 rectangle; points still come in [0, 1)^2
  options.seed = 7;                              // the same seed gives the same bits, whatever the threads
  try {
    const kdm::gen::SampleResult result = kdm::gen::sample(options, ramp);
    // More points where the ramp is higher: the right half holds most of them.
    std::size_t right = 0;
    for (std::size_t i = 0; i < result.size(); ++i) right += result.points[2 * i] >= 0.5;
    std::printf("%zu points, %zu in the right half, acceptance %.2f, %.2f s\n", result.size(), right,
                result.report.acceptance_rate(), result.report.seconds);
    if (result.size() != 5000 || right < 3500) return 1;

    // Three classes of constant densities 1 : 2 : 4 (trees, bushes, rocks): exact counts per class,
    // class 0 the best spread, all of them together one blue-noise set.
    options.domain = kdm::gen::Domain::kTorus;
    options.extent[0] = 1;
    options.n = 3500;
    const kdm::gen::ClassSample classes = kdm::gen::sample_classes(
        options,
        {kdm::gen::Density::constant(1), kdm::gen::Density::constant(2), kdm::gen::Density::constant(4)});
    std::printf("classes: %lld, %lld and %lld points\n", static_cast<long long>(classes.counts[0]),
                static_cast<long long>(classes.counts[1]), static_cast<long long>(classes.counts[2]));
    if (classes.counts[0] != 500 || classes.counts[1] != 1000 || classes.counts[2] != 2000) return 1;
  } catch (const kdm::gen::InvalidArgument& e) {  // bad options or density: one line naming the problem
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
