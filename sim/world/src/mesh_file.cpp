#include "sonarbench/sim/world/mesh_file.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <vector>

#include "collada_check.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::sim {
namespace {

// A PLY value as the file would write it: 99, -5, 2.5.
std::string Number(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// A PLY scalar type.
struct PlyType {
  int bytes = 0;  // 0: not a PLY type
  bool is_signed = false;
  bool is_float = false;
};

PlyType PlyTypeNamed(const std::string& name) {
  static const std::map<std::string, PlyType> kTypes = {
      {"char", {1, true, false}},    {"int8", {1, true, false}},    {"uchar", {1, false, false}},
      {"uint8", {1, false, false}},  {"short", {2, true, false}},   {"int16", {2, true, false}},
      {"ushort", {2, false, false}}, {"uint16", {2, false, false}}, {"int", {4, true, false}},
      {"int32", {4, true, false}},   {"uint", {4, false, false}},   {"uint32", {4, false, false}},
      {"float", {4, true, true}},    {"float32", {4, true, true}},  {"double", {8, true, true}},
      {"float64", {8, true, true}}};
  const auto found = kTypes.find(name);
  return found == kTypes.end() ? PlyType{} : found->second;
}

// A polygon past kMaxPolygonCorners, for a refusal.
std::string TooManyCorners(double corners) {
  return ": a face of " + Number(corners) + " corners, expected at most " +
         Number(kMaxPolygonCorners) + " (Assimp triangulates a polygon in quadratic time)";
}

// One property of a PLY element: a scalar, or a list (a count, then that many items).
struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count;  // the list's
  PlyType item;   // the scalar, or each item of the list
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::string format;  // ascii, binary_little_endian or binary_big_endian
  std::vector<PlyElement> elements;
  std::size_t body = 0;  // where the body starts
  int lines = 0;         // the header's, end_header's included
};

// A "property" line's words after the keyword: TYPE NAME, or list COUNT_TYPE ITEM_TYPE NAME.
PlyProperty ReadPlyProperty(std::istringstream& words,
                            const std::function<InputError(const std::string&)>& bad_line) {
  PlyProperty property;
  std::string type;
  words >> type;
  if (type == "list") {
    std::string count_type, item_type;
    words >> count_type >> item_type >> property.name;
    property.list = true;
    property.count = PlyTypeNamed(count_type);
    property.item = PlyTypeNamed(item_type);
    if (property.count.bytes == 0 || property.count.is_float || property.item.bytes == 0) {
      throw bad_line("property list COUNT_TYPE ITEM_TYPE NAME, COUNT_TYPE an integer type");
    }
  } else {
    words >> property.name;
    property.item = PlyTypeNamed(type);
    if (property.item.bytes == 0) throw bad_line("property TYPE NAME, TYPE a PLY type");
  }
  return property;
}

PlyHeader ReadPlyHeader(const std::string& bytes,
                        const std::function<InputError(std::string)>& fail) {
  PlyHeader header;
  std::size_t at = 0;
  for (int line_number = 1;; ++line_number) {
    const std::size_t end = bytes.find('\n', at);
    if (end == std::string::npos) throw fail("the header has no 'end_header' line");
    std::string line = bytes.substr(at, end - at);
    at = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // Assimp reads a header line up to a NUL or other control byte, and a count after it.
    for (const char c : line) {
      if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f) {
        throw fail("header line " + std::to_string(line_number) + " holds the control character " +
                   io::Quoted(std::string_view(&c, 1)));
      }
    }
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    const auto bad_line = [&](const std::string& expected) {
      return fail("header line " + std::to_string(line_number) + ": expected " + expected +
                  ", got " + io::Quoted(line));
    };
    if (line_number == 1) {
      if (keyword != "ply" || words >> keyword) throw bad_line("'ply'");
    } else if (keyword == "end_header") {
      header.lines = line_number;
      break;
    } else if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) {
      continue;
    } else if (keyword == "format") {
      words >> header.format;
      if (header.format != "ascii" && header.format != "binary_little_endian" &&
          header.format != "binary_big_endian") {
        throw bad_line("format ascii, binary_little_endian or binary_big_endian");
      }
    } else if (keyword == "element") {
      PlyElement element;
      if (!(words >> element.name >> element.count)) throw bad_line("element NAME COUNT");
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) throw bad_line("an element before its properties");
      header.elements.back().properties.push_back(ReadPlyProperty(words, bad_line));
    } else {
      throw bad_line("a PLY header keyword");
    }
  }
  if (header.format.empty()) throw fail("the header has no 'format' line");
  header.body = at;
  return header;
}

// The values of a PLY body one by one: binary of either order, or ASCII numbers, one element per
// line, separated by spaces or tabs.
class PlyValues {
 public:
  PlyValues(const std::string& bytes, const PlyHeader& header,
            std::function<InputError(std::string)> fail)
      : bytes_(bytes),
        at_(header.body),
        line_number_(header.lines),
        ascii_(header.format == "ascii"),
        little_endian_(header.format == "binary_little_endian"),
        fail_(std::move(fail)) {}

