#pragma once

// MAT v5 files read without libmatio: their elements' layout checked against the bytes they hold,
// and a struct array's values read in place. Internal to sonarbench::io (the .mat log reader).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sonarbench/base/error.hpp"

namespace sonarbench::io::mat_v5 {

using Fail = std::function<InputError(const std::string&)>;

/// An array's values as stored: the array's class (MAT's numbering: 6 double, 7 single, 8-13
/// int8..uint32), its element count, and its real part's data type (1-7, 9, 12, 13) and bytes.
struct ArrayView {
  std::uint32_t array_class = 0;
  bool complex = false;
  std::size_t count = 0;
  std::uint32_t data_type = 0;
  const char* data = nullptr;
  std::size_t data_bytes = 0;
  /// Dimensions longer than 1: at most one for a vector (or a scalar).
  int long_dims = 0;

  /// Element k of a real array of class double, single or (u)int8..32, as the class holds it;
  /// nullopt for other classes, complex arrays and k out of range.
  [[nodiscard]] std::optional<double> NumericAt(std::size_t k) const;
  /// The values as bytes when they are stored as uint8 in a real array whose class holds 0..255
  /// exactly (double, single, uint8, (u)int16, (u)int32): what NumericAt reads, without a call
  /// per value. Empty otherwise.
  [[nodiscard]] std::string_view StoredBytes() const;
};

/// A struct array: its element count, field names and each element's fields.
struct StructArray {
  std::string bytes;  // the element the views point into
  std::size_t count = 0;
  std::vector<std::string> fields;
  std::vector<ArrayView> values;  // element-major: values[i * fields.size() + f]

  /// Element i's field `name`, or nullptr when the struct has no such field.
  [[nodiscard]] const ArrayView* Field(std::size_t i, std::string_view name) const;
};

/// Whether `bytes` start with a little-endian MAT v5 header.
[[nodiscard]] bool IsV5(const std::string& bytes);

/// Checks every element of a MAT v5 file against the bytes it holds (throws fail(what) for the
/// first that does not fit: libmatio sizes arrays by what a file states) and returns the first
/// top-level variable called `name`, inflated, if there is one. Compressed elements inflate to
/// at most `max_inflated` bytes in all, checked as they inflate.
[[nodiscard]] std::optional<std::string> CheckFile(const std::string& bytes, std::string_view name,
                                                   const Fail& fail,
                                                   std::uint64_t max_inflated = UINT64_MAX);

/// A struct array variable (one CheckFile returned) read in place; nullopt for another class.
[[nodiscard]] std::optional<StructArray> ReadStructArray(std::string variable, const Fail& fail);

}  // namespace sonarbench::io::mat_v5
