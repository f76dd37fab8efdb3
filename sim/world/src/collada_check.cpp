#include "collada_check.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <set>
#include <sstream>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::sim {
namespace {

// The ids the file's elements carry (id="..."), for its references to resolve against.
std::set<std::string> XmlIds(const std::string& bytes) {
  std::set<std::string> ids;
  for (std::size_t at = bytes.find("id="); at != std::string::npos;
       at = bytes.find("id=", at + 1)) {
    if (at == 0 || !std::isspace(static_cast<unsigned char>(bytes[at - 1]))) continue;
    const std::size_t open = at + 3;
    if (open >= bytes.size() || (bytes[open] != '"' && bytes[open] != '\'')) continue;
    const std::size_t close = bytes.find(bytes[open], open + 1);
    if (close != std::string::npos) ids.insert(bytes.substr(open + 1, close - open - 1));
  }
  return ids;
}

// Every <instance_*> element must name an element of the file ("#id"), and one visual scene is
// instantiated: Assimp 5.2 leaks what it built of the scene otherwise.
void CheckColladaInstances(const std::string& bytes,
                           const std::function<InputError(std::size_t, const std::string&)>& fail) {
  const std::set<std::string> ids = XmlIds(bytes);
  int visual_scenes = 0;
  for (std::size_t at = bytes.find("<instance_"); at != std::string::npos;
       at = bytes.find("<instance_", at + 1)) {
    const std::size_t name_end = bytes.find_first_of(" \t\r\n/>", at);
    const std::size_t end = bytes.find('>', at);
    if (name_end == std::string::npos || end == std::string::npos) return;
    const std::string tag = bytes.substr(at + 1, name_end - at - 1);
    if (tag == "instance_visual_scene" && ++visual_scenes > 1) {
      throw fail(at,
                 "a second <instance_visual_scene>, expected one (COLLADA's <scene> holds one)");
    }
    const std::string key = tag == "instance_material" ? "target" : "url";
    const std::optional<std::string> ref =
        XmlAttribute(bytes.substr(name_end, end - name_end), key);
    if (!ref || !ref->starts_with('#') || !ids.contains(ref->substr(1))) {
      throw fail(at, "<" + tag + "> " + (ref ? "refers to " + io::Quoted(*ref) : "has no " + key) +
                         ", expected " + key + "=\"#ID\" naming an element of this file");
    }
  }
}

// Assimp 5.2 aborts on a primitive (<triangles>, <polylist>, ...) of a nonzero count without its
// index list <p>.
void CheckColladaPrimitives(
    const std::string& bytes,
    const std::function<InputError(std::size_t, const std::string&)>& fail) {
  for (const std::string tag :
       {"triangles", "polylist", "polygons", "lines", "linestrips", "tristrips", "trifans"}) {
    for (std::size_t at = bytes.find("<" + tag); at != std::string::npos;
         at = bytes.find("<" + tag, at + 1)) {
      const std::size_t name_end = at + 1 + tag.size();
      const std::size_t open_end = bytes.find('>', name_end);
      if (open_end == std::string::npos) return;  // Assimp's parser reports a cut-off tag
      if (bytes[name_end] != '>' && !std::isspace(static_cast<unsigned char>(bytes[name_end]))) {
        continue;  // another element whose name starts so
      }
      const std::optional<std::string> said =
          XmlAttribute(bytes.substr(name_end, open_end - name_end), "count");
      if (said && WholeNumber(*said) == 0u) continue;
      const std::size_t close =
          bytes[open_end - 1] == '/' ? open_end : bytes.find("</" + tag, open_end);
      const std::string body = bytes.substr(open_end, close - open_end);
      if (body.find("<p>") == std::string::npos && body.find("<p ") == std::string::npos) {
        throw fail(at, "<" + tag + "> of " + (said ? "count " + *said : "no count") +
                           " has no index list <p>, expected one");
      }
    }
  }
}

}  // namespace

