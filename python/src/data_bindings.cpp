#include "bindings.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/io/rosbag.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::python {
namespace {

// A recorded run read into sweeps: a dataset, a .mat log or a ROS 2 bag.
struct Log {
  std::string source;  // "dataset", "mat" or "mcap"
  std::string path;
  mapping::SensorGeometry sensor;
  py::list sweeps;  // of Sweep
  std::size_t beam_count = 0;
  std::size_t truncated_beams = 0;
  std::string manifest;  // a dataset's manifest.json, as JSON text; "" for none
};

// `sweeps` as a list of Python objects, moved.
py::list ListOf(std::vector<Sweep>&& sweeps) {
  py::list out;
  for (Sweep& s : sweeps) out.append(py::cast(std::move(s)));
  return out;
}

// `beams` cut into sweeps of the sensor's beams per sweep (the last may be partial), with their
// labels when there are any.
std::vector<Sweep> Sweeps(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& s,
                          std::span<const io::BeamLabels> labels) {
  const auto per_sweep = static_cast<std::size_t>(s.BeamsPerSweep());
  std::vector<Sweep> out;
  for (std::size_t first = 0, k = 0; first < beams.size(); first += per_sweep, ++k) {
    const std::size_t n = std::min(per_sweep, beams.size() - first);
    out.push_back(
        SweepOf(k, beams.subspan(first, n), labels.empty() ? labels : labels.subspan(first, n)));
  }
  return out;
}

mapping::SensorGeometry ModelGeometry(const py::object& sensor_model) {
  const std::string path =
      sensor_model.is_none() ? sim::ShippedSensorModelPath() : PathArg(sensor_model);
  return sim::LoadSensorModel(path).geometry;
}

Log ReadDatasetDir(const py::object& dir) {
  Log log;
  log.source = "dataset";
  log.path = PathArg(dir);
  std::vector<Sweep> sweeps;
  {
    const py::gil_scoped_release release;
    const io::Dataset dataset = io::ReadDataset(log.path);
    const std::vector<io::BeamLabels> labels = io::ReadDatasetLabels(log.path, dataset);
    log.sensor = dataset.sensor;
    log.beam_count = dataset.beams.size();
    sweeps = Sweeps(dataset.beams, dataset.sensor, labels);
    log.manifest = dataset.manifest.dump();
  }
  log.sweeps = ListOf(std::move(sweeps));
  return log;
}

Log ReadMat(const py::object& path, const py::object& sensor_model) {
  Log log;
  log.source = "mat";
  log.path = PathArg(path);
  log.sensor = ModelGeometry(sensor_model);
  std::vector<Sweep> sweeps;
  {
    const py::gil_scoped_release release;
    const std::string in_folder = sim::MatLogInDirectory(log.path);
    const io::MatLog mat = io::ReadMatLog(in_folder.empty() ? log.path : in_folder);
    log.beam_count = mat.beams.size();
    log.truncated_beams = mat.truncated_beams;
    sweeps = Sweeps(mat.beams, log.sensor, {});
  }
  log.sweeps = ListOf(std::move(sweeps));
  return log;
}

Log ReadBag(const py::object& path, const py::object& sensor_model, const std::string& topic,
            bool static_sonar) {
  Log log;
  log.source = "mcap";
  log.path = PathArg(path);
  log.sensor = ModelGeometry(sensor_model);
  io::RosbagReadOptions options;
  options.sensor = log.sensor;
  options.topic = topic;
  options.static_sonar = static_sonar;
  options.max_bytes = sonarbench::kMaxLogBytes;
  std::vector<Sweep> sweeps;
  {
    const py::gil_scoped_release release;
    const io::RosbagBeams bag = io::ReadRosbag(log.path, options);
    log.beam_count = bag.beams.size();
    log.truncated_beams = bag.truncated_beams;
    sweeps = Sweeps(bag.beams, log.sensor, {});
  }
  log.sweeps = ListOf(std::move(sweeps));
  return log;
}

}  // namespace

void BindData(py::module_& m) {
  py::class_<mapping::SensorGeometry>(m, "Sensor", "What the mapper knows of the sonar.")
      .def_readonly("bin_count", &mapping::SensorGeometry::num_bins)
      .def_readonly("bin_size_m", &mapping::SensorGeometry::bin_size_m)
      .def_property_readonly("beams_per_sweep", &mapping::SensorGeometry::BeamsPerSweep)
      .def_property_readonly("max_range_m", &mapping::SensorGeometry::MaxRangeM);
  m.def("sensor_model", &ModelGeometry, py::arg("path") = py::none(),
        "The geometry of a sensor model YAML file (default: the shipped SHAD Micron's).");

  py::class_<Log>(m, "Log", "A recorded run read whole: its sweeps and its sensor.")
      .def_readonly("source", &Log::source, "'dataset', 'mat' or 'mcap'.")
      .def_readonly("path", &Log::path)
      .def_readonly("sensor", &Log::sensor, "The beams' geometry (a dataset's own).")
      .def_readonly("sweeps", &Log::sweeps, "Sweeps of sensor.beams_per_sweep beams, in order.")
      .def_readonly("beam_count", &Log::beam_count)
      .def_readonly("truncated_beams", &Log::truncated_beams,
                    "Beams with fewer bins than the log's usual count.")
      .def_property_readonly(
          "manifest",
          [](const Log& log) -> py::object {
            if (log.manifest.empty()) return py::none();
            return py::module_::import("json").attr("loads")(log.manifest);
          },
          "A dataset's manifest.json as a dict; None for a .mat log or a bag.")
      .def("__len__", [](const Log& log) { return log.sweeps.size(); })
      .def("__repr__", [](const Log& log) {
        return "<sonarbench.Log " + log.source + " " + log.path + ": " +
               std::to_string(log.sweeps.size()) + " sweeps>";
      });

  m.def("read_dataset", &ReadDatasetDir, py::arg("path"),
        "Reads a sonarbench dataset directory (docs/dataset-format.md), checking its manifest "
        "and every file's sha256; a simulated one's sweeps carry their labels.");
  m.def("read_mat", &ReadMat, py::arg("path"), py::kw_only(), py::arg("sensor_model") = py::none(),
        "Reads a real MSIS log in .mat form (or the folder holding one): the vehicle static, "
        "every beam at the identity pose; sweeps cut by the sensor model's beams per sweep.");
  m.def("read_mcap", &ReadBag, py::arg("path"), py::kw_only(), py::arg("sensor_model") = py::none(),
        py::arg("topic") = "", py::arg("static") = false,
        "Reads the sonar beams of a ROS 2 MCAP bag (ProjectedSonarImage, posed by /tf), as "
        "`sonarbench import` does.");
}

}  // namespace sonarbench::python
