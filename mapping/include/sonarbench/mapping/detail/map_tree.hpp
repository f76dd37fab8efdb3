#pragma once

#include <octomap/OcTree.h>

#include <bit>
#include <cstddef>
#include <cstdint>

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

/// OctoMap's OcTree, plus what parallel updates need.
class MapTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  /// Adds `created` nodes to OctoMap's count (the .bt header carries it), after updates that
  /// left the count to the caller (UpdateLeavesUncounted in parallel).
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
    AddNodes(UpdateLeavesUncounted(count, key, log_odds));
  }

  /// UpdateLeavesInOrder, but the nodes it creates are returned, not counted in the tree: threads
  /// may update disjoint subtrees (below existing nodes) at once, then AddNodes their sum.
  template <typename Key, typename LogOdds>
  [[nodiscard]] std::size_t UpdateLeavesUncounted(std::size_t count, Key&& key,
                                                  LogOdds&& log_odds) {
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
      updateNodeLogOdds(path[kDepth], log_odds(i));
      previous = k;
    }
    return nodes;
  }
};

}  // namespace sonarbench::mapping
