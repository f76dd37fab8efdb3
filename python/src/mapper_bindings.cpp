#include <algorithm>
#include <filesystem>
#include <optional>

#include "bindings.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/io/octomap_file.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/world/budget.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::python {
namespace {

// The centre of a cell of `key` in a map of `resolution_m` [m], as OcTree::keyToCoord gives it.
double Centre(octomap::key_type key, double resolution_m) {
  constexpr int kTreeMaxVal = 32768;
  return (static_cast<double>(static_cast<int>(key) - kTreeMaxVal) + 0.5) * resolution_m;
}

py::dict StatsDict(const mapping::BatchStats& s) {
  py::dict d;
  d["beams"] = s.beams;
  d["beams_with_obstacle"] = s.beams_with_obstacle;
  d["free_cells"] = s.free_cells;
  d["occupied_cells"] = s.occupied_cells;
  d["cell_visits"] = s.cell_visits;
  return d;
}

// The production mapper over sweeps given from Python.
class PyMapper {
 public:
  PyMapper(const std::optional<PyScene>& scene, const py::object& sensor_model,
           const std::optional<mapping::SensorGeometry>& sensor, int threads, double max_cells,
           const py::kwargs& keys) {
    budgets_.max_cells = max_cells;
    if (scene && !sensor_model.is_none()) {
      throw InputError("Mapper: give a scene or a sensor_model, not both");
    }
    mapping::MapperConfig config;
    if (scene) {
      sensor_ = scene->scene->sensor.geometry;
      config = scene->scene->mapping;
    } else {
      const std::string path =
          sensor_model.is_none() ? sim::ShippedSensorModelPath() : PathArg(sensor_model);
      const sim::SensorModel model = sim::LoadSensorModel(path);
      sensor_ = model.geometry;
      config = model.mapping;
    }
    if (sensor) sensor_ = *sensor;
    if (keys.size() > 0) {
      // The keyword arguments as a mapping section: JSON is YAML.
      const std::string text = py::module_::import("json").attr("dumps")(keys).cast<std::string>();
      YamlReader reader = YamlReader::FromString(text, "Mapper keyword arguments");
      config = io::ReadMapperConfig(reader, config);
      reader.ThrowIfErrors();
    }
    if (threads < 0) throw InputError("threads: expected 0 (all cores) or more");
    config.threads = threads;
    mapper_ = std::make_unique<mapping::Mapper>(config, sensor_);
  }

  py::dict Integrate(const Sweep& sweep) { return StatsDict(IntegrateOne(sweep)); }

  py::dict IntegrateAll(const py::iterable& sweeps) {
    mapping::BatchStats sum;
    for (const py::handle item : sweeps) {
      sum += IntegrateOne(item.cast<const Sweep&>());
      CheckSignals();
    }
    return StatsDict(sum);
  }

  // The centres of the cells whose occupancy is `occupied` [m], world frame, sorted by key.
  py::array_t<double> Cells(bool occupied) const {
    std::vector<octomap::OcTreeKey> keys;
    {
      const py::gil_scoped_release release;
      mapper_->ForEachLeaf([&](const octomap::OcTreeKey& key, bool is_occupied) {
        if (is_occupied == occupied) keys.push_back(key);
      });
      std::sort(keys.begin(), keys.end(), [](const auto& a, const auto& b) {
        return std::lexicographical_compare(&a[0], &a[0] + 3, &b[0], &b[0] + 3);
      });
    }
    py::array_t<double> out({static_cast<py::ssize_t>(keys.size()), py::ssize_t{3}});
    auto view = out.mutable_unchecked<2>();
    const double res = mapper_->config().resolution_m;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      for (int d = 0; d < 3; ++d) {
        view(static_cast<py::ssize_t>(i), d) = Centre(keys[i][static_cast<unsigned>(d)], res);
      }
    }
    return out;
  }

  // Writes the map to `path` (.bt or .ot), atomically; an existing file only with `overwrite`.
  void Write(const py::object& path_arg, bool full, bool overwrite) const {
    const std::string path = PathArg(path_arg);
    if (!overwrite && std::filesystem::exists(path)) {
      throw InputError(path + ": exists; pass overwrite=True to replace it");
    }
    const py::gil_scoped_release release;
    io::WriteMapFile(*mapper_, path, full ? io::MapFormat::kFull : io::MapFormat::kBinary);
  }

  [[nodiscard]] const mapping::Mapper& mapper() const { return *mapper_; }
  [[nodiscard]] const mapping::SensorGeometry& sensor() const { return sensor_; }

