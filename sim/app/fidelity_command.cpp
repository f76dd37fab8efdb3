#include <array>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/fidelity.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/ray_tracer.hpp"
#include "sonarbench/sim/simulation.hpp"

namespace sonarbench::app {
namespace {

struct FidelityArgs {
  bool no_progress = false;
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string log;
  std::string out = "out/fidelity";
  std::optional<std::uint64_t> seed;
  int threads = 0;
  double wall_min_range_m = 1.6;
};

// One line of `sonarbench fidelity`'s summary: FidelityReport::HeadAngleCells of both runs.
std::string HeadAngleLine(const std::string& what,
                          const sonarbench::sim::FidelityReport::HeadAngleCells& simulated,
                          const sonarbench::sim::FidelityReport::HeadAngleCells& real) {
  std::ostringstream line;
  line << what << " (bins " << real.first_bin << "-" << real.last_bin << "): mean sim "
       << simulated.mean << ", real " << real.mean << "; ping to ping sim " << simulated.ping_spread
       << ", real " << real.ping_spread << "; across head angles sim " << simulated.angle_spread
       << ", real " << real.angle_spread << ", correlated at 1/"
       << sonarbench::sim::FidelityReport::kRingingFarStep << " head steps sim "
       << simulated.angle_correlation[0] << "/" << simulated.angle_correlation[1] << ", real "
       << real.angle_correlation[0] << "/" << real.angle_correlation[1] << "\n";
  return line.str();
}

// Values as "a/b/c", to one decimal.
template <std::size_t N>
std::string Slashed(const std::array<double, N>& values) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1);
  for (std::size_t i = 0; i < N; ++i) text << (i > 0 ? "/" : "") << values[i];
  return text.str();
}

int Fidelity(const FidelityArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::CheckOutputDirectory(args.out);
  const sim::Scene scene = LoadScene(args.scene, args.budgets);
  if (const double range = scene.sensor.geometry.MaxRangeM(); args.wall_min_range_m >= range) {
    std::ostringstream message;
    message << "--wall-min-range " << args.wall_min_range_m << ": expected less than the sonar's "
            << range << " m range (no echo lies past it)";
    throw sonarbench::InputError(message.str());
  }
  const sonarbench::mapping::MatLog log = sonarbench::mapping::ReadMatLog(args.log);
  const auto meshes = sim::BuildSceneMeshes(scene);
  std::vector<std::string> inputs = sim::SceneInputFiles(scene);
  inputs.push_back(args.log);
  sim::OutputDirectory out(args.out, OneShotClaim("fidelity", sim::kFidelityOutputFiles, inputs));
  const sim::RayTracer tracer(meshes);
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  const auto synthesized = sim::SimulateScene(
      scene, tracer, args.seed.value_or(scene.seed), args.threads,
      [&](std::size_t done, std::size_t total) { progress.Update("simulate", done, total); });
  progress.Clear();
  const std::vector<sonarbench::mapping::Beam> beams = sim::BeamsOf(synthesized);
  const auto& g = scene.sensor.geometry;
  const auto report = sim::CompareWithLog(beams, log.beams, g, args.wall_min_range_m);
  const auto per_sweep = static_cast<std::size_t>(g.BeamsPerSweep());
  const std::span<const sonarbench::mapping::Beam> sim_all(beams);
  const std::span<const sonarbench::mapping::Beam> real_all(log.beams);
  sim::WriteFidelityOutputs(
      out.write_root().string(), report, sim_all.first(std::min(per_sweep, sim_all.size())),
      real_all.first(std::min(per_sweep, real_all.size())), g, args.scene, args.log);
  out.Commit();
  std::cout << "mean intensity vs range: correlation " << report.profile_correlation_all
            << " (all bins), " << report.profile_correlation_usable
            << " (past self-reflection); mean |difference| " << report.profile_mean_abs_difference
            << " (past self-reflection)\n"
            << "mean intensity by range [m], sim / real:";
  const auto show = [](const std::optional<double>& v) {
    std::ostringstream text;
    if (v) {
      text << std::fixed << std::setprecision(1) << *v;
    } else {
      text << "none";
    }
    return text.str();
  };
  // Each band as "from-to sim / real".
  const auto by_band = [&](const sim::FidelityReport::RangeBands& sim_values,
                           const sim::FidelityReport::RangeBands& real_values) {
    std::ostringstream text;
    for (std::size_t b = 0; b < sim::FidelityReport::kRangeBandsM.size(); ++b) {
      text << (b == 0 ? " " : ", ") << sim::FidelityReport::kRangeBandsM[b][0] << "-"
           << sim::FidelityReport::kRangeBandsM[b][1] << " " << show(sim_values[b]) << " / "
           << show(real_values[b]);
    }
    return text.str();
  };
  std::cout << by_band(report.sim_band_means, report.real_band_means) << "\n"
            << "wall range: median difference " << report.median_wall_difference_bins
            << " bins over " << report.wall_angles_compared << " head angles\n"
            << "wall echo intensity, 10th/50th/90th percentile over beams: sim "
            << report.sim_wall_peak[0] << "/" << report.sim_wall_peak[1] << "/"
            << report.sim_wall_peak[2] << ", real " << report.real_wall_peak[0] << "/"
            << report.real_wall_peak[1] << "/" << report.real_wall_peak[2]
            << "; behind it (16-120 bins), mean |difference| "
            << report.wall_tail_mean_abs_difference << "\n"
            << "behind the walls (mean " << sim::FidelityReport::kBehindFirst << "-"
            << sim::FidelityReport::kBehindLast << " bins past the strongest echo), beams within "
            << sim::FidelityReport::kSquareDeg << " deg of a side's normal / "
            << sim::FidelityReport::kCornerFromDeg << "-45 deg off it: sim "
            << report.sim_behind_walls[0] << " / " << report.sim_behind_walls[1] << ", real "
            << report.real_behind_walls[0] << " / " << report.real_behind_walls[1]
            << "; within it, by side (0/90/180/270 deg): sim "
            << Slashed(report.sim_behind_walls_by_side) << ", real "
            << Slashed(report.real_behind_walls_by_side) << "\n"
            << "wall echo's front (20 bins before the strongest, over the beams whose strongest "
               "echo is the simulated wall: sim "
            << report.sim_direct_wall_beams << ", real " << report.real_direct_wall_beams
            << " beams): mean |difference| " << report.wall_front_mean_abs_difference << "\n"
            << "second trip (around twice the strongest echo's bin, offsets -30..+10): excess "
               "over its flanks sim "
            << report.sim_second_trip_excess << " (" << report.sim_second_trip_beams
            << " beams), real " << report.real_second_trip_excess << " ("
            << report.real_second_trip_beams
            << " beams) [intensity x bins]; profile mean |difference| "
            << report.second_trip_mean_abs_difference << "\n"
            << "intensity histograms: intersection " << report.histogram_intersection
            << "; values held: sim " << report.sim_values << ", real " << report.real_values
            << ", sim's never in the real log " << report.sim_values_not_real << "\n"
            << "range correlation at 1/2/3 bins (far half): sim " << report.sim_range_correlation[1]
            << "/" << report.sim_range_correlation[2] << "/" << report.sim_range_correlation[3]
            << ", real " << report.real_range_correlation[1] << "/"
            << report.real_range_correlation[2] << "/" << report.real_range_correlation[3] << "\n"
            << "beam-to-beam correlation at 1/2/3 head steps (far half): sim "
            << report.sim_beam_correlation[1] << "/" << report.sim_beam_correlation[2] << "/"
            << report.sim_beam_correlation[3] << ", real " << report.real_beam_correlation[1] << "/"
            << report.real_beam_correlation[2] << "/" << report.real_beam_correlation[3] << "\n"
            << "fine texture (less each bin's mean over +-" << sim::FidelityReport::kLocalReach
            << " bins): range correlation at 1/2/3 bins sim "
            << report.sim_local_range_correlation[1] << "/" << report.sim_local_range_correlation[2]
            << "/" << report.sim_local_range_correlation[3] << ", real "
            << report.real_local_range_correlation[1] << "/"
            << report.real_local_range_correlation[2] << "/"
            << report.real_local_range_correlation[3] << "; across 1/2/3 head steps sim "
            << report.sim_local_beam_correlation[1] << "/" << report.sim_local_beam_correlation[2]
            << "/" << report.sim_local_beam_correlation[3] << ", real "
            << report.real_local_beam_correlation[1] << "/" << report.real_local_beam_correlation[2]
            << "/" << report.real_local_beam_correlation[3] << "; contrast sim "
            << report.sim_local_contrast << ", real " << report.real_local_contrast << "\n"
            << "sweep-to-sweep spread per head angle and bin: sim " << report.sim_sweep_spread
            << ", real " << report.real_sweep_spread << "; by range [m], sim / real:"
            << by_band(report.sim_sweep_spread_by_band, report.real_sweep_spread_by_band) << "\n"
            << HeadAngleLine("self-reflection", report.sim_ringing, report.real_ringing)
            << HeadAngleLine("near range past it", report.sim_near_range, report.real_near_range)
            << "wrote " << args.out << "/fidelity.json\n";
  return 0;
}

