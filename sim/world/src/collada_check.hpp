#pragma once

// The checks a COLLADA file passes before Assimp reads it, and the plain XML scan they use.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace sonarbench::sim {

/// An element of an XML text, found by its tag: where it starts, its attributes' text and its
/// text up to the next tag.
struct XmlElement {
  std::size_t at = 0;
  std::string attributes;
  std::string content;
};

/// Calls `each` on every element `tag` of `bytes` that is not empty (<p/>). A plain scan, not a
/// parser: what it cannot find, Assimp's own parser reports.
void ForEachXmlElement(const std::string& bytes, const std::string& tag,
                       const std::function<void(const XmlElement&)>& each);
/// The value of the attribute `name` in an element's attributes' text; nullopt if it has none.
[[nodiscard]] std::optional<std::string> XmlAttribute(const std::string& attributes,
                                                      const std::string& name);
/// A whole number as COLLADA's unsigned types write it (a '+' allowed); nullopt if it is not one.
[[nodiscard]] std::optional<std::uint64_t> WholeNumber(const std::string& text);

/// Throws InputError naming `path` and the line where Assimp 5.2 would loop, abort, leak or read
/// out of bounds (collada_check.cpp says which).
void CheckCollada(const std::string& path, const std::string& bytes);

}  // namespace sonarbench::sim
