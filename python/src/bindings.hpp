#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/labels.hpp"
#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::python {

namespace py = pybind11;

/// One sweep's beams as the module hands them to Python: each field one contiguous block that
/// NumPy views without a copy (the arrays keep the Sweep alive). Beams shorter than the longest
/// (a log's truncated last ping) are padded with zeros past their `bin_counts`.
struct Sweep {
  std::size_t index = 0;                  ///< the sweep's number in its run or log
  std::size_t bins = 0;                   ///< bins of the longest beam
  std::vector<std::uint8_t> intensities;  ///< beams × bins
  std::vector<std::uint32_t> bin_counts;  ///< per beam
  std::vector<double> times_s;            ///< per beam [s]
  std::vector<double> head_angles_rad;    ///< per beam [rad]
  std::vector<double> bin_sizes_m;        ///< per beam [m]
  std::vector<double> poses;              ///< beams × 4 × 4, T_world_sonar, row-major
  bool labelled = false;                  ///< the per-bin labels below are filled
  std::vector<std::uint8_t> path_shares;  ///< beams × bins × kEchoPaths [1/255]
  std::vector<std::uint16_t> mesh;        ///< beams × bins, io::kNoLabelMesh for none
  std::vector<float> points_sonar_m;      ///< beams × bins × 3 [m], sonar frame, NaN for none

  [[nodiscard]] std::size_t beams() const { return times_s.size(); }
  /// The beams as the mapper takes them.
  [[nodiscard]] std::vector<mapping::Beam> ToBeams() const;
};

/// A sweep from beams and, when not empty, one BeamLabels per beam.
[[nodiscard]] Sweep SweepOf(std::size_t index, std::span<const mapping::Beam> beams,
                            std::span<const io::BeamLabels> labels = {});

/// A scene loaded for Python: the scene (its budgets those it was loaded with).
struct PyScene {
  std::shared_ptr<const sim::Scene> scene;
};

/// `text` as a Python str path (os.PathLike or str) to a std::string.
[[nodiscard]] std::string PathArg(const py::object& path);

/// Raises KeyboardInterrupt (or whatever a signal handler raised) when a signal is pending.
void CheckSignals();

/// The mapping::Mapper of a Python Mapper; whether `object` is one.
[[nodiscard]] const mapping::Mapper& MapperOf(const py::handle& mapper);
[[nodiscard]] bool IsMapper(const py::handle& object);

void BindSweep(py::module_& m);
void BindScene(py::module_& m);
void BindData(py::module_& m);
void BindMapper(py::module_& m);
void BindScore(py::module_& m);

}  // namespace sonarbench::python
