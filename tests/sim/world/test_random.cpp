#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "sim_fixtures.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/pulse_spreader.hpp"
#include "sonarbench/sim/sonar/range_spread.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/random.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

// The speckle and noise draws are exponential with mean 1 (the power of a Rayleigh amplitude).
// Kolmogorov-Smirnov against F(x) = 1 - exp(-x) on 200000 draws, fixed seed: the critical value
// at a 0.1% false-alarm rate is 1.949 / sqrt(n).
TEST(Rng, ExponentialDrawsFollowTheirDistribution) {
  constexpr int kDraws = 200000;
  Rng rng(12345);
  std::vector<double> x(kDraws);
  for (double& v : x) v = rng.Exponential();
  EXPECT_LT(KsDistance(x, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(static_cast<double>(kDraws)));
}

// The ziggurat's rare paths: the tail beyond its last edge R = 7.697 and the wedges between
// layers. Over 4 M draws, the counts beyond R, beyond 10 and in (1, 1.01] are binomial with
// p = e^-R, e^-10 and e^-1 - e^-1.01; each must lie within 3.29 standard deviations of n·p (a
// 0.1% false-alarm rate each, two-sided), fixed seed.
TEST(Rng, ExponentialTailAndWedgesHaveTheirProbabilities) {
  constexpr double kDraws = 4e6;
  Rng rng(4242);
  double beyond_r = 0;
  double beyond_10 = 0;
  double in_wedge = 0;
  for (int i = 0; i < static_cast<int>(kDraws); ++i) {
    const double x = rng.Exponential();
    ASSERT_GE(x, 0.0);
    beyond_r += x > ExponentialZiggurat::kR ? 1 : 0;
    beyond_10 += x > 10.0 ? 1 : 0;
    in_wedge += (x > 1.0 && x <= 1.01) ? 1 : 0;
  }
  for (const auto& [count, p] : {std::pair{beyond_r, std::exp(-ExponentialZiggurat::kR)},
                                 std::pair{beyond_10, std::exp(-10.0)},
                                 std::pair{in_wedge, std::exp(-1.0) - std::exp(-1.01)}}) {
    const double mean = kDraws * p;
    EXPECT_NEAR(count, mean, 3.29 * std::sqrt(mean * (1 - p))) << "p " << p;
  }
}

}  // namespace
}  // namespace sonarbench::sim