void ForEachXmlElement(const std::string& bytes, const std::string& tag,
                       const std::function<void(const XmlElement&)>& each) {
  for (std::size_t at = bytes.find("<" + tag); at != std::string::npos;
       at = bytes.find("<" + tag, at + 1)) {
    const std::size_t name_end = at + 1 + tag.size();
    if (name_end >= bytes.size()) break;
    // Another element whose name starts so (<param>, <vertices>).
    if (bytes[name_end] != '>' && !std::isspace(static_cast<unsigned char>(bytes[name_end]))) {
      continue;
    }
    const std::size_t content = bytes.find('>', name_end);
    if (content == std::string::npos || bytes[content - 1] == '/') continue;
    const std::size_t content_end = std::min(bytes.find('<', content), bytes.size());
    each({.at = at,
          .attributes = bytes.substr(name_end, content - name_end),
          .content = bytes.substr(content + 1, content_end - content - 1)});
  }
}

std::optional<std::string> XmlAttribute(const std::string& attributes, const std::string& name) {
  for (std::size_t at = attributes.find(name); at != std::string::npos;
       at = attributes.find(name, at + 1)) {
    if (at == 0 || !std::isspace(static_cast<unsigned char>(attributes[at - 1]))) continue;
    std::size_t i = at + name.size();
    while (i < attributes.size() && std::isspace(static_cast<unsigned char>(attributes[i]))) ++i;
    if (i == attributes.size() || attributes[i] != '=') continue;
    ++i;
    while (i < attributes.size() && std::isspace(static_cast<unsigned char>(attributes[i]))) ++i;
    if (i == attributes.size() || (attributes[i] != '"' && attributes[i] != '\'')) continue;
    const std::size_t end = attributes.find(attributes[i], i + 1);
    if (end == std::string::npos) return std::nullopt;
    return attributes.substr(i + 1, end - i - 1);
  }
  return std::nullopt;
}

std::optional<std::uint64_t> WholeNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const char* const first = text.data() + (text[0] == '+' ? 1 : 0);
  const char* const end = text.data() + text.size();
  std::uint64_t value = 0;
  const auto [stop, error] = std::from_chars(first, end, value);
  if (error != std::errc() || stop != end) return std::nullopt;
  return value;
}

// Assimp 5.2's COLLADA reader loops for ever on an index list (<p>, <vcount>, <v> or <h>)
// holding anything but whole numbers, takes an index of 2^31 or more for a valid one (4e9 in a
// 12-triangle file read as whole), segfaults on an array (<float_array>, ...) without a whole
// `count`, and reads only `count` of its items when there are more. So index lists and arrays
// are checked first.
void CheckCollada(const std::string& path, const std::string& bytes) {
  const auto fail = [&](std::size_t at, const std::string& what) {
    const auto line = std::count(bytes.begin(), bytes.begin() + static_cast<long>(at), '\n');
    return InputError(path + ":" + std::to_string(line + 1) +
                      ": not a readable COLLADA file: " + what);
  };
  for (const std::string tag : {"p", "vcount", "v", "h"}) {
    ForEachXmlElement(bytes, tag, [&](const XmlElement& element) {
      std::istringstream items(element.content);
      for (std::string item; items >> item;) {
        if (const auto index = WholeNumber(item); !index || *index > 0x7fffffff) {
          throw fail(element.at, "<" + tag + "> holds " + io::Quoted(item) +
                                     " where an index (a whole number from 0 to 2^31 - 1) "
                                     "belongs");
        }
      }
    });
  }
  for (const std::string tag :
       {"float_array", "int_array", "bool_array", "Name_array", "IDREF_array"}) {
    ForEachXmlElement(bytes, tag, [&](const XmlElement& element) {
      std::istringstream items(element.content);
      std::uint64_t count = 0;
      for (std::string item; items >> item;) ++count;
      const std::optional<std::string> said = XmlAttribute(element.attributes, "count");
      if (!said || WholeNumber(*said) != count) {
        throw fail(element.at, "<" + tag + "> holds " + std::to_string(count) +
                                   " items, expected its count attribute to say so, as count=\"" +
                                   std::to_string(count) + "\"");
      }
    });
  }
  CheckColladaPrimitives(bytes, fail);
  CheckColladaInstances(bytes, fail);
}

}  // namespace sonarbench::sim
