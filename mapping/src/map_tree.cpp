#include "map_tree.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

constexpr unsigned kDepth = 16;

// A leaf's place in OctoMap's depth-first order: its Morton code (x, y, z from the high bit of
// each level's three) with x and z swapped, OctoMap's child index being x | y << 1 | z << 2.
std::uint64_t TreeOrder(std::uint64_t morton) {
  constexpr std::uint64_t kX = 0x924924924924ULL, kY = 0x492492492492ULL, kZ = 0x249249249249ULL;
  return (morton & kY) | ((morton & kX) >> 2) | ((morton & kZ) << 2);
}

// The child index at level `depth` (0: the root's children) of a leaf in tree order.
unsigned ChildAt(std::uint64_t order, unsigned depth) {
  return static_cast<unsigned>(order >> (3 * (kDepth - 1 - depth))) & 7u;
}

using Leaves = std::vector<std::pair<std::uint64_t, float>>;

// The leaves [first, last) below one node at `depth` split by its children: each child's end.
std::array<std::size_t, 8> ChildEnds(const Leaves& leaves, std::size_t first, std::size_t last,
                                     unsigned depth) {
  std::array<std::size_t, 8> ends{};
  std::size_t at = first;
  for (unsigned c = 0; c < 8; ++c) {
    while (at < last && ChildAt(leaves[at].first, depth) == c) ++at;
    ends[c] = at;
  }
  return ends;
}

// OctoMap's .bt record of the node at `depth` holding leaves [first, last), then its inner
// children's (writeBinaryNode): two bits a child, 01 free leaf, 10 occupied, 11 inner. Counts
// the nodes in `nodes`.
void BinaryNode(const Leaves& leaves, std::size_t first, std::size_t last, unsigned depth,
                float threshold, std::string& out, std::size_t& nodes) {
  ++nodes;
  const std::array<std::size_t, 8> ends = ChildEnds(leaves, first, last, depth);
  const bool leaf_children = depth + 1 == kDepth;
  unsigned bits = 0;
  std::size_t begin = first;
  for (unsigned c = 0; c < 8; ++c) {
    if (ends[c] > begin) {
      const unsigned kind = !leaf_children ? 3u : (leaves[begin].second >= threshold ? 2u : 1u);
      bits |= kind << (2 * c);
      nodes += leaf_children ? 1 : 0;
    }
    begin = ends[c];
  }
  out.push_back(static_cast<char>(bits & 0xff));
  out.push_back(static_cast<char>(bits >> 8));
  if (leaf_children) return;
  begin = first;
  for (unsigned c = 0; c < 8; ++c) {
    if (ends[c] > begin) BinaryNode(leaves, begin, ends[c], depth + 1, threshold, out, nodes);
    begin = ends[c];
  }
}

// OctoMap's .ot record of the node at `depth` (writeNodesRecurs): its log-odds (an inner node's
// the greatest of its children's, as updateInnerOccupancy leaves it), a byte of which children
// exist, then the children's. Returns the node's log-odds; counts the nodes in `nodes`.
float FullNode(const Leaves& leaves, std::size_t first, std::size_t last, unsigned depth,
               std::string& out, std::size_t& nodes) {
  ++nodes;
  if (depth == kDepth) {
    const float value = leaves[first].second;
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
    out.push_back('\0');
    return value;
  }
  const std::size_t at = out.size();
  out.append(sizeof(float), '\0');
  const std::array<std::size_t, 8> ends = ChildEnds(leaves, first, last, depth);
  unsigned children = 0;
  std::size_t begin = first;
  for (unsigned c = 0; c < 8; ++c) {
    if (ends[c] > begin) children |= 1u << c;
    begin = ends[c];
  }
  out.push_back(static_cast<char>(children));
  float max = -std::numeric_limits<float>::max();
  begin = first;
  for (unsigned c = 0; c < 8; ++c) {
    if (ends[c] > begin)
      max = std::max(max, FullNode(leaves, begin, ends[c], depth + 1, out, nodes));
    begin = ends[c];
  }
  std::copy_n(reinterpret_cast<const char*>(&max), sizeof max,
              out.begin() + static_cast<std::ptrdiff_t>(at));
  return max;
}

// The Morton index within an 8³ block of each index in tree order (TreeOrder is its inverse).
std::array<unsigned, 512> MortonOfTreeIndex() {
  std::array<unsigned, 512> morton{};
  for (unsigned m = 0; m < 512; ++m) morton[TreeOrder(m)] = m;
  return morton;
}

}  // namespace

void WriteOctomapHeader(const octomap::OcTree& tree, std::size_t nodes, bool full,
                        std::ostream& out) {
  // AbstractOccupancyOcTree::writeBinaryConst's header, and AbstractOcTree::write's.
  out << (full ? kOctomapFullHeader : kOctomapBinaryHeader)
      << "\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
      << "id " << tree.getTreeType() << "\n"
      << "size " << nodes << "\n"
      << "res " << tree.getResolution() << "\n"
      << "data\n";
}

std::vector<std::pair<std::uint64_t, float>> MapTree::LeavesInTreeOrder() const {
  static const std::array<unsigned, 512> kMorton = MortonOfTreeIndex();
  std::vector<std::pair<std::uint64_t, const LeafBlock*>> blocks;
  for (const auto& leaves : leaves_) {
    for (const LeafBlock& block : leaves.blocks())
      blocks.emplace_back(TreeOrder(block.origin), &block);
  }
  std::sort(blocks.begin(), blocks.end());
  Leaves leaves;
  for (const auto& [order, block] : blocks) {
    for (unsigned t = 0; t < 512; ++t) {
      const unsigned m = kMorton[t];
      if ((block->present[m >> 6] >> (m & 63)) & 1u) {
        leaves.emplace_back(order | t, block->log_odds[m]);
      }
    }
  }
  return leaves;
}

void MapTree::WriteBinaryFromLeaves(std::ostream& out) const {
  const Leaves leaves = LeavesInTreeOrder();
  std::string data;
  std::size_t nodes = 0;
  if (!leaves.empty()) BinaryNode(leaves, 0, leaves.size(), 0, occ_prob_thres_log, data, nodes);
  WriteOctomapHeader(*this, nodes, false, out);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

void MapTree::WriteFullFromLeaves(std::ostream& out) const {
  const Leaves leaves = LeavesInTreeOrder();
  std::string data;
  std::size_t nodes = 0;
  if (!leaves.empty()) (void)FullNode(leaves, 0, leaves.size(), 0, data, nodes);
  WriteOctomapHeader(*this, nodes, true, out);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

}  // namespace sonarbench::mapping
