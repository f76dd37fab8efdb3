#include "kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace sonarbench::sim {

// ThreadSanitizer instruments the clones' resolver, which runs before it starts: one baseline.
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SONARBENCH_NO_CLONES
#endif
#endif
#ifdef SONARBENCH_NO_CLONES
#define SONARBENCH_CLONES
#else
#define SONARBENCH_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif

// to[k] += w · from[k] for every k. Compiled for AVX-512 and AVX2 besides the baseline, picked
// when the program starts: the loop is the same element-wise products and sums at any vector
// width, and the file is built without fused multiply-adds (sim/sonar/CMakeLists.txt), so every
// clone gives the same bits; the wider ones in a fraction of the time (synthesis_bench).
SONARBENCH_CLONES void AddScaled(std::span<double> to, std::span<const double> from, double w) {
  for (std::size_t k = 0; k < to.size(); ++k) to[k] += w * from[k];
}

std::vector<double> ExponentialKernel(double steps, int max_reach) {
  const int reach = std::min(static_cast<int>(std::ceil(steps * std::log(1e12) / 2.0)), max_reach);
  std::vector<double> kernel(2 * static_cast<std::size_t>(reach) + 1);
  for (int e = -reach; e <= reach; ++e) {
    kernel[static_cast<std::size_t>(e + reach)] = std::exp(-std::abs(e) / steps);
  }
  return kernel;
}

}  // namespace sonarbench::sim
