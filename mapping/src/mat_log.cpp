#include "sonarbench/mapping/mat_log.hpp"

#include <matio.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "sonarbench/mapping/error.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {
namespace {

struct MatCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct VarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};

std::size_t ElementCount(const matvar_t* var) {
  std::size_t n = 1;
  for (int i = 0; i < var->rank; ++i) n *= var->dims[i];
  return n;
}

// Element k of a real numeric variable as double; nullopt for other classes.
std::optional<double> NumericAt(const matvar_t* var, std::size_t k) {
  if (var->isComplex || var->data == nullptr || k >= ElementCount(var)) return std::nullopt;
  switch (var->class_type) {
    case MAT_C_DOUBLE:
      return static_cast<const double*>(var->data)[k];
    case MAT_C_SINGLE:
      return static_cast<const float*>(var->data)[k];
    case MAT_C_UINT8:
      return static_cast<const std::uint8_t*>(var->data)[k];
    case MAT_C_INT8:
      return static_cast<const std::int8_t*>(var->data)[k];
    case MAT_C_UINT16:
      return static_cast<const std::uint16_t*>(var->data)[k];
    case MAT_C_INT16:
      return static_cast<const std::int16_t*>(var->data)[k];
    case MAT_C_UINT32:
      return static_cast<const std::uint32_t*>(var->data)[k];
    case MAT_C_INT32:
      return static_cast<const std::int32_t*>(var->data)[k];
    default:
      return std::nullopt;
  }
}

}  // namespace

MatLog ReadMatLog(const std::string& path) {
  auto fail = [&](const std::string& what) { return InputError(path + ": " + what); };
  std::unique_ptr<mat_t, MatCloser> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  if (!mat) throw fail("cannot open as a MATLAB .mat file (expected a v5 or v7.3 .mat log)");
  std::unique_ptr<matvar_t, VarFreer> data(Mat_VarRead(mat.get(), "parsedData"));
  if (!data) throw fail("no readable variable 'parsedData' (expected the struct array of pings)");
  if (data->class_type != MAT_C_STRUCT) throw fail("'parsedData' is not a struct array");
  const std::size_t count = ElementCount(data.get());
  if (count == 0) throw fail("'parsedData' holds no beams");
  // A corrupt file can leave the struct's table of fields unread or the wrong size, and
  // libmatio's field lookup reads that table unchecked: check it before asking for a field.
  const unsigned fields = Mat_VarGetNumberOfFields(data.get());
  char* const* names = Mat_VarGetStructFieldnames(data.get());
  if (data->data == nullptr || fields == 0 || names == nullptr ||
      data->nbytes != count * fields * sizeof(matvar_t*) ||
      std::any_of(names, names + fields, [](const char* name) { return name == nullptr; })) {
    throw fail("'parsedData' is corrupt: its table of " + std::to_string(count) +
               " beams' fields does not read back whole");
  }

  MatLog log;
  log.beams.reserve(count);
  auto scalar = [&](std::size_t i, const char* field) -> double {
    const matvar_t* var = Mat_VarGetStructFieldByName(data.get(), field, i);
    const std::string where = "beam " + std::to_string(i) + ", field '" + field + "'";
    if (var == nullptr) throw fail(where + ": missing");
    if (ElementCount(var) != 1) throw fail(where + ": expected one number");
    const auto value = NumericAt(var, 0);
    if (!value || !std::isfinite(*value)) throw fail(where + ": expected a finite number");
    return *value;
  };
  std::map<std::size_t, std::size_t> bin_counts;
  for (std::size_t i = 0; i < count; ++i) {
    Beam beam;
    beam.time_s = scalar(i, "time");
    beam.head_angle_rad = scalar(i, "angle") * kDegToRad;
    beam.bin_size_m = scalar(i, "step_dist");
    if (beam.bin_size_m <= 0.0) {
      throw fail("beam " + std::to_string(i) + ", field 'step_dist': expected a range > 0 m");
    }
    const matvar_t* bins = Mat_VarGetStructFieldByName(data.get(), "intensities", i);
    const std::string where = "beam " + std::to_string(i) + ", field 'intensities'";
    if (bins == nullptr) throw fail(where + ": missing");
    const std::size_t n = ElementCount(bins);
    if (n == 0) throw fail(where + ": empty");
    beam.intensities.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const auto value = NumericAt(bins, k);
      if (!value || *value < 0.0 || *value > 255.0 || *value != std::floor(*value)) {
        throw fail(where + ", bin " + std::to_string(k) + ": expected an integer in 0..255");
      }
      beam.intensities[k] = static_cast<std::uint8_t>(*value);
    }
    ++bin_counts[n];
    log.beams.push_back(std::move(beam));
  }
  const std::size_t usual =
      std::max_element(bin_counts.begin(), bin_counts.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  for (const Beam& beam : log.beams) log.truncated_beams += beam.intensities.size() != usual;
  return log;
}

}  // namespace sonarbench::mapping
