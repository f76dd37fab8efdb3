#pragma once

#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <span>
#include <utility>
#include <vector>

#include "block_set.hpp"
#include "key_set.hpp"

namespace sonarbench::mapping::detail {
struct ChildLinker;
}  // namespace sonarbench::mapping::detail

namespace octomap {
// OcTreeDataNode befriends every OcTreeBaseImpl<NODE, I>. This one, for a type of ours, links a
// new child into its parent and nothing else: OctoMap's createNodeChild also counts the tree's
// nodes in a member that threads creating nodes in disjoint subtrees would race on.
template <>
class OcTreeBaseImpl<OcTreeNode, sonarbench::mapping::detail::ChildLinker> {
 public:
  static OcTreeNode* NewChild(OcTreeNode* parent, unsigned pos) {
    if (parent->children == nullptr) parent->children = new AbstractOcTreeNode*[8]();
    auto* child = new OcTreeNode();
    parent->children[pos] = child;
    return child;
  }
};
}  // namespace octomap

namespace sonarbench::mapping {

/// The header of OctoMap's binary `.bt` file (writeBinaryConst's) or, with `full`, of its `.ot`
/// file (write's) for `tree` holding `nodes` nodes.
void WriteOctomapHeader(const octomap::OcTree& tree, std::size_t nodes, bool full,
                        std::ostream& out);

/// OctoMap's OcTree, plus what parallel updates need: the log-odds of its leaves as batches
/// leave them, kept in 8³-cell blocks beside the tree (as Bonxai keeps a map), each root octant's
/// apart, and set into the tree's leaves when it is read (SyncLeaves, through FinishUpdates).
class MapTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  /// Applies octant `octant`'s updates to its leaves' log-odds as OctoMap's updateNode(key,
  /// log_odds, /*lazy_eval=*/true) applies them (add, then clamp), without walking the tree.
  /// Updates are Morton code << bits | level (the update log_odds[level]), distinct and sorted;
  /// threads may apply different octants at once.
  void ApplyUpdates(int octant, std::span<const std::uint64_t> updates, unsigned bits,
                    std::span<const float> log_odds) {
    auto& leaves = leaves_[static_cast<std::size_t>(octant)];
    const float min = clamping_thres_min, max = clamping_thres_max;
    const std::uint64_t full = (std::uint64_t{1} << bits) - 1;
    for (const std::uint64_t u : updates) {
      const std::uint64_t code = u >> bits;
      LeafBlock& block = leaves.BlockOf(code & ~std::uint64_t{511});
      const std::size_t index = code & 511;
      float value = block.log_odds[index];
      value += log_odds[u & full];
      block.log_odds[index] = value < min ? min : (value > max ? max : value);
      block.dirty[index >> 6] |= std::uint64_t{1} << (index & 63);
      block.present[index >> 6] |= std::uint64_t{1} << (index & 63);
    }
  }

  /// Writes the map as WriteOctomapBinary (`.bt`) and OcTree::write (`.ot`) write the tree once
  /// SyncLeaves and FinishUpdates ran, byte for byte, from the leaves' log-odds alone: the tree
  /// need not be built. For a map made by ApplyUpdates only (the mapper's).
  void WriteBinaryFromLeaves(std::ostream& out) const;
  void WriteFullFromLeaves(std::ostream& out) const;
  /// Calls `f(key, log_odds)` for every cell ApplyUpdates updated, in no particular order.
  template <typename F>
  void ForEachLeaf(F&& f) const {
    for (const auto& leaves : leaves_) {
      for (const LeafBlock& block : leaves.blocks()) {
        for (unsigned w = 0; w < 8; ++w) {
          for (std::uint64_t bits = block.present[w]; bits != 0; bits &= bits - 1) {
            const unsigned index = 64 * w + static_cast<unsigned>(std::countr_zero(bits));
            f(KeyFromMortonCode(block.origin | index), block.log_odds[index]);
          }
        }
      }
    }
  }

