#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace sonarbench::io {

/// `text` quoted for a message: bytes outside printable ASCII as \xNN, and past `max` bytes cut
/// with "..." (a damaged file's line may be binary, or megabytes without a newline).
[[nodiscard]] std::string Quoted(std::string_view text, std::size_t max = 80);

/// `value` for a message, in at most 6 significant digits ("1e+300", "0.05", "nan").
[[nodiscard]] std::string Number(double value);

/// Whether `text` is well-formed UTF-8 (what JSON reports and manifests can hold).
[[nodiscard]] bool IsUtf8(std::string_view text);

}  // namespace sonarbench::io
