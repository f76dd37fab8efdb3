#pragma once

#include <octomap/OcTree.h>

#include <cstddef>
#include <memory>
#include <string>

#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::io {

/// What an OctoMap file holds, from its header and a walk over its nodes.
struct OcTreeFileInfo {
  /// "bt" (binary: two bits a node, free or occupied) or "ot" (full: a log-odds value a node).
  std::string format;
  /// The header's tree type (`id`); only "OcTree" is read.
  std::string tree_type;
  double resolution_m = 0.0;
  /// Nodes in the file, inner ones included (the header's `size`, checked against the data).
  std::size_t nodes = 0;
  /// Leaf cells at the finest level the leaves stand for: a pruned leaf at depth d counts
  /// 8^(16 - d).
  double leaf_cells = 0.0;
};

/// Reads an OctoMap occupancy tree from a `.bt` file (as octovis and octomap_server save) or a
/// `.ot` file, told apart by the first line, after checking the whole file: the header (`id`
/// OcTree, `res` finite and > 0, `size`, then `data`; comment lines allowed), every node within
/// OctoMap's 16 levels, log-odds finite, exactly `size` nodes, the data ending where the file
/// does, and at most `max_cells` nodes and leaf cells. OctoMap's own reader, which trusts its
/// input, only ever sees a checked file. Throws InputError naming the file and what was expected.
[[nodiscard]] std::unique_ptr<octomap::OcTree> ReadOcTreeFile(const std::string& path,
                                                              double max_cells,
                                                              OcTreeFileInfo* info = nullptr);

/// Writes `mapper`'s map to `path` atomically (WriteFileAtomically: an existing file is replaced
/// only once the new one is whole): `.bt` (Mapper::WriteBinary) or, with kFull, `.ot`
/// (Mapper::WriteFull). Throws EnvironmentError naming the file when the machine refuses.
enum class MapFormat { kBinary, kFull };
void WriteMapFile(const mapping::Mapper& mapper, const std::string& path, MapFormat format);

}  // namespace sonarbench::io
