#pragma once

// The fidelity statistics' texture and per-head-angle parts (fidelity_texture.cpp), for
// fidelity.cpp's Measure.

#include <span>
#include <utility>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"
#include "sonarbench/sim/eval/fidelity.hpp"

namespace sonarbench::sim::fidelity_parts {

// The head-angle step of a beam, in [0, steps).
inline std::size_t StepIndex(const mapping::Beam& beam, const mapping::SensorGeometry& sensor) {
  const int steps = sensor.BeamsPerSweep();
  const long step = std::lround(beam.head_angle_rad / sensor.step_angle_rad);
  return static_cast<std::size_t>(((step % steps) + steps) % steps);
}

// Each beam's bins [first, bins) (fewer for a short beam), less the beam's mean over them.
std::vector<std::vector<double>> CentredRows(std::span<const mapping::Beam> beams,
                                             std::size_t first, std::size_t bins);

// Each beam's bins [first, bins) (fewer for a short beam), less the beam's mean over the bins
// within FidelityReport::kLocalReach of each (from the whole beam, fewer at its ends).
std::vector<std::vector<double>> LocallyCentredRows(std::span<const mapping::Beam> beams,
                                                    std::size_t first, std::size_t bins);

// Stats::local_contrast from the beams' locally centred rows of bins [first, ...).
double LocalContrast(std::span<const mapping::Beam> beams,
                     const std::vector<std::vector<double>>& rows, std::size_t first);

// Stats::range_correlation from the beams' centred rows.
std::vector<double> RangeCorrelation(const std::vector<std::vector<double>>& rows);

// Stats::beam_correlation from the beams' centred rows.
std::vector<double> BeamCorrelation(std::span<const mapping::Beam> beams,
                                    const std::vector<std::vector<double>>& rows,
                                    const mapping::SensorGeometry& sensor);

// Stats::sweep_spread: per head-angle step and usable bin, the standard deviation over the
// sweeps that saw it (two or more), averaged over those cells.
double SweepSpread(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor);

// The bins [first, end) among the first `bins` whose centres (k + ½) bins lie in band `band` of
// FidelityReport::kRangeBandsM (empty when none does).
std::pair<std::size_t, std::size_t> BandBins(std::size_t band, double bin_size_m, std::size_t bins);

// Stats::sweep_spread_by_band: SweepSpread over the usable bins of each band.
FidelityReport::RangeBands SweepSpreadByBand(std::span<const mapping::Beam> beams,
                                             const mapping::SensorGeometry& sensor);

// FidelityReport::HeadAngleCells over bins [first, last] (last < bins).
FidelityReport::HeadAngleCells HeadAngleStats(std::span<const mapping::Beam> beams,
                                              const mapping::SensorGeometry& sensor,
                                              std::size_t first, std::size_t last);

}  // namespace sonarbench::sim::fidelity_parts