// `sonarbench fidelity`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, FidelityArgs& args) {
  CLI::App* command = app.add_subcommand(
      "fidelity",
      "Compare a simulated scene with a real log of the same place: mean intensity against range "
      "(correlation), the strongest echo's range per head angle (median difference in bins) and "
      "its intensity (percentiles), the profile around it (the tail behind the walls; and its "
      "front, over the beams whose strongest echo is the simulated wall) and around twice its "
      "range (the second trip), intensity histograms (intersection), the texture along range "
      "and across beams (correlations), and the first sweeps side by side (sim left, real "
      "right). Writes fidelity.json, profile.csv/.png, wall_range.csv, wall_profile.csv, "
      "direct_wall_profile.csv, second_trip_profile.csv, histogram.csv, by_head_angle.csv (the "
      "self-reflection's and the near range's mean per head angle), polar.png and fan.png into "
      "--out.");
  command->add_option("scene", args.scene, "Scene YAML file")->required()->check(CLI::ExistingFile);
  command->add_option("log", args.log, "Real log (.mat)")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Output directory")->capture_default_str();
  AddSeedOption(command, args.seed, "Overrides the scene's seed");
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  command
      ->add_option("--wall-min-range", args.wall_min_range_m,
                   "Strongest echoes are sought beyond this range [m] (past the floor's)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            const std::optional<double> range = ParsedWhole<double>(text);
            if (range && std::isfinite(*range) && *range > 0.0) return "";
            return "expected a range in metres, finite and above 0, got '" + text + "'";
          },
          "METRES"))
      ->capture_default_str();
  return command;
}

}  // namespace

Command AddFidelityCommand(CLI::App& app) {
  auto args = std::make_shared<FidelityArgs>();
  return {AddOptions(app, *args), [args] { return Fidelity(*args); }};
}

}  // namespace sonarbench::app
