#include "cli.hpp"

#include <omp.h>

#include <cmath>

#include "sonarbench/io/dataset.hpp"
#include "sonarbench/mapping/atomic_file.hpp"

namespace sonarbench::app {

std::string MetricsLine(const sonarbench::sim::MapMetrics& m) {
  std::ostringstream line;
  line << "occupied precision " << m.occupied_precision << " (" << m.true_positive_cells << "/"
       << m.occupied_cells << "), recall " << m.occupied_recall << " (" << m.observed_occupied_cells
       << "/" << m.observable_cells << "), coverage " << m.coverage << " ("
       << m.known_observable_cells << "/" << m.observable_cells << ")";
  return line.str();
}

void PrintVerdict(const std::string& name, const sonarbench::sim::Verdict& v) {
  std::size_t met = 0;
  for (const auto& c : v.results) met += c.status != sonarbench::sim::CriterionStatus::kFail;
  for (const auto& w : v.warnings) std::cout << "warning: " << w << "\n";
  std::cout << (v.passed ? "PASS " : "FAIL ") << name << ": " << met << "/" << v.results.size()
            << " criteria met" << (v.expect_fail ? " (the scene expects a failure)" : "") << "\n";
  for (const auto& reason : v.reasons) std::cout << "  " << reason << "\n";
}

sonarbench::sim::OutputClaim OneShotClaim(std::string command, std::vector<std::string> files,
                                          std::vector<std::string> inputs) {
  namespace sim = sonarbench::sim;
  std::erase(inputs, std::string());
  std::string what = command;
  for (const std::string& input : inputs) what += "\n" + input;
  sim::OutputClaim claim;
  claim.command = std::move(command);
  claim.config_sha256 = sonarbench::mapping::Sha256(what);
  claim.mode = sim::OutputMode::kReplace;
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

void AddBudgetOptions(CLI::App* command, sonarbench::sim::Budgets& budgets) {
  command
      ->add_option("--max-triangles", budgets.max_triangles,
                   "Refuse a scene whose meshes would make more triangles (estimated from the "
                   "scene before anything is built)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--max-cells", budgets.max_cells,
                   "Refuse a scene whose ground truth or map would hold more cells (estimated "
                   "from the scene, or the log's poses, before anything is built)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--max-beams", budgets.max_beams,
                   "Refuse a scene whose sweeps would make more beams (each held in memory)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

void AddThreadsOption(CLI::App* command, int& threads) {
  command
      ->add_option("-j,--threads", threads,
                   "Threads; 0 = all cores. Outputs are identical for any value.")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  // Every parallel loop that names no thread count, the images' too, takes this one.
  command->parse_complete_callback([&threads] {
    if (threads > 0) omp_set_num_threads(threads);
  });
}

}  // namespace sonarbench::app
