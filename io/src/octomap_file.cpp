#include "sonarbench/io/octomap_file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::io {
namespace {

constexpr int kTreeDepth = 16;          // OctoMap's levels below the root
constexpr std::size_t kMaxLine = 4096;  // longer header lines are not OctoMap's

// The leaf cells a leaf at `depth` stands for: 8^(16 - depth).
double CellsAtDepth(int depth) { return std::ldexp(1.0, 3 * (kTreeDepth - depth)); }

// The header: the lines up to and including "data"; the stream is left at the first data byte.
struct Header {
  std::string id;
  std::optional<unsigned> size;
  std::optional<double> res;
};

class Reader {
 public:
  Reader(std::istream& in, std::string path) : in_(in), path_(std::move(path)) {}

  // The next header line without its '\n'; throws at the end of the file or a line too long.
  std::string Line() {
    std::string line;
    for (int c = in_.get(); c != '\n'; c = in_.get()) {
      if (c == std::char_traits<char>::eof()) Fail("the header ends before its 'data' line");
      if (line.size() == kMaxLine)
        Fail("header line " + std::to_string(line_ + 1) + " is too long");
      line += static_cast<char>(c);
    }
    ++line_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  }

  Header ReadHeader() {
    Header h;
    for (;;) {
      const std::string line = Line();
      const std::size_t space = line.find(' ');
      const std::string key = line.substr(0, space);
      const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
      if (line.empty() || line[0] == '#') continue;
      if (key == "data" && value.empty()) return h;
      if (key == "id") {
        h.id = value;
      } else if (key == "size") {
        h.size = Parsed<unsigned>(value, "size", "a whole number of nodes");
      } else if (key == "res") {
        h.res = Parsed<double>(value, "res", "a resolution in metres");
      } else {
        Fail("header line " + std::to_string(line_) + " is " + Quoted(line) +
             "; expected 'id', 'size', 'res', 'data' or a comment");
      }
    }
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(path_ + ": not a readable OctoMap file: " + what);
  }

  std::istream& in() { return in_; }
  [[nodiscard]] std::size_t line() const { return line_; }

 private:
  template <typename T>
  T Parsed(const std::string& value, const char* key, const char* expected) {
    T out{};
    const char* end = value.data() + value.size();
    const auto [stop, error] = std::from_chars(value.data(), end, out);
    if (value.empty() || error != std::errc() || stop != end) {
      Fail(std::string("'") + key + "' on header line " + std::to_string(line_) + " is " +
           Quoted(value) + "; expected " + expected);
    }
    return out;
  }

  std::istream& in_;
  std::string path_;
  std::size_t line_ = 0;
};

// Walks the nodes in the order OctoMap writes them (a node, then its inner children's subtrees
// in child order), counting nodes and leaf cells, never deeper than OctoMap's 16 levels.
class NodeWalk {
 public:
  NodeWalk(Reader& reader, bool full, double max_cells)
      : reader_(reader), full_(full), max_cells_(max_cells) {}

  void Root() {
    Count(1, 0.0);
    if (full_) {
      FullNode(0);
    } else if (BinaryNode(0) == 0) {
      Count(0, CellsAtDepth(0));  // a root without children is one leaf
    }
  }

  [[nodiscard]] std::size_t nodes() const { return nodes_; }
  [[nodiscard]] double leaf_cells() const { return leaf_cells_; }

 private:
  void Read(char* bytes, std::size_t count) {
    reader_.in().read(bytes, static_cast<std::streamsize>(count));
    if (reader_.in().gcount() != static_cast<std::streamsize>(count)) {
      reader_.Fail("the data ends inside node " + std::to_string(nodes_) + " (truncated?)");
    }
  }

  void Count(std::size_t nodes, double cells) {
    nodes_ += nodes;
    leaf_cells_ += cells;
    if (static_cast<double>(nodes_) > max_cells_ || leaf_cells_ > max_cells_) {
      reader_.Fail("its nodes stand for more than " + std::to_string(max_cells_) +
                   " cells (--max-cells); a pruned node near the root covers 8^(16 - depth) "
                   "cells");
    }
  }

  void NeedDepth(int depth) const {
    if (depth > kTreeDepth) {
      reader_.Fail("node " + std::to_string(nodes_) + " has children below level 16, the " +
                   "finest OctoMap has");
    }
  }

  // .bt: two bytes, two bits a child, low bit first (1 free leaf, 2 occupied leaf, 3 inner,
  // 0 none). Returns the node's child count.
  int BinaryNode(int depth) {
    unsigned char bytes[2];
    Read(reinterpret_cast<char*>(bytes), 2);
    int children = 0;
    bool inner[8] = {};
    for (int i = 0; i < 8; ++i) {
      const unsigned code = (bytes[i / 4] >> (2 * (i % 4))) & 3U;
      if (code == 0) continue;
      NeedDepth(depth + 1);
      ++children;
      inner[i] = code == 3;
      Count(1, inner[i] ? 0.0 : CellsAtDepth(depth + 1));
    }
    for (int i = 0; i < 8; ++i) {
      if (inner[i] && BinaryNode(depth + 1) == 0) {
        reader_.Fail("node " + std::to_string(nodes_) + " is marked as having children and has " +
                     "none");
      }
    }
    return children;
  }

