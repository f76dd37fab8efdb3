#include "cli.hpp"

#include <omp.h>

#include <cmath>
#include <cstdlib>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"

namespace sonarbench::app {

std::string MetricsLine(const sonarbench::sim::MapMetrics& m) {
  // A share of `total` cells and the count behind it (the shares are ratios of these counts).
  auto share = [](double value, std::size_t total) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3f (%.0f/%zu)", value,
                  std::round(value * static_cast<double>(total)), total);
    return std::string(text);
  };
  char f1[16];
  std::snprintf(f1, sizeof f1, "%.3f", m.f1_within[1]);
  std::ostringstream line;
  line << "within a cell: precision " << share(m.precision_within[1], m.occupied_cells)
       << ", recall " << share(m.recall_within[1], m.observable_cells) << ", F1 " << f1
       << "; ghosts " << share(m.ghost_share, m.occupied_cells);
  if (m.ghost_arc_share && m.ghost_echo_share) {
    line << ": on echoes' arcs " << share(*m.ghost_arc_share, m.occupied_cells)
         << ", where no surface answers " << share(*m.ghost_echo_share, m.occupied_cells);
  }
  line << "\n  exact cells: precision " << share(m.occupied_precision, m.occupied_cells)
       << ", recall " << share(m.occupied_recall, m.observable_cells) << ", coverage "
       << share(m.coverage, m.observable_cells);
  return line.str();
}

namespace {

// The edit distance between `a` and `b` (insertions, deletions, substitutions).
std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// "--out", the option of `command` nearest `given` (at most two edits; `given` itself when the
// command has it), or "".
std::string NearestOption(const CLI::App& command, const std::string& given) {
  std::string nearest;
  std::size_t best = 3;
  for (const CLI::Option* option : command.get_options()) {
    for (const std::string& name : option->get_lnames()) {
      const std::size_t d = EditDistance(given, "--" + name);
      if (d < best) best = d, nearest = "--" + name;
    }
  }
  return nearest;
}

}  // namespace

std::string ParseErrorMessage(const CLI::App& cli, const CLI::ParseError& error, int argc,
                              char** argv) {
  const auto parsed = cli.get_subcommands();
  const CLI::App& command = parsed.empty() ? cli : *parsed.front();
  const std::string name = parsed.empty() ? "" : command.get_name();
  std::string what = error.what();
  if (!what.empty()) what[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(what[0])));
  // An option the command does not have, named with the nearest it has.
  std::string hint;
  for (int i = 1; i < argc && hint.empty(); ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0 || arg == "--") continue;
    const std::string option = arg.substr(0, arg.find('='));
    const std::string nearest = NearestOption(command, option);
    if (nearest == option) continue;
    hint = option + " is no option of " + (name.empty() ? "sonarbench" : name) +
           (nearest.empty() ? "" : "; did you mean " + nearest + "?") + "; ";
  }
  return "sonarbench: error: " + (name.empty() ? "" : name + ": ") + what + " (" + hint +
         "sonarbench " + (name.empty() ? "" : name + " ") + "--help)";
}

