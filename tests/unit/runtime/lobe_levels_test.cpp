// SPDX-License-Identifier: Apache-2.0
// The clustered lobes group their levels above the finest on first use (lobe_ndf.h): threads that
// meet an unbuilt level at once get exactly the answers of a hierarchy grouped up front (run under
// TSan in CI, which also checks that the lazy build is race-free).
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/lobe_ndf.h>
#include <glintbake/runtime/texel_source.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>
#include <vector>

namespace glintbake::runtime {
namespace {

// A bumpy, repeating 128^2 map: smooth bumps plus a high-frequency ripple, so that the tiles'
// lobes differ and the reduction merges for real.
std::vector<float> bumpyNormals(int n) {
  std::vector<float> v(size_t(n) * size_t(n) * 2);
  const double k = kTwoPi / n;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      float* p = &v[(size_t(y) * size_t(n) + size_t(x)) * 2];
      p[0] = float(0.2 * std::sin(3 * k * x) * std::cos(2 * k * y) + 0.05 * std::sin(37 * k * (x + y)));
      p[1] = float(0.2 * std::cos(5 * k * y) + 0.05 * std::cos(29 * k * (x - 2 * y)));
    }
  }
  return v;
}

std::vector<double> queries(const LobeNdf& lobes, int seed, int map) {
  std::mt19937_64 rng{uint64_t(seed)};
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> out;
  for (int k = 0; k < 60; ++k) {
    // Footprints over every level of the hierarchy, in a different order on every thread.
    const double sigma = 2.0 * std::pow(2.0, 6.0 * u(rng));
    const Footprint fp{map * u(rng), map * u(rng), sigma};
    double e = 0.0, m = 0.0;
    out.push_back(double(lobes.eval(fp, {0.3 * u(rng) - 0.15, 0.3 * u(rng) - 0.15}, &e)) + e);
    out.push_back(double(lobes.mass(fp, &m)) + m);
    NdfSample smp;
    const RuntimeStatus st = lobes.sample(fp, u(rng), u(rng), &smp);
    out.push_back(double(st) + (st == RuntimeStatus::kOk ? smp.s.x + smp.s.y + smp.pdf : 0.0));
  }
  return out;
}

TEST(LobeLevels, ConcurrentFirstQueriesMatchLevelsGroupedUpFront) {
  constexpr int kMapSide = 128, kThreads = 4;
  const std::vector<float> normals = bumpyNormals(kMapSide);
  const InterleavedTexels texels(kMapSide, kMapSide, true, normals.data(), 2);
  LobeNdf eager, lazy;
  ASSERT_EQ(eager.build(texels, 1, 0.005, 8, 32), RuntimeStatus::kOk);
  eager.prepare();
  ASSERT_EQ(lazy.build(texels, 1, 0.005, 8, 32), RuntimeStatus::kOk);
  std::vector<std::vector<double>> serial(kThreads), threaded(kThreads);
  for (int t = 0; t < kThreads; ++t) serial[size_t(t)] = queries(eager, t, kMapSide);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) threads.emplace_back([&, t] { threaded[size_t(t)] = queries(lazy, t, kMapSide); });
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(serial[size_t(t)], threaded[size_t(t)]) << "thread " << t;
  lazy.prepare();  // built already: a no-op that changes nothing
  EXPECT_EQ(queries(lazy, 0, kMapSide), serial[0]);
}

}  // namespace
}  // namespace glintbake::runtime