  // .ot: a float log-odds value and a byte of child flags, then each child's subtree.
  void FullNode(int depth) {
    char bytes[5];
    Read(bytes, 5);
    float log_odds = 0.0F;
    std::memcpy(&log_odds, bytes, sizeof log_odds);
    if (!std::isfinite(log_odds)) {
      reader_.Fail("node " + std::to_string(nodes_) + " has log-odds " + std::to_string(log_odds) +
                   "; expected a finite value");
    }
    const auto flags = static_cast<unsigned char>(bytes[4]);
    if (flags == 0) {
      Count(0, CellsAtDepth(depth));
      return;
    }
    for (int i = 0; i < 8; ++i) {
      if (((flags >> i) & 1U) == 0) continue;
      NeedDepth(depth + 1);
      Count(1, 0.0);
      FullNode(depth + 1);
    }
  }

  Reader& reader_;
  bool full_;
  double max_cells_;
  std::size_t nodes_ = 0;
  double leaf_cells_ = 0.0;
};

// Checks the file whole; returns what it holds and where its data starts.
OcTreeFileInfo CheckFile(const std::string& path, double max_cells, std::streamoff& data_offset) {
  // A FIFO or device is refused by its type before it is opened; a node takes at least 2 bytes
  // (.bt) and at most ~60 in memory, so the cell budget bounds the file too.
  (void)CheckInputFile(path, static_cast<std::uint64_t>(std::min(max_cells * 64.0, 1e12)) + 4096);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the map file");
  Reader reader(in, path);
  OcTreeFileInfo info;
  if (in.peek() == std::char_traits<char>::eof()) {
    reader.Fail(std::string("the file is empty; expected '") + mapping::kOctomapBinaryHeader +
                "' or '" + mapping::kOctomapFullHeader + "' first");
  }
  const std::string first = reader.Line();
  if (first.starts_with(mapping::kOctomapBinaryHeader)) {
    info.format = "bt";
  } else if (first.starts_with(mapping::kOctomapFullHeader)) {
    info.format = "ot";
  } else {
    reader.Fail("the first line is " + Quoted(first) + "; expected '" +
                mapping::kOctomapBinaryHeader + "' (.bt) or '" + mapping::kOctomapFullHeader +
                "' (.ot)");
  }
  const Header header = reader.ReadHeader();
  info.tree_type = header.id;
  if (header.id != "OcTree") {
    reader.Fail("the tree type ('id') is " + Quoted(header.id) +
                "; sonarbench reads occupancy maps of type OcTree (a ColorOcTree or "
                "OcTreeStamped can be converted with OctoMap's tools)");
  }
  if (!header.res || !header.size) reader.Fail("the header has no 'res' or no 'size' line");
  info.resolution_m = *header.res;
  if (!std::isfinite(info.resolution_m) || info.resolution_m <= 0.0) {
    reader.Fail("'res' is " + Number(info.resolution_m) + "; expected metres > 0");
  }
  data_offset = in.tellg();
  NodeWalk walk(reader, info.format == "ot", max_cells);
  if (*header.size > 0) walk.Root();
  if (walk.nodes() != *header.size) {
    reader.Fail("the header's 'size' is " + std::to_string(*header.size) +
                " nodes; the data holds " + std::to_string(walk.nodes()));
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    reader.Fail("bytes follow the tree's data (" + std::to_string(walk.nodes()) + " nodes)");
  }
  info.nodes = walk.nodes();
  info.leaf_cells = walk.leaf_cells();
  return info;
}

}  // namespace

std::unique_ptr<octomap::OcTree> ReadOcTreeFile(const std::string& path, double max_cells,
                                                OcTreeFileInfo* info) {
  std::streamoff data_offset = 0;
  const OcTreeFileInfo checked = CheckFile(path, max_cells, data_offset);
  // OctoMap's node readers, past the header already checked (its header readers print notes).
  auto tree = std::make_unique<octomap::OcTree>(checked.resolution_m);
  std::ifstream in(path, std::ios::binary);
  in.seekg(data_offset);
  if (checked.nodes > 0 && checked.format == "bt") tree->readBinaryData(in);
  if (checked.nodes > 0 && checked.format == "ot") tree->readData(in);
  // The file changed since it was checked.
  if (!in || tree->size() != checked.nodes) {
    throw InputError(path + ": changed while it was read; read it again");
  }
  if (info) *info = checked;
  return tree;
}

void WriteMapFile(const mapping::Mapper& mapper, const std::string& path, MapFormat format) {
  // A failed write leaves `out` bad: WriteFileAtomically reports it with the OS's reason.
  WriteFileAtomically(path, [&](std::ostream& out) {
    if (format == MapFormat::kFull) {
      mapper.WriteFull(out);
    } else {
      mapper.WriteBinary(out);
    }
  });
}

}  // namespace sonarbench::io