std::string Count(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::string Seconds3(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", seconds);
  return text;
}

std::string DetectionLine(const mapping::MapperConfig& config) {
  const nlohmann::json mapping = sim::MapperConfigJson(config);
  const nlohmann::json& detection = mapping["detection"];
  std::string line = detection.value("method", "?");
  if (line == "threshold") line += " " + detection["threshold"].dump();
  line += detection["max_obstacles"] == 1
              ? ", the first echo a beam"
              : ", at most " + detection["max_obstacles"].dump() +
                    " echoes a beam (later echoes: " + detection.value("later_echoes", "?") + ")";
  if (detection.value("behind_walls", "keep") == "refuse") line += ", none behind a wall";
  return line + ", " + mapping.value("occupancy", "?") + " at " + mapping["resolution_m"].dump() +
         " m";
}

void PrintVerdict(const std::string& name, const sonarbench::sim::Verdict& v) {
  using sonarbench::sim::CriterionStatus;
  std::size_t met = 0;
  std::size_t not_applicable = 0;
  for (const auto& c : v.results) {
    not_applicable += c.status == CriterionStatus::kNotApplicable;
    met += c.status == CriterionStatus::kPass || c.status == CriterionStatus::kAcceptable;
  }
  for (const auto& w : v.warnings) std::cout << "warning: " << w << "\n";
  std::cout << (v.passed ? "PASS " : "FAIL ") << name << ": " << met << "/"
            << v.results.size() - not_applicable << " criteria met"
            << (not_applicable ? ", " + std::to_string(not_applicable) + " not applicable" : "")
            << (v.expect_fail ? " (the scene expects a failure)" : "") << "\n";
  for (const auto& reason : v.reasons) std::cout << "  " << reason << "\n";
}

io::OutputClaim OneShotClaim(std::string command, std::vector<std::string> files,
                             std::vector<std::string> inputs) {
  namespace sim = sonarbench::sim;
  std::erase(inputs, std::string());
  std::string what = command;
  for (const std::string& input : inputs) what += "\n" + input;
  io::OutputClaim claim;
  claim.command = std::move(command);
  claim.config_sha256 = sonarbench::io::Sha256(what);
  claim.mode = io::OutputMode::kReplace;
  claim.record = files.front();
  claim.files = std::move(files);
  claim.inputs = std::move(inputs);
  return claim;
}

sonarbench::sim::Shard ResolveShard(const std::string& option) {
  if (!option.empty()) return sonarbench::sim::ParseShard(option);
  return sonarbench::sim::ShardFromSlurm().value_or(sonarbench::sim::Shard{});
}

void AddSeedOption(CLI::App* command, std::optional<std::uint64_t>& seed,
                   const std::string& description) {
  command->add_option("-s,--seed", seed, description)
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            if (ParsedWhole<std::uint64_t>(text)) return "";
            return "expected an integer from 0 to 18446744073709551615, got '" + text + "'";
          },
          "UINT64"));
}

namespace {

// A budget: a finite number above 0 (CLI11's PositiveNumber takes "nan" and "inf", and its range
// message prints the double's whole range).
CLI::Validator BudgetNumber() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (!text.empty() && end == text.c_str() + text.size() && std::isfinite(value) &&
            value > 0.0 && value <= 1e15) {
          return "";
        }
        return "expected a number above 0 and at most 1e15 (e.g. 2e8), got " +
               sonarbench::io::Quoted(text);
      },
      "NUMBER > 0");
}

}  // namespace

void AddBudgetOptions(CLI::App* command, sonarbench::sim::Budgets& budgets) {
  command
      ->add_option("--max-triangles", budgets.max_triangles,
                   "Refuse a scene whose meshes would make more triangles (estimated from the "
                   "scene before anything is built)")
      ->check(BudgetNumber())
      ->capture_default_str();
  command
      ->add_option("--max-cells", budgets.max_cells,
                   "Refuse a scene whose ground truth or map would hold more cells (estimated "
                   "from the scene, or the log's poses, before anything is built)")
      ->check(BudgetNumber())
      ->capture_default_str();
  command
      ->add_option("--max-beams", budgets.max_beams,
                   "Refuse a scene whose sweeps would make more beams (each held in memory)")
      ->check(BudgetNumber())
      ->capture_default_str();
}

void AddThreadsOption(CLI::App* command, int& threads) {
  command
      ->add_option("-j,--threads", threads,
                   "Threads; 0 = all cores. Outputs are identical for any value.")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            const std::optional<int> n = ParsedWhole<int>(text);
            if (n && *n >= 0 && *n <= 1024) return "";
            return "expected a whole number of threads from 0 (all cores) to 1024, got " +
                   sonarbench::io::Quoted(text);
          },
          "0-1024"))
      ->capture_default_str();
  // Every parallel loop that names no thread count, the images' too, takes this one.
  command->parse_complete_callback([&threads] {
    if (threads > 0) omp_set_num_threads(threads);
  });
}

}  // namespace sonarbench::app
