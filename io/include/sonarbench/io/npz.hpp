#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace sonarbench::io {

/// A NumPy .npz archive, built in memory and written at once: a zip (stored without zip64, so at
/// most 4 GiB an array) of one .npy file (format 1.0, C order) per array, each deflated, with
/// fixed time stamps so the same arrays give the same bytes. numpy.load reads it.
class NpzArchive {
 public:
  /// Adds array `name` of NumPy type `descr` ("|u1", "<u2", "<f4", "<f8", "<U16", ...) and
  /// `shape`, its C-order bytes `data` (their count must be the shape's product times the
  /// type's size). Throws std::invalid_argument otherwise, InputError past 4 GiB.
  void Add(const std::string& name, const std::string& descr, const std::vector<std::size_t>& shape,
           std::string_view data);
  /// The archive with `comment` as the zip's comment.
  void Write(std::ostream& out, const std::string& comment) const;

 private:
  struct Entry {
    std::string name;
    std::uint32_t crc = 0;
    std::uint64_t size = 0;
    std::string deflated;
  };
  std::vector<Entry> entries_;
};

/// The zip comment of an .npz file, if it is a zip archive with one.
[[nodiscard]] std::optional<std::string> NpzComment(const std::string& path);

/// Strings as NumPy's fixed-width unicode ("<U`width`", UTF-32 little-endian): the bytes, and
/// the width (the longest string's length in code points; ASCII expected).
[[nodiscard]] std::pair<std::string, std::size_t> NumpyUnicode(
    const std::vector<std::string>& strings);

}  // namespace sonarbench::io
