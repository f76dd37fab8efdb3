#include <algorithm>
#include <cmath>
#include <limits>

#include "bindings.hpp"
#include "sonarbench/base/error.hpp"

namespace sonarbench::python {
namespace {

// A read-only view of `data` (shape `shape`, C order) that keeps `owner` alive.
template <typename T>
py::array View(const std::vector<T>& data, std::vector<py::ssize_t> shape,
               const py::object& owner) {
  py::array view(py::dtype::of<T>(), std::move(shape), {}, data.data(), owner);
  view.attr("flags").attr("writeable") = false;
  return view;
}

py::ssize_t Size(std::size_t n) { return static_cast<py::ssize_t>(n); }

// The array argument `name` as a C-contiguous array of T with `dims` dimensions.
template <typename T>
py::array_t<T, py::array::c_style | py::array::forcecast> Arg(const py::object& value,
                                                              const char* name, int dims) {
  auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != dims) {
    throw InputError(std::string(name) + ": expected an array of " + std::to_string(dims) +
                     " dimension" + (dims == 1 ? "" : "s"));
  }
  return a;
}

// A Sweep from arrays: intensities (beams × bins, uint8), head angles [rad], poses (beams × 4 ×
// 4, T_world_sonar), the bin size [m] and times [s] (default: 0, 1, 2, ...).
Sweep SweepFromArrays(const py::object& intensities, const py::object& head_angles_rad,
                      const py::object& poses, double bin_size_m, const py::object& times_s) {
  const py::array raw = py::array::ensure(intensities);
  if (!raw || raw.dtype().kind() != 'u' || raw.itemsize() != 1) {
    throw InputError("intensities: expected a uint8 array (beams × bins)");
  }
  const auto i = Arg<std::uint8_t>(intensities, "intensities", 2);
  const auto h = Arg<double>(head_angles_rad, "head_angles_rad", 1);
  const auto p = Arg<double>(poses, "poses", 3);
  const auto beams = static_cast<std::size_t>(i.shape(0));
  if (static_cast<std::size_t>(h.shape(0)) != beams) {
    throw InputError("head_angles_rad: expected one angle per beam (" + std::to_string(beams) +
                     "), got " + std::to_string(h.shape(0)));
  }
  if (static_cast<std::size_t>(p.shape(0)) != beams || p.shape(1) != 4 || p.shape(2) != 4) {
    throw InputError("poses: expected shape (" + std::to_string(beams) + ", 4, 4)");
  }
  if (!(std::isfinite(bin_size_m) && bin_size_m > 0.0)) {
    throw InputError("bin_size_m: expected metres > 0, got " + std::to_string(bin_size_m));
  }
  Sweep s;
  s.bins = static_cast<std::size_t>(i.shape(1));
  s.intensities.assign(i.data(), i.data() + i.size());
  s.bin_counts.assign(beams, static_cast<std::uint32_t>(s.bins));
  s.head_angles_rad.assign(h.data(), h.data() + h.size());
  s.poses.assign(p.data(), p.data() + p.size());
  s.bin_sizes_m.assign(beams, bin_size_m);
  if (times_s.is_none()) {
    for (std::size_t b = 0; b < beams; ++b) s.times_s.push_back(static_cast<double>(b));
  } else {
    const auto t = Arg<double>(times_s, "times_s", 1);
    if (static_cast<std::size_t>(t.shape(0)) != beams) {
      throw InputError("times_s: expected one time per beam (" + std::to_string(beams) + ")");
    }
    s.times_s.assign(t.data(), t.data() + t.size());
  }
  for (std::size_t b = 0; b < beams; ++b) {
    const double* m = s.poses.data() + 16 * b;
    const bool finite = std::all_of(m, m + 16, [](double v) { return std::isfinite(v); });
    if (!finite || m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0) {
      throw InputError("poses[" + std::to_string(b) +
                       "]: expected a finite rigid transform, last row (0, 0, 0, 1)");
    }
    if (!std::isfinite(s.head_angles_rad[b]) || !std::isfinite(s.times_s[b])) {
      throw InputError("beam " + std::to_string(b) + ": head angle and time must be finite");
    }
  }
  return s;
}

using Shape = std::vector<py::ssize_t>;

// A read-only array property `name` of Sweep viewing `field` in the shape `shape` gives it;
// None for a sweep without labels when `label` is set.
template <typename T, typename ShapeOf>
void DefView(py::class_<Sweep>& cls, const char* name, const std::vector<T> Sweep::*field,
             ShapeOf shape, bool label, const char* doc) {
  cls.def_property_readonly(
      name,
      [field, shape, label](const py::object& self) -> py::object {
        const auto& s = self.cast<const Sweep&>();
        if (label && !s.labelled) return py::none();
        return View(s.*field, shape(s), self);
      },
      doc);
}

void DefViews(py::class_<Sweep>& cls) {
  const auto beams = [](const Sweep& s) { return Shape{Size(s.beams())}; };
  const auto bins = [](const Sweep& s) { return Shape{Size(s.beams()), Size(s.bins)}; };
  DefView(cls, "intensities", &Sweep::intensities, bins, false,
          "Echo intensity, beams × bins, uint8; bin k spans [k, k+1)·bin_size_m.");
  DefView(cls, "bin_counts", &Sweep::bin_counts, beams, false,
          "Bins each beam has (a shorter beam is padded with zeros in intensities).");
  DefView(cls, "times_s", &Sweep::times_s, beams, false,
          "Time of each ping [s] since the start of the run or log.");
  DefView(cls, "head_angles_rad", &Sweep::head_angles_rad, beams, false,
          "Head angle of each beam [rad] about the sonar frame's z axis.");
  DefView(cls, "bin_sizes_m", &Sweep::bin_sizes_m, beams, false,
          "Range of one bin of each beam [m].");
  DefView(
      cls, "poses", &Sweep::poses,
      [](const Sweep& s) {
        return Shape{Size(s.beams()), 4, 4};
      },
      false,
      "T_world_sonar of each beam (beams × 4 × 4): the sonar frame at head angle 0, in the "
      "world frame [m], as the mapper is given it (a simulated run's reported pose).");
  DefView(
      cls, "path_shares", &Sweep::path_shares,
      [](const Sweep& s) {
        return Shape{Size(s.beams()), Size(s.bins), Size(io::kEchoPaths)};
      },
      true,
      "Each path's share of each bin's power in 255ths (beams × bins × 7, uint8, summing to "
      "255; paths in ECHO_PATHS order), or None without labels.");
  DefView(cls, "mesh", &Sweep::mesh, bins, true,
          "The scene mesh with the most direct energy in each bin (its index in the scene's "
          "meshes; NO_MESH for none), beams × bins, uint16, or None.");
  DefView(
      cls, "points_sonar_m", &Sweep::points_sonar_m,
      [](const Sweep& s) {
        return Shape{Size(s.beams()), Size(s.bins), 3};
      },
      true,
      "Where that mesh's strongest direct return in each bin lies, sonar frame [m] "
      "(beams × bins × 3, float32; NaN for none), or None.");
}

}  // namespace

