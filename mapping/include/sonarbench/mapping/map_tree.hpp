#pragma once

#include <octomap/OcTree.h>

#include <bit>
#include <cstdint>

namespace sonarbench::mapping {

/// OctoMap's OcTree, plus what parallel updates need.
class MapTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  /// OctoMap counts nodes in a plain member that concurrent node creation in disjoint subtrees
  /// races on, so after such updates the count is taken again from the tree itself (the .bt
  /// header carries it).
  void RecountNodes() {
    tree_size = calcNumNodes();
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
    constexpr unsigned kDepth = 16;
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
          ++tree_size;
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
            expandNode(node);  // a pruned node
          } else {
            createNodeChild(node, pos);
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
  }
};

}  // namespace sonarbench::mapping
