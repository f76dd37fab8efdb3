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

// Echo boxes summed by their edges give each bin what the box covers of it, as the direct sum
// over the bins would: boxes inside one bin, across many, starting before bin 0 and running
// past the last. The two differ only by rounding: each bin's sum is a running sum over at most
// 2 · 500 edges, so within 1000 · 2^-52 < 1e-12 of the total power; and bins no box reaches
// hold exactly 0.
TEST(PulseSpreader, SpreadsEachBoxOverTheBinsItCovers) {
  constexpr std::size_t kBins = 120;
  Rng rng(5);
  PulseSpreader spreader(kBins);
  std::vector<double> direct(kBins, 0.0);
  double total = 0.0;
  for (int box = 0; box < 500; ++box) {
    // Boxes between bins -2 and 100 (none reaches bins 105 on), half a bin to 5 bins long
    // and powers over six decades.
    const double start = 102.0 * rng.Uniform() - 2.0;
    const double end = start + (box % 10 == 0 ? 0.3 : 0.5 + 4.5 * rng.Uniform());
    const double power = std::pow(10.0, 6.0 * rng.Uniform() - 3.0);
    spreader.Add(start, end, power);
    total += power * (end - start);
    for (std::size_t k = 0; k < kBins; ++k) {
      const double overlap =
          std::min(static_cast<double>(k + 1), end) - std::max(static_cast<double>(k), start);
      if (overlap > 0.0) direct[k] += power * overlap;
    }
  }
  std::vector<double> spread(kBins, 0.0);
  spreader.AddTo(spread);
  for (std::size_t k = 0; k < kBins; ++k) {
    EXPECT_NEAR(spread[k], direct[k], 1e-12 * total) << "bin " << k;
    if (direct[k] == 0.0) {
      EXPECT_EQ(spread[k], 0.0) << "bin " << k;
    }
  }
  EXPECT_EQ(spread[kBins - 1], 0.0);
  // Emptied: a second read-out adds nothing to what the bins hold; a box added after is read
  // out alone.
  std::vector<double> again(kBins, -1.5);
  spreader.AddTo(again);
  EXPECT_EQ(again, std::vector<double>(kBins, -1.5));
  spreader.Add(10.0, 12.0, 2.0);
  std::vector<double> alone(kBins, 0.0);
  spreader.AddTo(alone);
  std::vector<double> expected(kBins, 0.0);
  expected[10] = expected[11] = 2.0;
  EXPECT_EQ(alone, expected);
}

}  // namespace
}  // namespace sonarbench::sim