Sweep SweepOf(std::size_t index, std::span<const mapping::Beam> beams,
              std::span<const io::BeamLabels> labels) {
  Sweep s;
  s.index = index;
  for (const mapping::Beam& beam : beams) s.bins = std::max(s.bins, beam.intensities.size());
  const std::size_t n = beams.size();
  s.intensities.assign(n * s.bins, 0);
  s.poses.resize(16 * n);
  s.labelled = !labels.empty();
  if (s.labelled) {
    s.path_shares.assign(n * s.bins * io::kEchoPaths, 0);
    s.mesh.assign(n * s.bins, io::kNoLabelMesh);
    s.points_sonar_m.assign(3 * n * s.bins, std::numeric_limits<float>::quiet_NaN());
  }
  for (std::size_t b = 0; b < n; ++b) {
    const mapping::Beam& beam = beams[b];
    std::copy(beam.intensities.begin(), beam.intensities.end(),
              s.intensities.begin() + static_cast<std::ptrdiff_t>(b * s.bins));
    s.bin_counts.push_back(static_cast<std::uint32_t>(beam.intensities.size()));
    s.times_s.push_back(beam.time_s);
    s.head_angles_rad.push_back(beam.head_angle_rad);
    s.bin_sizes_m.push_back(beam.bin_size_m);
    const Eigen::Matrix4d m = beam.T_world_sonar.matrix();
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) s.poses[16 * b + 4 * static_cast<std::size_t>(r) + c] = m(r, c);
    }
    if (!s.labelled) continue;
    const io::BeamLabels& l = labels[b];
    for (std::size_t k = 0; k < l.mesh.size() && k < s.bins; ++k) {
      const std::size_t at = b * s.bins + k;
      std::copy(l.shares[k].begin(), l.shares[k].end(),
                s.path_shares.begin() + static_cast<std::ptrdiff_t>(at * io::kEchoPaths));
      s.mesh[at] = l.mesh[k];
      for (int d = 0; d < 3; ++d) s.points_sonar_m[3 * at + d] = l.point_sonar_m[k][d];
    }
  }
  return s;
}

