#include "sonarbench/sim/scenario.hpp"

#include <omp.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/sim/ground_truth.hpp"
#include "sonarbench/sim/images.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/ray_tracer.hpp"
#include "sonarbench/sim/report.hpp"
#include "sonarbench/sim/simulation.hpp"

namespace sonarbench::sim {
namespace {

class Stopwatch {
 public:
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

constexpr double kRadToDeg = 1.0 / mapping::kDegToRad;

nlohmann::json DistanceJson(const DistanceStats& d) {
  return {{"count", d.count}, {"mean_m", d.mean_m}, {"p95_m", d.p95_m}, {"max_m", d.max_m}};
}

const char* DetectionMethodName(mapping::DetectionConfig::Method method) {
  switch (method) {
    case mapping::DetectionConfig::Method::kThreshold:
      return "threshold";
    case mapping::DetectionConfig::Method::kCanny:
      return "canny";
    case mapping::DetectionConfig::Method::kAutoCanny:
      return "auto_canny";
  }
  return "?";
}

nlohmann::json MappingJson(const mapping::MapperConfig& c) {
  return {{"resolution_m", c.resolution_m},
          {"rays_horizontal", c.rays_horizontal},
          {"rays_vertical", c.rays_vertical},
          {"detection",
           {{"method", DetectionMethodName(c.detection.method)},
            {"threshold", c.detection.threshold},
            {"smoothing_bins", c.detection.smoothing_bins},
            {"min_run_bins", c.detection.min_run_bins},
            {"max_obstacles", c.detection.max_obstacles},
            {"canny_low", c.detection.canny_low},
            {"canny_high", c.detection.canny_high},
            {"canny_blur_sigma", c.detection.canny_blur_sigma},
            {"auto_canny_sigma", c.detection.auto_canny_sigma}}},
          {"key_set", c.key_set == mapping::KeySetKind::kStd ? "std" : "open_addressing"},
          {"prob_hit", c.prob_hit},
          {"prob_miss", c.prob_miss},
          {"clamp_min", c.clamp_min},
          {"clamp_max", c.clamp_max},
          {"clear_without_obstacle", c.clear_without_obstacle},
          {"free_range_m", c.free_range_m}};
}

nlohmann::json SensorJson(const SensorModel& s) {
  const auto& g = s.geometry;
  const auto& a = s.acoustics;
  return {{"name", s.name},
          {"geometry",
           {{"beam_width_horizontal_deg", g.beam_width_horizontal_rad * kRadToDeg},
            {"beam_width_vertical_deg", g.beam_width_vertical_rad * kRadToDeg},
            {"num_bins", g.num_bins},
            {"bin_size_m", g.bin_size_m},
            {"step_angle_deg", g.step_angle_rad * kRadToDeg},
            {"beams_per_second", g.beams_per_second},
            {"self_reflection_range_m", g.self_reflection_range_m}}},
          {"acoustics",
           {{"rays_horizontal", a.rays_horizontal},
            {"rays_vertical", a.rays_vertical},
            {"aperture_scale", a.aperture_scale},
            {"spreading_db_per_decade", a.spreading_db_per_decade},
            {"absorption_db_per_m", a.absorption_db_per_m},
            {"tvg_db_per_decade", a.tvg_db_per_decade},
            {"gain_db", a.gain_db},
            {"pulse_length_m", a.pulse_length_m},
            {"noise_level_db", a.noise_level_db},
            {"speckle", a.speckle},
            {"ad_low_db", a.ad_low_db},
            {"ad_span_db", a.ad_span_db},
            {"self_reflection_db", a.self_reflection_db}}}};
}

}  // namespace

ScenarioResult RunScenario(const Scene& scene, const RunOptions& options) {
  ScenarioResult result;
  result.seed = options.seed.value_or(scene.seed);
  result.threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  Stopwatch clock;

  const std::vector<TriangleMesh> meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  result.timings.build_scene_s = clock.Lap();

  const std::vector<SynthesizedBeam> synthesized =
      SimulateScene(scene, tracer, result.seed, result.threads);
  result.beams = synthesized.size();
  result.timings.simulate_s = clock.Lap();

  mapping::MapperConfig mapper_config = scene.mapping;
  mapper_config.threads = result.threads;
  result.mapper = std::make_unique<mapping::Mapper>(mapper_config, scene.sensor.geometry);
  const std::vector<mapping::Beam> beams = BeamsOf(synthesized);
  result.mapping_totals = result.mapper->IntegrateSweeps(beams);
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  result.first_sweep.assign(beams.begin(),
                            beams.begin() + static_cast<long>(std::min(per_sweep, beams.size())));
  result.timings.map_s = clock.Lap();

  const octomap::OcTree& map = result.mapper->tree();
  result.truth = VoxelizeMeshes(meshes, map);
  std::vector<BeamPose> poses;
  for (std::size_t b = 0; b < synthesized.size(); ++b) poses.push_back(ScheduleBeam(scene, b).pose);
  // A perfect sensor: rays twice as dense as the acoustic sampling in each direction.
  const Acoustics& a = scene.sensor.acoustics;
  result.observable = ObservableSurfaceCells(tracer, poses, scene.sensor.geometry,
                                             2 * a.rays_horizontal, 2 * a.rays_vertical, map);
  result.timings.ground_truth_s = clock.Lap();

  result.metrics = ScoreMap(map, result.truth, result.observable, meshes);
  result.timings.score_s = clock.Lap();
  return result;
}

void WriteScenarioOutputs(const std::string& out_dir, const Scene& scene,
                          const ScenarioResult& result) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  const fs::path dir(out_dir);
  result.mapper->WriteBinary((dir / "map.bt").string());
  WritePolarImage((dir / "polar.png").string(), result.first_sweep);
  WriteFanImage((dir / "fan.png").string(), result.first_sweep, 0.01);
  WriteTopDownImage((dir / "map_top.png").string(), CollectMapCells(result.mapper->tree()),
                    result.truth, result.observable);

