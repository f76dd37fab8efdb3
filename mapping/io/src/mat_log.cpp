#include "sonarbench/io/mat_log.hpp"

#include <matio.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "sonarbench/mapping/atomic_file.hpp"
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

// A MAT v5 file's elements, walked by their tags without reading any array's values: libmatio
// 1.5 sizes its arrays by the dimensions a file states, so a corrupt one (a byte changed inside
// the compressed log) had it allocate 13 GB and take 35 s before it refused the file. A file
// whose stated sizes do not fit in the bytes it holds is refused here instead.
class MatV5Check {
 public:
  explicit MatV5Check(std::function<InputError(const std::string&)> fail)
      : fail_(std::move(fail)) {}

  // Checks the file's bytes; files that are not MAT v5 (v4, v7.3's HDF5) are left to libmatio.
  void File(const std::string& bytes) {
    if (bytes.size() < 128 || bytes.compare(126, 2, "IM") != 0 ||
        static_cast<unsigned char>(bytes[125]) != 0x01) {
      return;
    }
    for (std::size_t at = 128; at < bytes.size();) {
      const Tag tag = ReadTag(bytes, at, bytes.size());
      if (tag.type == kCompressed) {
        Element(Inflate(bytes.substr(tag.data, tag.bytes)), 0);
        at = tag.data + tag.bytes;
      } else {
        Element(bytes.substr(at, tag.end - at), 0);
        at = tag.end;
      }
    }
  }

 private:
  static constexpr std::uint32_t kInt8 = 1, kInt32 = 5, kUInt32 = 6, kMatrix = 14, kCompressed = 15;
  static constexpr int kMostDepth = 16;

  struct Tag {
    std::uint32_t type = 0;
    std::size_t bytes = 0;  // the data's
    std::size_t data = 0;   // where the data starts
    std::size_t end = 0;    // where the next element starts (padded to 8 bytes)
  };

  static std::uint32_t U32(const std::string& bytes, std::size_t at) {
    std::uint32_t value = 0;
    std::memcpy(&value, bytes.data() + at, sizeof value);  // little-endian, as "IM" says
    return value;
  }

  // The tag at `at`, whose element must end by `limit`.
  Tag ReadTag(const std::string& bytes, std::size_t at, std::size_t limit) const {
    if (limit < at + 8 || limit > bytes.size()) throw fail_("an element's tag is cut off");
    Tag tag;
    tag.type = U32(bytes, at);
    if ((tag.type >> 16) != 0) {  // a small element: its bytes in the tag's upper half
      tag.bytes = tag.type >> 16;
      tag.type &= 0xffff;
      tag.data = at + 4;
      tag.end = at + 8;
      if (tag.bytes > 4) {
        throw fail_("a small element states " + std::to_string(tag.bytes) +
                    " bytes, more than the 4 it can hold");
      }
      return tag;
    }
    tag.bytes = U32(bytes, at + 4);
    tag.data = at + 8;
    // An array may state more bytes than follow: libmatio writes a compressed char array's size
    // with padding it leaves out. What an array holds is checked element by element.
    if (tag.type == kMatrix) {
      tag.bytes = std::min(tag.bytes, limit - tag.data);
    } else if (tag.bytes > limit - tag.data) {
      throw fail_("an element states " + std::to_string(tag.bytes) + " bytes where " +
                  std::to_string(limit - tag.data) + " are left");
    }
    // Padded to 8 bytes, but for a compressed one; libmatio leaves the last padding out of what
    // it compresses.
    const std::size_t padded = tag.type == kCompressed ? tag.bytes : (tag.bytes + 7) / 8 * 8;
    tag.end = std::min(tag.data + padded, limit);
    return tag;
  }

  std::string Inflate(const std::string& compressed) const {
    z_stream stream{};
    if (inflateInit(&stream) != Z_OK) throw fail_("zlib cannot start");
    std::string out;
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
    stream.avail_in = static_cast<uInt>(compressed.size());
    int status = Z_OK;
    while (status == Z_OK) {
      out.resize(out.size() + (1 << 20));
      stream.next_out = reinterpret_cast<Bytef*>(out.data() + stream.total_out);
      stream.avail_out = 1 << 20;
      status = inflate(&stream, Z_NO_FLUSH);
    }
    out.resize(stream.total_out);
    inflateEnd(&stream);
    if (status != Z_STREAM_END) throw fail_("a compressed element does not inflate whole");
    return out;
  }

  // One element and, if it is an array (miMATRIX), what it holds.
  void Element(const std::string& bytes, int depth) const {
    if (bytes.empty()) return;
    const Tag tag = ReadTag(bytes, 0, bytes.size());
    if (tag.type == kMatrix) Matrix(bytes, tag, depth);
  }