  [[nodiscard]] bool ascii() const { return ascii_; }
  // The file's line that the element being read is on (ASCII).
  [[nodiscard]] int line_number() const { return line_number_; }

  // Starts an element: in ASCII its line, the next one not blank; false if there is none.
  bool BeginElement() {
    if (!ascii_) return true;
    for (;;) {
      if (at_ >= bytes_.size()) return false;
      line_end_ = std::min(bytes_.find('\n', at_), bytes_.size());
      ++line_number_;
      // Assimp ends a line at a form feed or a NUL as well: such a byte would split an element.
      for (std::size_t i = at_; i < line_end_; ++i) {
        const auto c = static_cast<unsigned char>(bytes_[i]);
        if ((c < 0x20 && c != '\t' && !(c == '\r' && i + 1 == line_end_)) || c == 0x7f) {
          throw fail_("line " + std::to_string(line_number_) + " holds the control character " +
                      io::Quoted(std::string_view(bytes_.data() + i, 1)));
        }
      }
      SkipBlanks();
      if (at_ < line_end_) return true;
      at_ = line_end_ + 1;
    }
  }

  // The next value, read as `type`; nullopt at the body's end, or in ASCII at the line's.
  std::optional<double> Next(const PlyType& type) {
    if (ascii_) {
      SkipBlanks();
      if (at_ >= line_end_) return std::nullopt;
      std::size_t end = at_;
      while (end < line_end_ && !IsBlank(bytes_[end])) ++end;
      double value = 0.0;
      const auto [stop, error] = std::from_chars(bytes_.data() + at_, bytes_.data() + end, value);
      if (error != std::errc() || stop != bytes_.data() + end) {
        throw fail_("line " + std::to_string(line_number_) + " holds " +
                    io::Quoted(bytes_.substr(at_, end - at_)) + " where a number belongs");
      }
      at_ = end;
      return value;
    }
    if (bytes_.size() - at_ < static_cast<std::size_t>(type.bytes)) return std::nullopt;
    std::uint64_t bits = 0;
    for (int b = 0; b < type.bytes; ++b) {
      const int shift = little_endian_ ? 8 * b : 8 * (type.bytes - 1 - b);
      bits |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[at_ + b])) << shift;
    }
    at_ += type.bytes;
    if (type.is_float && type.bytes == 4) {
      float value = 0.0f;
      const auto narrow = static_cast<std::uint32_t>(bits);
      std::memcpy(&value, &narrow, sizeof value);
      return value;
    }
    if (type.is_float) {
      double value = 0.0;
      std::memcpy(&value, &bits, sizeof value);
      return value;
    }
    if (type.is_signed && (bits >> (8 * type.bytes - 1)) != 0) {
      return static_cast<double>(bits) - std::ldexp(1.0, 8 * type.bytes);
    }
    return static_cast<double>(bits);
  }

  // Ends an element: in ASCII its line holds nothing more.
  void EndElement(const std::string& element) {
    if (!ascii_) return;
    SkipBlanks();
    if (at_ < line_end_) {
      throw fail_("line " + std::to_string(line_number_) + " holds more values than " + element +
                  " has properties");
    }
    at_ = line_end_ + 1;
  }

 private:
  static bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
  void SkipBlanks() {
    while (at_ < line_end_ && IsBlank(bytes_[at_])) ++at_;
  }

  const std::string& bytes_;
  std::size_t at_;
  std::size_t line_end_ = 0;
  int line_number_;
  bool ascii_;
  bool little_endian_;
  std::function<InputError(std::string)> fail_;
};