  const MapMetrics& m = result.metrics;
  const StageTimings& t = result.timings;
  nlohmann::json report = ReportHeader();
  report.update(
      {{"scene",
        {{"name", scene.name}, {"file", scene.file}, {"sensor_model", scene.sensor_model_file}}},
       {"seed", result.seed},
       {"threads", result.threads},
       {"parameters",
        {{"sweeps", scene.sweeps},
         {"beams", result.beams},
         {"start_head_angle_deg", scene.start_head_angle_rad * kRadToDeg},
         {"sensor", SensorJson(scene.sensor)},
         {"mapping", MappingJson(result.mapper->config())}}},
       {"metrics",
        {{"occupied_precision", m.occupied_precision},
         {"occupied_recall", m.occupied_recall},
         {"occupied_f1", m.occupied_f1},
         {"coverage", m.coverage},
         {"coverage_absolute", m.coverage_absolute},
         {"free_accuracy", m.free_accuracy},
         {"surface_distance",
          {{"map_to_mesh", DistanceJson(m.map_to_mesh)},
           {"mesh_to_map", DistanceJson(m.mesh_to_map)}}},
         {"counts",
          {{"truth_cells", m.truth_cells},
           {"observable_cells", m.observable_cells},
           {"occupied_cells", m.occupied_cells},
           {"free_cells", m.free_cells},
           {"true_positive_cells", m.true_positive_cells},
           {"observed_occupied_cells", m.observed_occupied_cells},
           {"known_observable_cells", m.known_observable_cells},
           {"free_on_surface_cells", m.free_on_surface_cells}}}}},
       {"mapping_totals",
        {{"beams", result.mapping_totals.beams},
         {"beams_with_obstacle", result.mapping_totals.beams_with_obstacle},
         {"ray_casts", result.mapping_totals.ray_casts},
         {"cell_visits", result.mapping_totals.cell_visits},
         {"free_cell_updates", result.mapping_totals.free_cells},
         {"occupied_cell_updates", result.mapping_totals.occupied_cells}}},
       {"timing",
        {{"build_scene_s", t.build_scene_s},
         {"simulate_s", t.simulate_s},
         {"map_s", t.map_s},
         {"ground_truth_s", t.ground_truth_s},
         {"score_s", t.score_s},
         {"total_s", t.build_scene_s + t.simulate_s + t.map_s + t.ground_truth_s + t.score_s}}},
       {"outputs",
        {{"map", "map.bt"},
         {"polar", "polar.png"},
         {"fan", "fan.png"},
         {"map_top", "map_top.png"}}}});
  WriteJson((dir / "report.json").string(), report);
}

}  // namespace sonarbench::sim