  /// Sets the tree's leaves to the log-odds of every cell updated since the last call, creating
  /// nodes as updateNode would, the octants on up to `threads` threads.
  void SyncLeaves(int threads) {
    std::array<std::size_t, 8> nodes{};
    for (std::size_t o = 0; o < 8; ++o) {  // each octant's cells in Morton order
      auto& codes = sync_codes_[o];
      auto& values = sync_values_[o];
      codes.clear();
      values.clear();
      std::vector<LeafBlock*> dirty;
      for (LeafBlock& block : leaves_[o].blocks()) {
        if (block.dirty != std::array<std::uint64_t, 8>{}) dirty.push_back(&block);
      }
      std::sort(dirty.begin(), dirty.end(),
                [](const LeafBlock* a, const LeafBlock* b) { return a->origin < b->origin; });
      for (LeafBlock* block : dirty) {
        for (unsigned w = 0; w < 8; ++w) {
          for (std::uint64_t bits = block->dirty[w]; bits != 0; bits &= bits - 1) {
            const unsigned index = 64 * w + static_cast<unsigned>(std::countr_zero(bits));
            codes.push_back(block->origin | index);
            values.push_back(block->log_odds[index]);
          }
          block->dirty[w] = 0;
        }
      }
      // The root and its child o, made here: the threads below share no node.
      if (!codes.empty()) CreatePath(KeyFromMortonCode(codes.front()));
    }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int o = 0; o < 8; ++o) {
      const auto& codes = sync_codes_[static_cast<std::size_t>(o)];
      const auto& values = sync_values_[static_cast<std::size_t>(o)];
      nodes[static_cast<std::size_t>(o)] = WalkLeavesUncounted(
          codes.size(), [&codes](std::size_t i) { return KeyFromMortonCode(codes[i]); },
          [&values](std::size_t i, octomap::OcTreeNode* leaf) { leaf->setLogOdds(values[i]); });
    }
    for (const std::size_t n : nodes) AddNodes(n);
  }

  /// Adds `created` nodes to OctoMap's count (the .bt header carries it), after walks that left
  /// the count to the caller (WalkLeavesUncounted in parallel).
  void AddNodes(std::size_t created) {
    tree_size += created;
    size_changed = true;
  }

  /// Creates the root and the nodes on the path to `key`'s leaf, if missing, without changing
  /// a value (a new leaf holds log-odds 0 until its update; adding 0 changes no value).
  void CreatePath(const octomap::OcTreeKey& key) {
    UpdateLeavesInOrder(
        1, [&key](std::size_t) { return key; }, [](std::size_t) { return 0.0f; });
  }

  /// Adds `log_odds(i)` to the leaf of `key(i)` for i in [0, count), creating missing nodes: the
  /// same tree as updateNode(key, log_odds, /*lazy_eval=*/true) for each in turn (OctoMap's early
  /// return at a clamped leaf only skips an update that clamping would undo). The keys must be
  /// distinct and in octree (Morton) order: consecutive keys share the path from the root down
  /// to their deepest common node, which is then not walked again.
  template <typename Key, typename LogOdds>
  void UpdateLeavesInOrder(std::size_t count, Key&& key, LogOdds&& log_odds) {
    AddNodes(WalkLeavesUncounted(count, key, [&](std::size_t i, octomap::OcTreeNode* leaf) {
      updateNodeLogOdds(leaf, log_odds(i));
    }));
  }

  /// Calls `leaf(i, node)` with the leaf of `key(i)` for i in [0, count), creating missing nodes
  /// as UpdateLeavesInOrder does (keys distinct, in Morton order). The nodes it creates are
  /// returned, not counted in the tree: threads may walk disjoint subtrees (below existing
  /// nodes) at once, then AddNodes their sum.
  template <typename Key, typename Leaf>
  [[nodiscard]] std::size_t WalkLeavesUncounted(std::size_t count, Key&& key, Leaf&& leaf) {
    using Linker = octomap::OcTreeBaseImpl<octomap::OcTreeNode, detail::ChildLinker>;
    constexpr unsigned kDepth = 16;
    std::size_t nodes = 0;
    octomap::OcTreeNode* path[kDepth + 1];
    octomap::OcTreeKey previous;
    for (std::size_t i = 0; i < count; ++i) {
      const octomap::OcTreeKey k = key(i);
      // The depth below which this key's path leaves the previous key's.
      unsigned depth = 0;
      bool created = false;  // whether path[depth] was just created
      if (i > 0) {
        const unsigned diff = static_cast<unsigned>((k[0] ^ previous[0]) | (k[1] ^ previous[1]) |
                                                    (k[2] ^ previous[2]));
        depth = kDepth - static_cast<unsigned>(std::bit_width(diff));
      } else {
        if (root == nullptr) {
          root = new octomap::OcTreeNode();
          ++nodes;
          created = true;
        }
        path[0] = root;
      }
      for (; depth < kDepth; ++depth) {
        octomap::OcTreeNode* node = path[depth];
        const unsigned bit = kDepth - 1 - depth;
        const unsigned pos =
            ((k[0] >> bit) & 1u) | (((k[1] >> bit) & 1u) << 1) | (((k[2] >> bit) & 1u) << 2);
        if (!nodeChildExists(node, pos)) {
          if (!nodeHasChildren(node) && !created) {
            // A pruned node: its eight children take its value (OctoMap's expandNode).
            for (unsigned c = 0; c < 8; ++c) Linker::NewChild(node, c)->copyData(*node);
            nodes += 8;
          } else {
            Linker::NewChild(node, pos);
            ++nodes;
            created = true;
          }
        } else {
          created = false;
        }
        path[depth + 1] = getNodeChild(node, pos);
      }
      leaf(i, path[kDepth]);
      previous = k;
    }
    return nodes;
  }

 private:
  // Every updated cell with its log-odds, in the order of OctoMap's depth-first walk: each
  // level's child index x | y << 1 | z << 2, 48 bits.
  [[nodiscard]] std::vector<std::pair<std::uint64_t, float>> LeavesInTreeOrder() const;

  struct LeafBlock {
    std::uint64_t origin = 0;  // the Morton code of its first cell (low nine bits 0)
    std::array<float, 512> log_odds{};
    std::array<std::uint64_t, 8> dirty{};    // bit i: cell i updated since the last SyncLeaves
    std::array<std::uint64_t, 8> present{};  // bit i: cell i updated at all
  };
  std::array<BlockTable<LeafBlock>, 8> leaves_;
  std::array<std::vector<std::uint64_t>, 8> sync_codes_;
  std::array<std::vector<float>, 8> sync_values_;
};

}  // namespace sonarbench::mapping