// Assimp 5.2's PLY reader loops for ever on a header without `end_header`, aborts (an assertion
// in its triangulation) on a body shorter than its header declares or on a face of no vertices,
// and reads out of bounds through a face's vertex index past the vertices. So a PLY file is
// checked first: its header whole, every element the header counts present in the body (in ASCII
// on a line of its own, as Assimp reads it), and every face a list of at least one whole index to
// one of the vertices.
void CheckPly(const std::string& path, const std::string& bytes) {
  const auto fail = [&](std::string what) {
    return InputError(path + ": not a readable PLY file: " + what);
  };
  const PlyHeader header = ReadPlyHeader(bytes, fail);
  std::uint64_t vertices = 0;
  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") vertices = element.count;
  }
  PlyValues values(bytes, header, fail);
  for (const PlyElement& element : header.elements) {
    for (std::uint64_t i = 0; i < element.count && !element.properties.empty(); ++i) {
      const auto where = [&] { return "element '" + element.name + "' " + std::to_string(i); };
      const auto ends = [&] {
        return fail("the body ends in " + where() + " of the " + std::to_string(element.count) +
                    " its header declares");
      };
      if (!values.BeginElement()) throw ends();
      const auto next = [&](const PlyType& type) {
        const std::optional<double> value = values.Next(type);
        if (value) return *value;
        if (!values.ascii()) throw ends();
        throw fail("line " + std::to_string(values.line_number()) + " holds fewer values than " +
                   where() + " has properties");
      };
      for (const PlyProperty& p : element.properties) {
        if (!p.list) {
          (void)next(p.item);
          continue;
        }
        const double count = next(p.count);
        if (count < 0.0 || count != std::floor(count)) {
          throw fail(where() + ": a list's count of " + Number(count));
        }
        const bool indices =
            element.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index");
        if (indices && count == 0.0) throw fail(where() + ": a face of no vertices");
        if (indices && count > kMaxPolygonCorners) throw fail(where() + TooManyCorners(count));
        for (double k = 0; k < count; ++k) {
          const double index = next(p.item);
          if (indices && (index < 0.0 || index >= static_cast<double>(vertices) ||
                          index != std::floor(index))) {
            throw fail(where() + ": vertex index " + Number(index) +
                       ", expected a whole index from 0 of the " + std::to_string(vertices) +
                       " vertices");
          }
        }
      }
      values.EndElement(where());
    }
  }
}

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// The triangles a mesh file holds, counted from its text without building them: an OBJ's faces
// (n corners make n - 2), an STL's facets, a PLY's faces, a COLLADA file's primitives' counts.
// Assimp makes at least this many (a polygon of n corners as n - 2).
double CountTriangles(const std::string& path, const std::string& bytes,
                      const std::string& extension) {
  const std::string lower = Lowercase(bytes.substr(0, 4096));
  double triangles = 0.0;
  if (extension == ".ply" || lower.starts_with("ply")) {
    try {
      const PlyHeader header =
          ReadPlyHeader(bytes, [](std::string what) { return InputError(what); });
      for (const PlyElement& element : header.elements) {
        if (element.name == "face") triangles += static_cast<double>(element.count);
      }
    } catch (const InputError&) {
      // CheckPly reports it.
    }
  } else if (extension == ".dae" || lower.find("<collada") != std::string::npos) {
    for (const std::string tag : {"triangles", "polylist", "polygons", "tristrips", "trifans"}) {
      ForEachXmlElement(bytes, tag, [&](const XmlElement& element) {
        const auto count = XmlAttribute(element.attributes, "count");
        if (const auto n = count ? WholeNumber(*count) : std::nullopt) {
          triangles += static_cast<double>(*n);
        }
      });
    }
  } else if (extension == ".stl" || lower.starts_with("solid")) {
    std::uint32_t facets = 0;
    if (bytes.size() >= 84) std::memcpy(&facets, bytes.data() + 80, 4);
    if (bytes.size() == 84 + 50 * std::uint64_t{facets}) return facets;  // binary
    for (std::size_t at = bytes.find("endfacet"); at != std::string::npos;
         at = bytes.find("endfacet", at + 8)) {
      ++triangles;
    }
  } else {
    // OBJ, and what Assimp reads as it does: "f a b c ..." lines.
    for (std::size_t at = 0; at < bytes.size();) {
      std::size_t end = bytes.find('\n', at);
      if (end == std::string::npos) end = bytes.size();
      if (end - at > 1 && bytes[at] == 'f' && (bytes[at + 1] == ' ' || bytes[at + 1] == '\t')) {
        std::istringstream corners(bytes.substr(at + 2, end - at - 2));
        double n = 0;
        for (std::string corner; corners >> corner;) ++n;
        if (n > kMaxPolygonCorners) throw InputError(path + ": an 'f' line" + TooManyCorners(n));
        triangles += std::max(0.0, n - 2);
      }
      at = end + 1;
    }
  }
  return triangles;
}

}  // namespace

MeshFileData LoadMeshFile(const std::string& path, double max_triangles) {
  std::error_code error;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path, error))) {
    throw InputError(path + ": no such mesh file");
  }
  // What Assimp cannot read safely is checked first, in the formats it reads by their content;
  // and what it would build is counted before it allocates.
  std::string bytes = ReadFileBytes(path, kMaxMeshFileBytes);
  // Assimp picks a reader by the extension and then by the content: either sends a file here.
  const std::string extension = Lowercase(std::filesystem::path(path).extension().string());
  const std::string lower = Lowercase(bytes.substr(0, 4096));
  if (extension == ".ply" || lower.starts_with("ply")) {
    CheckPly(path, bytes);
  } else if (extension == ".dae" || lower.find("<collada") != std::string::npos) {
    CheckCollada(path, bytes);
  }
  if (const double triangles = CountTriangles(path, bytes, extension);
      !(triangles <= max_triangles)) {
    char text[96];
    std::snprintf(text, sizeof text, "holds %.3g triangles, more than the %.3g", triangles,
                  max_triangles);
    throw InputError(path + ": " + text +
                     " this run allows (--max-triangles raises the limit; expected a mesh this "
                     "machine can hold)");
  }
  bytes = std::string();
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // Points and lines have no surface to echo from.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                  aiProcess_SortByPType | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0) {
    throw InputError(path + ": not a readable mesh file (OBJ, STL, PLY or DAE expected): " +
                     io::Quoted(importer.GetErrorString(), 300));
  }
  MeshFileData data;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(data.vertices.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      data.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      data.triangles.push_back(
          {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  if (data.triangles.empty()) throw InputError(path + ": the mesh file holds no triangle");
  return data;
}

}  // namespace sonarbench::sim
