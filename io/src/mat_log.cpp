#include "sonarbench/io/mat_log.hpp"

#include <matio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "mat_v5.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::io {
namespace {

constexpr const char* kNoParsedData =
    "no readable variable 'parsedData' (expected the struct array of pings)";

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

// A libmatio variable's values as a MAT v5 file holds them (libmatio stores each class's own type).
mat_v5::ArrayView ViewOf(const matvar_t* var) {
  constexpr std::uint32_t kTypeOfClass[16] = {0, 0, 0, 0, 0, 0, 9, 7, 1, 2, 3, 4, 5, 6, 12, 13};
  const auto array_class = static_cast<std::uint32_t>(var->class_type);
  int long_dims = 0;
  for (int i = 0; i < var->rank; ++i) long_dims += var->dims[i] > 1;
  return {array_class,
          var->isComplex != 0,
          ElementCount(var),
          array_class < 16 ? kTypeOfClass[array_class] : 0,
          static_cast<const char*>(var->data),
          var->nbytes,
          long_dims};
}

// Throws unless the struct array's table of fields reads back whole. A corrupt file can leave it
// unread or the wrong size, and libmatio's field lookup reads that table unchecked: checked
// before asking for a field (the MAT v5 check finds such files first; a v7.3 file it does not
// read).
void CheckFieldTable(const std::string& path, matvar_t* data, std::size_t count) {
  const unsigned fields = Mat_VarGetNumberOfFields(data);
  char* const* names = Mat_VarGetStructFieldnames(data);
  if (data->data == nullptr || fields == 0 || names == nullptr ||
      data->nbytes != count * fields * sizeof(matvar_t*) ||
      std::any_of(names, names + fields, [](const char* name) { return name == nullptr; })) {
    throw InputError(path + ": 'parsedData' is corrupt: its table of " + std::to_string(count) +
                     " beams' fields does not read back whole");
  }
}

// Beam i's intensities, each an integer in 0..255.
std::vector<std::uint8_t> ReadIntensities(const std::string& path,
                                          const std::optional<mat_v5::ArrayView>& bins,
                                          std::size_t i) {
  auto where = [&] { return path + ": beam " + std::to_string(i) + ", field 'intensities'"; };
  if (!bins) throw InputError(where() + ": missing");
  const std::size_t n = bins->count;
  if (n == 0) throw InputError(where() + ": empty");
  if (bins->long_dims > 1) {
    throw InputError(where() + ": a matrix of " + std::to_string(n) +
                     " values; expected one row or column of range bins");
  }
  if (n > kMaxBinsPerBeam) {
    throw InputError(where() + ": " + std::to_string(n) + " range bins; expected at most " +
                     std::to_string(kMaxBinsPerBeam));
  }
  if (const std::string_view bytes = bins->StoredBytes(); bytes.size() == n) {
    return {bytes.begin(), bytes.end()};  // stored as uint8: each value already in 0..255
  }
  std::vector<std::uint8_t> intensities(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto value = bins->NumericAt(k);
    if (!value || *value < 0.0 || *value > 255.0 || *value != std::floor(*value)) {
      throw InputError(where() + ", bin " + std::to_string(k) + ": expected an integer in 0..255");
    }
    intensities[k] = static_cast<std::uint8_t>(*value);
  }
  return intensities;
}

// Only a little-endian v5 or v7.3 header reaches libmatio: a v4 file cannot hold the struct array
// of pings, and libmatio sizes a v4 variable's name by whatever its first bytes say.
void CheckMatHeader(const std::string& bytes,
                    const std::function<InputError(const std::string&)>& fail) {
  if (bytes.size() >= 128 && bytes.compare(126, 2, "MI") == 0) {
    throw fail("a big-endian MAT file (expected a little-endian v5 or v7.3 .mat log)");
  }
  const bool v5_or_v73 = bytes.size() >= 128 && bytes.compare(126, 2, "IM") == 0 &&
                         bytes[124] == '\0' && (bytes[125] == '\x01' || bytes[125] == '\x02');
  if (!v5_or_v73) {
    throw fail(
        "not a MAT v5 or v7.3 file (no MAT header in its first 128 bytes; expected the "
        ".mat log of pings)");
  }
}

// The log's `count` beams, each element's fields given by `field(i, name)` (nullopt: missing).
using FieldOf = std::function<std::optional<mat_v5::ArrayView>(std::size_t, const char*)>;
MatLog ReadBeams(const std::string& path, std::size_t count, const FieldOf& field_of) {
  auto fail = [&](const std::string& what) { return InputError(path + ": " + what); };
  MatLog log;
  log.beams.reserve(count);
  auto scalar = [&](std::size_t i, const char* field) -> double {
    const auto var = field_of(i, field);
    auto where = [&] { return "beam " + std::to_string(i) + ", field '" + field + "'"; };
    if (!var) throw fail(where() + ": missing");
    if (var->count != 1) throw fail(where() + ": expected one number");
    const auto value = var->NumericAt(0);
    if (!value || !std::isfinite(*value)) throw fail(where() + ": expected a finite number");
    return *value;
  };
  std::map<std::size_t, std::size_t> bin_counts;
  for (std::size_t i = 0; i < count; ++i) {
    Beam beam;
    beam.time_s = scalar(i, "time");
    beam.head_angle_rad = scalar(i, "angle") * mapping::kDegToRad;
    beam.bin_size_m = scalar(i, "step_dist");
    if (beam.bin_size_m <= 0.0) {
      throw fail("beam " + std::to_string(i) + ", field 'step_dist': expected a range > 0 m");
    }
    beam.intensities = ReadIntensities(path, field_of(i, "intensities"), i);
    ++bin_counts[beam.intensities.size()];
    log.beams.push_back(std::move(beam));
  }
  const std::size_t usual =
      std::max_element(bin_counts.begin(), bin_counts.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  for (const Beam& beam : log.beams) log.truncated_beams += beam.intensities.size() != usual;
  return log;
}

// A MAT v5 file's log, read in place once its layout is checked.
MatLog ReadV5Log(const std::string& path, const std::string& bytes, std::uint64_t max_bytes) {
  auto fail = [&](const std::string& what) { return InputError(path + ": " + what); };
  const mat_v5::Fail corrupt = [&](const std::string& what) {
    return fail("a corrupt MAT file (" + what + ")");
  };
  std::optional<std::string> variable =
      mat_v5::CheckFile(bytes, "parsedData", corrupt, max_bytes - bytes.size());
  if (!variable) throw fail(kNoParsedData);
  const std::optional<mat_v5::StructArray> read =
      mat_v5::ReadStructArray(std::move(*variable), corrupt);
  if (!read) throw fail("'parsedData' is not a struct array");
  const mat_v5::StructArray& data = *read;
  if (data.count == 0) throw fail("'parsedData' holds no beams");
  if (data.fields.empty()) {
    throw fail("'parsedData' has no fields (expected time, angle, step_dist and intensities)");
  }
  return ReadBeams(path, data.count, [&](std::size_t i, const char* name) {
    const mat_v5::ArrayView* view = data.Field(i, name);
    return view ? std::optional(*view) : std::nullopt;
  });
}

}  // namespace

MatLog ReadMatLog(const std::string& path, std::uint64_t max_bytes) {
  auto fail = [&](const std::string& what) { return InputError(path + ": " + what); };
  {
    const std::string bytes = ReadFileBytes(path, max_bytes);
    CheckMatHeader(bytes, fail);
    if (mat_v5::IsV5(bytes)) return ReadV5Log(path, bytes, max_bytes);
  }
  // v7.3 (HDF5): libmatio.
  std::unique_ptr<mat_t, MatCloser> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  if (!mat) throw fail("cannot open as a MATLAB .mat file (expected a v5 or v7.3 .mat log)");
  std::unique_ptr<matvar_t, VarFreer> data(Mat_VarRead(mat.get(), "parsedData"));
  if (!data) throw fail(kNoParsedData);
  if (data->class_type != MAT_C_STRUCT) throw fail("'parsedData' is not a struct array");
  const std::size_t count = ElementCount(data.get());
  if (count == 0) throw fail("'parsedData' holds no beams");
  CheckFieldTable(path, data.get(), count);
  return ReadBeams(path, count, [&](std::size_t i, const char* name) {
    const matvar_t* var = Mat_VarGetStructFieldByName(data.get(), name, i);
    return var ? std::optional(ViewOf(var)) : std::nullopt;
  });
}

}  // namespace sonarbench::io
