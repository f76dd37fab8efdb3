#include <optional>

#include "bindings.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"

namespace sonarbench::python {
namespace {

PyScene LoadScene(const py::object& path, double max_triangles, double max_cells,
                  double max_beams) {
  sim::Budgets budgets;
  budgets.max_triangles = max_triangles;
  budgets.max_cells = max_cells;
  budgets.max_beams = max_beams;
  auto scene = std::make_shared<sim::Scene>(sim::LoadScene(PathArg(path), budgets));
  sim::CheckBudgets(*scene, budgets);
  return {std::move(scene)};
}

// A scene's run, simulated sweep by sweep: the world and the synthesizer built once.
class Simulator {
 public:
  Simulator(const PyScene& scene, std::optional<std::uint64_t> seed, int threads)
      : scene_(scene.scene),
        seed_(seed.value_or(scene.scene->seed)),
        threads_(threads),
        world_(std::make_unique<sim::SceneWorld>(*scene_)),
        synthesizer_(sim::SceneSynthesizer(*scene_, world_->tracer, seed_)),
        beam_count_(sim::ScenarioBeamCount(*scene_)),
        per_sweep_(static_cast<std::size_t>(scene_->sensor.geometry.BeamsPerSweep())) {
    if (threads < 0)
      throw InputError("threads: expected 0 (all cores) or more, got " + std::to_string(threads));
  }

  [[nodiscard]] std::size_t sweep_count() const {
    return (beam_count_ + per_sweep_ - 1) / per_sweep_;
  }
  [[nodiscard]] std::uint64_t seed() const { return seed_; }

  // Sweep `k` as `simulate` writes it (beams/sweep_k.bin, truth/labels_k.bin).
  [[nodiscard]] Sweep SimulateSweep(std::size_t k, bool labels) {
    if (k >= sweep_count()) {
      throw py::index_error("sweep " + std::to_string(k) + ": the scene has " +
                            std::to_string(sweep_count()) + " sweeps");
    }
    const py::gil_scoped_release release;
    const std::size_t first = k * per_sweep_;
    sim::SimulateBeamsInto(*scene_, synthesizer_, seed_, threads_, first,
                           std::min(beam_count_, first + per_sweep_),
                           labels ? sim::Labels::kKeep : sim::Labels::kDrop, synthesized_);
    const std::vector<mapping::Beam> beams = sim::BeamsOf(synthesized_);
    if (labels) sim::LabelFileBeams(synthesized_, threads_, labels_);
    return SweepOf(
        k, beams,
        labels ? std::span<const io::BeamLabels>(labels_) : std::span<const io::BeamLabels>());
  }

 private:
  std::shared_ptr<const sim::Scene> scene_;
  std::uint64_t seed_;
  int threads_;
  std::unique_ptr<sim::SceneWorld> world_;  // the synthesizer holds its tracer
  sim::BeamSynthesizer synthesizer_;
  std::size_t beam_count_;
  std::size_t per_sweep_;
  std::vector<sim::SynthesizedBeam> synthesized_;  // a sweep's, its memory kept for the next
  std::vector<io::BeamLabels> labels_;             // the same
};

// Simulator.sweeps(): each sweep in turn, simulated when asked for.
struct SweepIterator {
  Simulator* simulator;
  std::size_t next;
  bool labels;
};

void DefSceneClass(py::module_& m) {
  py::class_<PyScene>(m, "Scene", "A scene file loaded with its sensor model (load_scene).")
      .def_property_readonly("name", [](const PyScene& s) { return s.scene->name; })
      .def_property_readonly("file", [](const PyScene& s) { return s.scene->file; })
      .def_property_readonly(
          "seed", [](const PyScene& s) { return s.scene->seed; },
          "The scene's own seed (Simulator's default).")
      .def_property_readonly(
          "sweeps", [](const PyScene& s) { return s.scene->sweeps; },
          "Head revolutions of the run.")
      .def_property_readonly("beam_count",
                             [](const PyScene& s) { return sim::ScenarioBeamCount(*s.scene); })
      .def_property_readonly(
          "beams_per_sweep",
          [](const PyScene& s) { return s.scene->sensor.geometry.BeamsPerSweep(); })
      .def_property_readonly("bin_count",
                             [](const PyScene& s) { return s.scene->sensor.geometry.num_bins; })
      .def_property_readonly("bin_size_m",
                             [](const PyScene& s) { return s.scene->sensor.geometry.bin_size_m; })
      .def_property_readonly(
          "mesh_names",
          [](const PyScene& s) {
            std::vector<std::string> names;
            for (const sim::MeshSpec& mesh : s.scene->meshes) names.push_back(mesh.name);
            return names;
          },
          "The scene's meshes in order: a label's mesh index names one of these.")
      .def("__repr__", [](const PyScene& s) {
        return "<sonarbench.Scene '" + s.scene->name + "' from " + s.scene->file + ">";
      });
}

}  // namespace

void BindScene(py::module_& m) {
  DefSceneClass(m);
  m.def("load_scene", &LoadScene, py::arg("path"), py::kw_only(),
        py::arg("max_triangles") = sim::Budgets{}.max_triangles,
        py::arg("max_cells") = sim::Budgets{}.max_cells,
        py::arg("max_beams") = sim::Budgets{}.max_beams,
        "Loads a scene YAML file and the sensor model it names, and checks its budgets as the "
        "command line does (--max-triangles, --max-cells, --max-beams). Raises InputError naming "
        "the file and key.");

  py::class_<SweepIterator>(m, "SweepIterator")
      .def("__iter__", [](SweepIterator& it) -> SweepIterator& { return it; })
      .def("__next__", [](SweepIterator& it) {
        if (it.next >= it.simulator->sweep_count()) throw py::stop_iteration();
        return it.simulator->SimulateSweep(it.next++, it.labels);
      });

  py::class_<Simulator>(m, "Simulator",
                        "A scene's run, simulated sweep by sweep with the scene's world built "
                        "once. Not for use from several Python threads at once.")
      .def(py::init<const PyScene&, std::optional<std::uint64_t>, int>(), py::arg("scene"),
           py::kw_only(), py::arg("seed") = py::none(), py::arg("threads") = 0,
           "seed: the run's seed (default the scene's); threads: 0 for all cores. The beams do "
           "not depend on the thread count.")
      .def_property_readonly("sweep_count", &Simulator::sweep_count)
      .def_property_readonly("seed", &Simulator::seed)
      .def("sweep", &Simulator::SimulateSweep, py::arg("index"), py::kw_only(),
           py::arg("labels") = true,
           "Sweep `index` of the run: the same beams `sonarbench simulate` writes to "
           "beams/sweep_NNNN.bin and, with labels, truth/labels_NNNN.bin. Releases the GIL.")
      .def(
          "sweeps",
          [](Simulator& s, bool labels) {
            return SweepIterator{&s, 0, labels};
          },
          py::kw_only(), py::arg("labels") = true, py::keep_alive<0, 1>(),
          "An iterator over every sweep of the run in order.")
      .def("__len__", &Simulator::sweep_count)
      .def(
          "__getitem__", [](Simulator& s, std::size_t k) { return s.SimulateSweep(k, true); },
          py::arg("index"));
}

}  // namespace sonarbench::python