 private:
  mapping::SensorGeometry sensor_;
  std::unique_ptr<mapping::Mapper> mapper_;
  sim::Budgets budgets_;
  std::vector<Eigen::Vector3d> corners_;  // the box of the poses integrated so far, or none
  double reach_m_ = 0.0;                  // the longest beam integrated so far [m]

  mapping::BatchStats IntegrateOne(const Sweep& sweep) {
    const py::gil_scoped_release release;
    std::vector<mapping::Beam> beams = sweep.ToBeams();
    CheckBudget(beams);
    return mapper_->Integrate(beams);
  }

  // Refuses, before the map grows, a sweep that would take the map past max_cells (or out of
  // OctoMap's key range) with the sweeps integrated before it: those stand in as two beams at the
  // corners of their box reaching as far as the longest of them (CheckBeamsMapCells).
  void CheckBudget(std::vector<mapping::Beam>& beams) {
    const std::size_t own = beams.size();
    for (const Eigen::Vector3d& corner : corners_) {
      mapping::Beam stand_in;
      stand_in.T_world_sonar.translation() = corner;
      stand_in.bin_size_m = reach_m_;
      stand_in.intensities.assign(reach_m_ > 0.0 ? 1 : 0, 0);
      beams.push_back(stand_in);
    }
    sim::CheckBeamsMapCells(beams, sensor_, mapper_->config().resolution_m, budgets_,
                            "Mapper.integrate");
    for (std::size_t b = 0; b < own; ++b) {
      const Eigen::Vector3d p = beams[b].T_world_sonar.translation();
      if (corners_.empty()) corners_ = {p, p};
      corners_[0] = corners_[0].cwiseMin(p);
      corners_[1] = corners_[1].cwiseMax(p);
      reach_m_ = std::max(reach_m_,
                          beams[b].bin_size_m * static_cast<double>(beams[b].intensities.size()));
    }
    beams.resize(own);
  }
};

}  // namespace

const mapping::Mapper& MapperOf(const py::handle& mapper) {
  return mapper.cast<const PyMapper&>().mapper();
}

bool IsMapper(const py::handle& object) { return py::isinstance<PyMapper>(object); }

void BindMapper(py::module_& m) {
  py::class_<PyMapper>(m, "Mapper",
                       "The production mapper (detection, beam volumes, OctoMap log-odds). Not "
                       "for use from several Python threads at once.")
      .def(
          py::init<const std::optional<PyScene>&, const py::object&,
                   const std::optional<mapping::SensorGeometry>&, int, double, const py::kwargs&>(),
          py::kw_only(), py::arg("scene") = py::none(), py::arg("sensor_model") = py::none(),
          py::arg("sensor") = py::none(), py::arg("threads") = 0,
          py::arg("max_cells") = sim::Budgets{}.max_cells,
          "The sensor and the mapping section of `scene`, else of `sensor_model` (a YAML "
          "file; default the shipped SHAD Micron's); `sensor` (a Log's) replaces the geometry; "
          "further keyword arguments are keys of a mapping section over those (resolution_m=, "
          "detection={'method': 'ca_cfar', ...}). threads: 0 for all cores; the map does not "
          "depend on it. max_cells: the map's budget (the command line's --max-cells); a sweep "
          "that "
          "would take the map past it is refused before it is integrated.")
      .def("integrate", &PyMapper::Integrate, py::arg("sweep"),
           "Integrates one sweep as one batch (each cell updated once, occupied winning). "
           "Returns its counts. Releases the GIL.")
      .def("integrate_sweeps", &PyMapper::IntegrateAll, py::arg("sweeps"),
           "Integrates each sweep of an iterable in turn (Ctrl-C stops it between sweeps); "
           "returns the summed counts.")
      .def(
          "occupied", [](const PyMapper& p) { return p.Cells(true); },
          "Centres of the occupied cells, N × 3 [m], world frame, in key order.")
      .def(
          "free", [](const PyMapper& p) { return p.Cells(false); },
          "Centres of the free cells, N × 3 [m], world frame, in key order.")
      .def(
          "write_bt",
          [](const PyMapper& p, const py::object& path, bool overwrite) {
            p.Write(path, false, overwrite);
          },
          py::arg("path"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the map as an OctoMap .bt file (the bytes `sonarbench map` writes), atomically.")
      .def(
          "write_ot",
          [](const PyMapper& p, const py::object& path, bool overwrite) {
            p.Write(path, true, overwrite);
          },
          py::arg("path"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the map as an OctoMap .ot file (full probabilities), atomically.")
      .def_property_readonly("resolution_m",
                             [](const PyMapper& p) { return p.mapper().config().resolution_m; })
      .def_property_readonly("sensor", &PyMapper::sensor);
}

}  // namespace sonarbench::python
