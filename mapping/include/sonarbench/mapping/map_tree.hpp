#pragma once

#include <octomap/OcTree.h>

namespace sonarbench::mapping {

/// OctoMap's OcTree, plus what parallel updates need: OctoMap counts nodes in a plain member
/// that concurrent node creation in disjoint subtrees would race on, so after such updates the
/// count is taken again from the tree itself (the .bt header carries it).
class MapTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;
  void RecountNodes() {
    tree_size = calcNumNodes();
    size_changed = true;
  }
};

}  // namespace sonarbench::mapping
