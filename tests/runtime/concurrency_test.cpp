// Several threads querying one Tileset at once (the runtime's thread-safety promise, query.h). CI also
// runs this binary under ThreadSanitizer (.ci/run), which turns any data race here into a failure.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "kdm/runtime/density_check.h"
#include "kdm/runtime/query.h"

namespace kdm {
namespace {

struct Emitted {
  double x, y;
  PointId id;
  friend bool operator==(const Emitted& a, const Emitted& b) {
    return a.x == b.x && a.y == b.y && a.id == b.id;  // bit for bit
  }
};

// Runs a query to completion through a small buffer, so every thread also resumes cursors many times.
std::vector<Emitted> run(const QueryParams& q) {
  std::vector<QueryPoint> buffer(997);
  std::vector<Emitted> out;
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const Status s = query_points(Tileset::builtin(), q, buffer.data(), buffer.size(), &written, &cursor);
    for (std::size_t i = 0; i < written; ++i) out.push_back({buffer[i].x, buffer[i].y, buffer[i].id});
    if (s != Status::kBufferFull) {
      EXPECT_EQ(s, Status::kOk) << status_message(s);
      return out;
    }
  }
}

double wave(void* user, double x, double y) {  // thread-safe: reads only its (shared, const) argument
  const double k = *static_cast<const double*>(user);
  return 0.5 + 0.5 * std::sin(k * x) * std::cos(k * y);
}

TEST(ConcurrencyTest, ThreadsQueryingOneTilesetMatchASingleThreadedRun) {
  // Shared read-only inputs: a density image with its max-mip, and a callback's user data.
  std::vector<float> texels(32 * 32), mip;
  for (int i = 0; i < 32 * 32; ++i)
    texels[i] = 0.2f + 0.8f * static_cast<float>((i % 32) * (i / 32)) / (31 * 31);
  DensityImageView image;
  image.width = image.height = 32;
  image.x0 = -1, image.y0 = -1, image.x1 = 3, image.y1 = 3;
  image.values = texels.data();
  ASSERT_EQ(make_density_max_mip(image, mip), Status::kOk);
  const double frequency = 2.5;

  // Different regions, scales, tile sizes and all three density kinds.
  std::vector<QueryParams> cases;
  for (int i = 0; i < 9; ++i) {
    QueryParams q;
    q.x0 = -1 + 0.37 * i, q.y0 = -1 + 0.21 * i, q.x1 = q.x0 + 1.5, q.y1 = q.y0 + 1.2;
    q.origin_x = q.x0;
    q.tile_size = i % 2 ? 0.5 : 1.0;
    q.scale = 3000 + 1000 * i;  // within the top level: 11000 · 1.1 < 16384 per unit tile
    if (i % 3 == 1) {
      q.density.kind = QueryDensity::Kind::kImage;
      q.density.image = &image;
    } else if (i % 3 == 2) {
      q.density.kind = QueryDensity::Kind::kCallback;
      q.density.callback = wave;
      q.density.user = const_cast<double*>(&frequency);
      q.density.callback_max = 1;
    } else {
      q.density.constant = 0.3 + 0.1 * i;
    }
    cases.push_back(q);
  }

  // The threads start together, so the first use of the built-in set (its one-time decode) races too.
  constexpr int kThreads = 4;
  std::atomic<bool> go{false};
  std::vector<std::vector<std::vector<Emitted>>> got(kThreads,
                                                     std::vector<std::vector<Emitted>>(cases.size()));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      while (!go.load()) std::this_thread::yield();
      for (std::size_t k = 0; k < cases.size(); ++k) {
        const std::size_t c = (k + 2 * t) % cases.size();  // each thread walks the cases in its own order
        got[t][c] = run(cases[c]);
      }
    });
  go = true;
  for (std::thread& th : threads) th.join();

  for (std::size_t c = 0; c < cases.size(); ++c) {
    const std::vector<Emitted> reference = run(cases[c]);
    EXPECT_GT(reference.size(), 1000u) << "case " << c;
    for (int t = 0; t < kThreads; ++t) EXPECT_TRUE(got[t][c] == reference) << "thread " << t << " case " << c;
  }
}

// NaN from x = 1 on: every thread finds it through one shared check, which keeps one whole finding.
double flawed_wave(void* user, double x, double y) {
  return x >= 1 ? std::nan("") : wave(user, x, y);
}

TEST(ConcurrencyTest, ThreadsShareOneDensityCheck) {
  const double frequency = 2.5;
  QueryParams q;
  q.x0 = -1, q.y0 = -1, q.x1 = 2, q.y1 = 1;
  q.scale = 4000;
  q.density.kind = QueryDensity::Kind::kCallback;
  q.density.callback = flawed_wave;
  q.density.user = const_cast<double*>(&frequency);
  q.density.callback_max = 1;
  const std::vector<Emitted> bare = run(q);
  DensityCheck check;
  ASSERT_EQ(check.wrap(&q.density), Status::kOk);
  constexpr int kThreads = 4;
  std::atomic<bool> go{false};
  std::vector<std::vector<Emitted>> got(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      while (!go.load()) std::this_thread::yield();
      got[t] = run(q);
    });
  go = true;
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_TRUE(got[t] == bare) << "thread " << t;
  DensityFinding f;
  ASSERT_TRUE(check.failed(&f));
  EXPECT_TRUE(std::isnan(f.value));
  EXPECT_GE(f.x, 1);
  EXPECT_GT(check.largest(), 0.5);
}

}  // namespace
}  // namespace kdm
