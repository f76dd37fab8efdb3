#pragma once

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sonarbench/io/output_directory.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/eval/verdict.hpp"
#include "sonarbench/sim/world/budget.hpp"
#include "sonarbench/sim/world/scene.hpp"

// What the command files of the sonarbench CLI share: exit codes, options, the progress line.
namespace sonarbench::app {

inline constexpr int kExitCriteriaFailed = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInternalError = 3;

/// A command: its subcommand, with options bound to its arguments, and what runs it once parsed.
struct Command {
  CLI::App* cli = nullptr;
  std::function<int()> run;
};

Command AddRunCommand(CLI::App& app);
Command AddMapCommand(CLI::App& app);
Command AddScoreCommand(CLI::App& app);
Command AddFidelityCommand(CLI::App& app);
Command AddSimulateCommand(CLI::App& app);
Command AddSweepCommand(CLI::App& app);
Command AddDetectorsCommand(CLI::App& app);
Command AddImportCommand(CLI::App& app);
Command AddExportCommand(CLI::App& app);

// One self-overwriting progress line on stderr (stage, sweeps done, rate, time left), shown only
// on an interactive terminal outside CI, at most five times a second.
class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  ~ProgressLine() { Clear(); }

  static bool WantedFor(bool disabled_by_user) {
    return !disabled_by_user && isatty(STDERR_FILENO) == 1 && std::getenv("CI") == nullptr;
  }

  void Update(std::string_view stage, std::size_t done, std::size_t total) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (stage != stage_) {
      // A stage starts when the previous one reported its last sweep (or when the run began).
      stage_ = stage;
      stage_start_ = last_event_;
    } else if (done < total && now - last_print_ < std::chrono::milliseconds(200)) {
      last_event_ = now;
      return;
    }
    last_event_ = now;
    last_print_ = now;
    const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    char line[160];
    std::snprintf(line, sizeof line, "\r%-10s %zu/%zu  %.0f s left   ", std::string(stage).c_str(),
                  done, total, rate > 0 ? static_cast<double>(total - done) / rate : 0.0);
    std::cerr << line << std::flush;
    shown_ = true;
  }

  void Clear() {
    if (shown_) std::cerr << "\r" << std::string(60, ' ') << "\r" << std::flush;
    shown_ = false;
  }

 private:
  bool enabled_;
  bool shown_ = false;
  std::string stage_;
  std::chrono::steady_clock::time_point stage_start_;
  std::chrono::steady_clock::time_point last_event_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_print_;
};

/// A map's scores for the terminal: precision, recall and F1 within a cell, the ghosts and their
/// split, each with its count; then the exact cells' precision, recall and coverage.
[[nodiscard]] std::string MetricsLine(const sim::MapMetrics& m);
/// A command line CLI11 refused, as one line: "sonarbench: error: COMMAND: what (did you mean
/// --out?; sonarbench COMMAND --help)", an unknown option matched to the nearest the command has.
[[nodiscard]] std::string ParseErrorMessage(const CLI::App& cli, const CLI::ParseError& error,
                                            int argc, char** argv);
/// "1 sweep", "3 sweeps": `n` and the noun, plural unless one.
[[nodiscard]] std::string Count(std::size_t n, const std::string& noun);
/// A duration for the terminal: "0.045", three decimals [s].
[[nodiscard]] std::string Seconds3(double seconds);
/// "threshold 70, two strongest echoes, ..." : the detection a map used, for the terminal.
[[nodiscard]] std::string DetectionLine(const mapping::MapperConfig& config);
/// Prints the verdict's warnings, "PASS|FAIL NAME: M/N criteria met" and each reason.
void PrintVerdict(const std::string& name, const sim::Verdict& v);
/// What a one-shot command (run, map, fidelity) claims in its --out: `files`, the first of them the
/// record, written last; the files it reads are never written or removed.
[[nodiscard]] io::OutputClaim OneShotClaim(std::string command, std::vector<std::string> files,
                                           std::vector<std::string> inputs);
/// The --shard option's value, else a SLURM array job's shard, else the whole run.
[[nodiscard]] sim::Shard ResolveShard(const std::string& option);

// An option's text as a T, whole and in T's range; nullopt otherwise.
template <typename T>
[[nodiscard]] std::optional<T> ParsedWhole(const std::string& text) {
  T value{};
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc() || stop != end) return std::nullopt;
  return value;
}

/// -s/--seed: a decimal integer from 0 to 2^64 - 1, checked as text (CLI11 would take "-1" as
/// 2^64 - 1 and a seed past the top as the top).
void AddSeedOption(CLI::App* command, std::optional<std::uint64_t>& seed,
                   const std::string& description);
/// --max-triangles and --max-cells: what a run may build (Budgets), checked before building.
void AddBudgetOptions(CLI::App* command, sim::Budgets& budgets);
/// The --threads option every subcommand has.
void AddThreadsOption(CLI::App* command, int& threads);

}  // namespace sonarbench::app