std::vector<mapping::Beam> Sweep::ToBeams() const {
  std::vector<mapping::Beam> out(beams());
  for (std::size_t b = 0; b < out.size(); ++b) {
    mapping::Beam& beam = out[b];
    beam.time_s = times_s[b];
    beam.head_angle_rad = head_angles_rad[b];
    beam.bin_size_m = bin_sizes_m[b];
    const auto* first = intensities.data() + b * bins;
    beam.intensities.assign(first, first + bin_counts[b]);
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = poses[16 * b + 4 * static_cast<std::size_t>(r) + c];
    }
    beam.T_world_sonar.matrix() = m;
  }
  return out;
}

void BindSweep(py::module_& m) {
  m.attr("ECHO_PATHS") = py::make_tuple("direct", "multipath", "sidelobe", "second_trip",
                                        "reverberation", "vehicle", "noise");
  m.attr("NO_MESH") = io::kNoLabelMesh;
  py::class_<Sweep> cls(m, "Sweep",
                        "One sweep of beams (a head revolution or a log's share of one).");
  cls.def(py::init(&SweepFromArrays), py::arg("intensities"), py::arg("head_angles_rad"),
          py::arg("poses"), py::arg("bin_size_m"), py::arg("times_s") = py::none(),
          "A sweep from arrays: intensities (beams × bins, uint8), head angles [rad] about the "
          "sonar's z axis, poses (beams × 4 × 4, T_world_sonar at head angle 0), the bin size "
          "[m] and times [s] (default 0, 1, 2, ...). Copies the arrays.")
      .def_readonly("index", &Sweep::index, "The sweep's number in its run or log.")
      .def_property_readonly("beam_count", &Sweep::beams)
      .def_property_readonly(
          "bin_size_m",
          [](const Sweep& s) { return s.bin_sizes_m.empty() ? 0.0 : s.bin_sizes_m.front(); },
          "Range of one bin [m] (the first beam's; every beam's in bin_sizes_m).")
      .def_property_readonly(
          "labelled", [](const Sweep& s) { return s.labelled; },
          "Whether the per-bin labels are present (simulated with labels).")
      .def("__repr__", [](const Sweep& s) {
        return "<sonarbench.Sweep " + std::to_string(s.index) + ": " + std::to_string(s.beams()) +
               " beams × " + std::to_string(s.bins) + " bins" + (s.labelled ? ", labelled>" : ">");
      });
  DefViews(cls);
}

}  // namespace sonarbench::python
