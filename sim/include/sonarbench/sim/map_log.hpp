#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::sim {

/// A recorded log run through the production mapper.
struct LogMapResult {
  std::string input;
  /// "mat" (a real .mat log) or "dataset" (a sonarbench dataset directory).
  std::string source;
  std::size_t beams = 0;
  std::size_t sweeps = 0;
  std::size_t truncated_beams = 0;
  double import_s = 0.0;
  double map_s = 0.0;
  mapping::BatchStats totals;
  std::unique_ptr<mapping::Mapper> mapper;
  std::vector<mapping::Beam> first_sweep;
};

/// The `.mat` log to read when `input` is a directory that is not a dataset (no manifest.json)
/// and holds exactly one `.mat` file, as the real log's folder does; "" when `input` is a
/// dataset, a file, or a directory without one. Throws InputError when it holds several.
[[nodiscard]] std::string MatLogInDirectory(const std::string& input);

/// Reads a real `.mat` log (a file, or a folder holding just one, see MatLogInDirectory) or a
/// dataset directory (mapping::ReadDataset; its own sensor geometry replaces `sensor`) and maps it
/// sweep by sweep (BeamsPerSweep() consecutive beams each; the last sweep may be partial). Throws
/// InputError for input that is not a readable log.
[[nodiscard]] LogMapResult MapLog(const std::string& input, const mapping::SensorGeometry& sensor,
                                  const mapping::MapperConfig& config);

/// Writes `map.bt`, `map.ot`, `map_top.png`, `polar.png`, `fan.png` and `report.json` into
/// `out_dir`, each atomically, the report last.
void WriteLogMapOutputs(const std::string& out_dir, const LogMapResult& result);

}  // namespace sonarbench::sim