  // An array: its flags, dimensions and name, then a char or numeric array's values, as many as
  // its dimensions say, or a struct array's fields, one array per element and field.
  void Matrix(const std::string& bytes, const Tag& matrix, int depth) const {
    if (matrix.bytes == 0) return;  // an empty array
    if (depth > kMostDepth) throw fail_("arrays nested deeper than " + std::to_string(kMostDepth));
    const std::size_t end = matrix.data + matrix.bytes;
    const Tag flags = ReadTag(bytes, matrix.data, end);
    if (flags.type != kUInt32 || flags.bytes != 8) throw fail_("an array without its flags");
    const std::uint32_t array_class = U32(bytes, flags.data) & 0xff;
    const bool complex = (U32(bytes, flags.data) & 0x0800) != 0;
    const Tag dims = ReadTag(bytes, flags.end, end);
    if (dims.type != kInt32 || dims.bytes % 4 != 0 || dims.bytes < 8) {
      throw fail_("an array without its dimensions");
    }
    double elements = 1.0;
    for (std::size_t d = 0; d < dims.bytes; d += 4) {
      elements *= static_cast<double>(static_cast<std::int32_t>(U32(bytes, dims.data + d)));
    }
    if (elements < 0.0) throw fail_("an array of negative dimensions");
    // Cell, struct, char and numeric arrays; libmatio sizes a sparse or object array by counts
    // this check does not follow, and a log holds none.
    if (array_class == 0 || array_class == 3 || array_class == 5 || array_class > 15) {
      throw fail_("an array of class " + std::to_string(array_class) +
                  " (expected cell, struct, char or numeric arrays)");
    }
    const Tag name = ReadTag(bytes, dims.end, end);
    if (name.type != kInt8) throw fail_("an array without its name");
    std::size_t at = name.end;
    if (array_class == 4 || (array_class >= 6 && array_class <= 15)) {  // char; double ... uint64
      for (int part = 0; part < (complex && array_class != 4 ? 2 : 1); ++part) {
        const Tag values = ReadTag(bytes, at, end);
        const std::size_t size = TypeBytes(values.type);
        if (size == 0 || static_cast<double>(values.bytes / size) != elements ||
            values.bytes % size != 0) {
          std::ostringstream stated;  // a product of dimensions may pass any integer type
          stated << std::setprecision(15) << elements;
          throw fail_("an array of " + stated.str() + " elements holds " +
                      std::to_string(values.bytes) + " bytes of values");
        }
        at = values.end;
      }
    } else if (array_class == 1) {  // cell: an array per element
      for (double k = 0; k < elements; ++k) {
        const Tag cell = ReadTag(bytes, at, end);
        if (cell.type != kMatrix) throw fail_("a cell array's element is not an array");
        Matrix(bytes, cell, depth + 1);
        at = cell.end;
      }
    } else if (array_class == 2) {  // struct
      const Tag length = ReadTag(bytes, at, end);
      const Tag names = ReadTag(bytes, length.end, end);
      const std::uint32_t name_length = length.bytes == 4 ? U32(bytes, length.data) : 0;
      if (length.type != kInt32 || name_length == 0 || names.bytes % name_length != 0) {
        throw fail_("a struct array without its field names");
      }
      const double fields = static_cast<double>(names.bytes / name_length);
      at = names.end;
      for (double k = 0; k < elements * fields; ++k) {
        const Tag field = ReadTag(bytes, at, end);
        if (field.type != kMatrix) throw fail_("a struct array's field is not an array");
        Matrix(bytes, field, depth + 1);
        at = field.end;
      }
    }
  }

  static std::size_t TypeBytes(std::uint32_t type) {
    switch (type) {
      case 1:
      case 2:
      case 16:
        return 1;  // int8, uint8, utf8
      case 3:
      case 4:
      case 17:
        return 2;  // int16, uint16, utf16
      case 5:
      case 6:
      case 7:
      case 18:
        return 4;  // int32, uint32, single, utf32
      case 9:
      case 12:
      case 13:
        return 8;  // double, int64, uint64
      default:
        return 0;
    }
  }

  std::function<InputError(const std::string&)> fail_;
};

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
std::vector<std::uint8_t> ReadIntensities(const std::string& path, matvar_t* data, std::size_t i) {
  const matvar_t* bins = Mat_VarGetStructFieldByName(data, "intensities", i);
  const std::string where = path + ": beam " + std::to_string(i) + ", field 'intensities'";
  if (bins == nullptr) throw InputError(where + ": missing");
  const std::size_t n = ElementCount(bins);
  if (n == 0) throw InputError(where + ": empty");
  std::vector<std::uint8_t> intensities(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto value = NumericAt(bins, k);
    if (!value || *value < 0.0 || *value > 255.0 || *value != std::floor(*value)) {
      throw InputError(where + ", bin " + std::to_string(k) + ": expected an integer in 0..255");
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

}  // namespace

MatLog ReadMatLog(const std::string& path) {
  auto fail = [&](const std::string& what) { return InputError(path + ": " + what); };
  if (std::filesystem::is_regular_file(path)) {
    const std::string bytes = ReadFileBytes(path);
    CheckMatHeader(bytes, fail);
    MatV5Check([&](const std::string& what) {
      return fail("a corrupt MAT file (" + what + ")");
    }).File(bytes);
  }
  std::unique_ptr<mat_t, MatCloser> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  if (!mat) throw fail("cannot open as a MATLAB .mat file (expected a v5 or v7.3 .mat log)");
  std::unique_ptr<matvar_t, VarFreer> data(Mat_VarRead(mat.get(), "parsedData"));
  if (!data) throw fail("no readable variable 'parsedData' (expected the struct array of pings)");
  if (data->class_type != MAT_C_STRUCT) throw fail("'parsedData' is not a struct array");
  const std::size_t count = ElementCount(data.get());
  if (count == 0) throw fail("'parsedData' holds no beams");
  CheckFieldTable(path, data.get(), count);

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
    beam.intensities = ReadIntensities(path, data.get(), i);
    const std::size_t n = beam.intensities.size();
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
