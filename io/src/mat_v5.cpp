#include "mat_v5.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>
#include <type_traits>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/files.hpp"

namespace sonarbench::io::mat_v5 {
namespace {

// The bytes of one value of a MAT data type (miINT8 ... miUINT64, miUTF8..32); 0 for others.
std::size_t TypeBytes(std::uint32_t type) {
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

// The value at `at`, of data type `type`, as a double.
double StoredAt(const char* at, std::uint32_t type) {
  auto get = [&](auto value) {
    std::memcpy(&value, at, sizeof value);  // little-endian, as "IM" says
    return static_cast<double>(value);
  };
  switch (type) {
    case 1:
      return get(std::int8_t{});
    case 2:
      return get(std::uint8_t{});
    case 3:
      return get(std::int16_t{});
    case 4:
      return get(std::uint16_t{});
    case 5:
      return get(std::int32_t{});
    case 6:
      return get(std::uint32_t{});
    case 7:
      return get(float{});
    case 9:
      return get(double{});
    case 12:
      return get(std::int64_t{});
    default:
      return get(std::uint64_t{});  // 13
  }
}

// `value` as the class's C type holds it; nullopt where that type cannot.
template <typename T>
std::optional<double> As(double value) {
  if constexpr (std::is_floating_point_v<T>) {
    if (std::isfinite(value) && std::abs(value) > std::numeric_limits<T>::max())
      return std::nullopt;
    return static_cast<double>(static_cast<T>(value));
  } else {
    if (!(value >= static_cast<double>(std::numeric_limits<T>::min()) &&
          value <= static_cast<double>(std::numeric_limits<T>::max()))) {
      return std::nullopt;
    }
    return static_cast<double>(static_cast<T>(value));
  }
}

// A MAT v5 file's elements, walked by their tags: first checked, every stated size against the
// bytes that hold it (a reader that sizes arrays by what a file states, as libmatio 1.5 does,
// allocated 13 GB for one byte changed inside the compressed log), then read in place.
class Walker {
 public:
  explicit Walker(Fail fail, std::uint64_t max_inflated = UINT64_MAX)
      : fail_(std::move(fail)), left_(max_inflated) {}

  // Checks the file's elements; returns the first top-level variable called `name`, inflated.
  std::optional<std::string> File(const std::string& bytes, std::string_view name) const {
    std::optional<std::string> kept;
    for (std::size_t at = 128; at < bytes.size();) {
      const Tag tag = ReadTag(bytes, at, bytes.size());
      std::string element;
      if (tag.type == kCompressed) {
        element = Inflate(bytes.substr(tag.data, tag.bytes));
        at = tag.data + tag.bytes;
      } else {
        element = bytes.substr(at, tag.end - at);
        at = tag.end;
      }
      Element(element, 0);
      const bool array = element.size() >= 8 && U32(element, 0) == kMatrix;
      if (!kept && array && Read(element).name == name) kept = std::move(element);
    }
    return kept;
  }

  // A checked array's header and values (the real part's), read in place.
  struct Array {
    std::string_view name;
    ArrayView view;
    std::size_t fields_at = 0;  // a struct array's: where its field name length starts
    std::size_t end = 0;
  };
  Array Read(const std::string& bytes, std::size_t at = 0) const {
    const Tag matrix = ReadTag(bytes, at, bytes.size());
    Array array;
    array.end = matrix.end;
    if (matrix.type != kMatrix) throw fail_("an element that is not an array");
    if (matrix.bytes == 0) return array;  // an empty array
    const std::size_t end = matrix.data + matrix.bytes;
    const Tag flags = ReadTag(bytes, matrix.data, end);
    array.view.array_class = U32(bytes, flags.data) & 0xff;
    array.view.complex = (U32(bytes, flags.data) & 0x0800) != 0;
    const Tag dims = ReadTag(bytes, flags.end, end);
    array.view.count = 1;
    for (std::size_t d = 0; d < dims.bytes; d += 4) {
      const auto dim = static_cast<std::int32_t>(U32(bytes, dims.data + d));
      if (dim < 0) throw fail_("an array of negative dimensions");
      array.view.count *= static_cast<std::size_t>(dim);
      array.view.long_dims += dim > 1;
    }
    const Tag name = ReadTag(bytes, dims.end, end);
    array.name = std::string_view(bytes.data() + name.data, name.bytes);
    array.name = array.name.substr(0, array.name.find('\0'));
    array.fields_at = name.end;
    const std::uint32_t c = array.view.array_class;
    if (c == 4 || (c >= 6 && c <= 15)) {
      const Tag values = ReadTag(bytes, name.end, end);
      array.view.data_type = values.type;
      array.view.data = bytes.data() + values.data;
      array.view.data_bytes = values.bytes;
    }
    return array;
  }

  // A struct array's field names and each element's fields.
  std::optional<StructArray> Struct(std::string variable) const {
    StructArray out;
    out.bytes = std::move(variable);  // views point into it; a moved string keeps its buffer
    const std::string& bytes = out.bytes;
    const Array array = Read(bytes);
    if (array.view.array_class != 2) return std::nullopt;
    const Tag matrix = ReadTag(bytes, 0, bytes.size());
    const std::size_t end = matrix.data + matrix.bytes;
    const Tag length = ReadTag(bytes, array.fields_at, end);
    const Tag names = ReadTag(bytes, length.end, end);
    const std::size_t name_length = U32(bytes, length.data);
    for (std::size_t f = 0; f < names.bytes / name_length; ++f) {
      std::string field(bytes.data() + names.data + f * name_length, name_length);
      out.fields.push_back(field.substr(0, field.find('\0')));
    }
    out.count = array.view.count;
    out.values.reserve(out.count * out.fields.size());  // each one an element the check walked
    std::size_t at = names.end;
    for (std::size_t k = 0; k < out.count * out.fields.size(); ++k) {
      const Array field = Read(bytes, at);
      out.values.push_back(field.view);
      at = field.end;
    }
    return out;
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

  // The element a compressed one holds: its size counted first (inflated into a scratch buffer),
  // checked against what is left of the budget, then inflated into exactly that much.
  std::string Inflate(const std::string& compressed) const {
    std::string scratch(1 << 20, '\0');
    const std::uint64_t size = InflateInto(compressed, scratch, true);
    if (size > left_) {
      throw fail_("its compressed elements inflate to more than the " + ByteCount(left_) +
                  " left of what sonarbench reads from one log (import's --max-input-mb raises "
                  "it)");
    }
    std::string out(size, '\0');
    (void)InflateInto(compressed, out, false);
    left_ -= size;
    return out;
  }

  // Inflates `compressed` into `out` (over and over when `count_only`, which stops past left_);
  // returns the bytes it inflates to.
  std::uint64_t InflateInto(const std::string& compressed, std::string& out,
                            bool count_only) const {
    z_stream stream{};
    if (inflateInit(&stream) != Z_OK) throw fail_("zlib cannot start");
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
    stream.avail_in = static_cast<uInt>(compressed.size());
    int status = Z_OK;
    std::uint64_t total = 0;
    while (status == Z_OK && (!count_only || total <= left_)) {
      const std::size_t at = count_only ? 0 : static_cast<std::size_t>(total);
      stream.next_out = reinterpret_cast<Bytef*>(out.data() + at);
      stream.avail_out = static_cast<uInt>(std::min<std::size_t>(out.size() - at, 1 << 20));
      if (stream.avail_out == 0) break;
      const uInt room = stream.avail_out;
      status = inflate(&stream, Z_NO_FLUSH);
      total += room - stream.avail_out;
    }
    inflateEnd(&stream);
    if (count_only && total > left_) return total;
    if (status != Z_STREAM_END) throw fail_("a compressed element does not inflate whole");
    return total;
  }

  // One element and, if it is an array (miMATRIX), what it holds.
  void Element(const std::string& bytes, int depth) const {
    if (bytes.empty()) return;
    const Tag tag = ReadTag(bytes, 0, bytes.size());
    if (tag.type == kMatrix) Matrix(bytes, tag, depth);
  }

  // The values element at `at` of an array of `elements` (a real or imaginary part): as many
  // values as that, of a type of known size. Returns where the next element starts.
  std::size_t Values(const std::string& bytes, std::size_t at, std::size_t end,
                     double elements) const {
    const Tag values = ReadTag(bytes, at, end);
    const std::size_t size = TypeBytes(values.type);
    if (size == 0 || static_cast<double>(values.bytes / size) != elements ||
        values.bytes % size != 0) {
      std::ostringstream stated;  // a product of dimensions may pass any integer type
      stated << std::setprecision(15) << elements;
      throw fail_("an array of " + stated.str() + " elements holds " +
                  std::to_string(values.bytes) + " bytes of values");
    }
    return values.end;
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
        at = Values(bytes, at, end, elements);
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

  Fail fail_;
  // What compressed elements may still inflate to (bytes), checked as they inflate.
  mutable std::uint64_t left_;
};

}  // namespace

std::optional<double> ArrayView::NumericAt(std::size_t k) const {
  const std::size_t size = TypeBytes(data_type);
  if (complex || data == nullptr || k >= count || size == 0 || data_type >= 16 ||
      (k + 1) * size > data_bytes) {
    return std::nullopt;
  }
  const double value = StoredAt(data + k * size, data_type);
  switch (array_class) {
    case 6:
      return value;
    case 7:
      return As<float>(value);
    case 8:
      return As<std::int8_t>(value);
    case 9:
      return As<std::uint8_t>(value);
    case 10:
      return As<std::int16_t>(value);
    case 11:
      return As<std::uint16_t>(value);
    case 12:
      return As<std::int32_t>(value);
    case 13:
      return As<std::uint32_t>(value);
    default:
      return std::nullopt;
  }
}

std::string_view ArrayView::StoredBytes() const {
  constexpr std::uint32_t kUint8 = 2;  // miUINT8
  const bool holds_bytes =
      array_class == 6 || array_class == 7 || (array_class >= 9 && array_class <= 13);
  if (complex || data == nullptr || data_type != kUint8 || !holds_bytes || count > data_bytes) {
    return {};
  }
  return {data, count};
}

const ArrayView* StructArray::Field(std::size_t i, std::string_view name) const {
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (fields[f] == name) return i < count ? &values[i * fields.size() + f] : nullptr;
  }
  return nullptr;
}

bool IsV5(const std::string& bytes) {
  return bytes.size() >= 128 && bytes.compare(126, 2, "IM") == 0 &&
         static_cast<unsigned char>(bytes[125]) == 0x01;
}

std::optional<std::string> CheckFile(const std::string& bytes, std::string_view name,
                                     const Fail& fail, std::uint64_t max_inflated) {
  const Walker walker(fail, max_inflated);
  return walker.File(bytes, name);
}

std::optional<StructArray> ReadStructArray(std::string variable, const Fail& fail) {
  return Walker(fail).Struct(std::move(variable));
}

}  // namespace sonarbench::io::mat_v5
