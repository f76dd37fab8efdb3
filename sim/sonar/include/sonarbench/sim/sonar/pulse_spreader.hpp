#pragma once

#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

namespace sonarbench::sim {

/// Sums echoes that each last a pulse length over a beam's range bins. An echo is a box: power
/// `power` per bin over [start, end) (in bins), of which bin k receives `power` times the part
/// of [k, k + 1) the box covers. Each box costs two edge updates, whatever its length; the bins
/// are formed once at the end.
///
/// Bin k's sum is the power of the boxes open through all of it plus, for each edge inside it,
/// ±power times the part of the bin after the edge. Edges are kept per bin: the power of the
/// boxes they open (+) or close (-), their partial contributions, and their count, so that the
/// running power is set to exactly 0 wherever no box is open (no rounding residue after an echo).
class PulseSpreader {
 public:
  explicit PulseSpreader(std::size_t bins = 0) { Reset(bins); }

  /// Empties the spreader and sizes it for `bins` bins.
  void Reset(std::size_t bins) {
    edges_.assign(bins, Edges{});
    empty_ = true;
  }

  [[nodiscard]] std::size_t Bins() const { return edges_.size(); }

  /// Adds `power` per bin over [start, end) bins (start ≤ end; parts beyond the last bin, or
  /// before bin 0, are dropped).
  // Inlined: the synthesis calls it for every echo of every ray.
  [[gnu::always_inline]] void Add(double start, double end, double power) {
    empty_ = false;
    Edge(start, power, 1);
    Edge(end, -power, -1);
  }

  /// Adds every bin's sum to `out` (one value per bin) and empties the spreader.
  void AddTo(std::span<double> out) {
    if (empty_) return;
    empty_ = true;
    double running = 0.0;
    int open = 0;
    for (std::size_t k = 0; k < out.size() && k < edges_.size(); ++k) {
      Edges& e = edges_[k];
      out[k] += std::max(0.0, (open > 0 ? running : 0.0) + e.partial);
      running += e.opened;
      open += e.count;
      if (open == 0) running = 0.0;
      e = Edges{};
    }
  }

 private:
  [[gnu::always_inline]] void Edge(double at, double power, int count) {
    at = std::max(at, 0.0);
    if (!(at < static_cast<double>(edges_.size()))) return;
    const auto k = static_cast<std::size_t>(at);
    Edges& e = edges_[k];
    e.opened += power;
    e.partial += power * (static_cast<double>(k + 1) - at);
    e.count += count;
  }

  /// A bin's edges: the power of the boxes they open (+) or close (-), their partial
  /// contributions to the bin, and their count, side by side for the edge updates.
  struct Edges {
    double opened = 0.0;
    double partial = 0.0;
    int count = 0;
  };
  std::vector<Edges> edges_;
  bool empty_ = true;  // no box added since the last AddTo or Reset
};

}  // namespace sonarbench::sim
