#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/octomap_file.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

constexpr double kNoBudget = 1e12;

// A tree with occupied and free cells at several places and a block of 8 occupied siblings that
// prunes to one node a level up.
octomap::OcTree SampleTree() {
  octomap::OcTree tree(0.05);
  for (int i = 0; i < 40; ++i) {
    tree.updateNode(octomap::point3d(0.05F * static_cast<float>(i), 0.3F, -0.2F), true);
    tree.updateNode(octomap::point3d(-0.05F * static_cast<float>(i), 1.1F, 0.4F), false);
  }
  const octomap::OcTreeKey corner = tree.coordToKey(1.0, 1.0, 1.0);
  for (int c = 0; c < 8; ++c) {
    octomap::OcTreeKey key(corner[0] & ~1, corner[1] & ~1, corner[2] & ~1);
    key[0] += c & 1;
    key[1] += (c >> 1) & 1;
    key[2] += (c >> 2) & 1;
    tree.updateNode(key, tree.getClampingThresMaxLog(), true);
  }
  tree.updateInnerOccupancy();
  tree.toMaxLikelihood();
  tree.prune();
  return tree;
}

// Every leaf: key, depth, occupied.
std::vector<std::tuple<std::size_t, unsigned, bool>> Leaves(const octomap::OcTree& tree) {
  std::vector<std::tuple<std::size_t, unsigned, bool>> out;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    out.emplace_back(octomap::OcTreeKey::KeyHash{}(it.getKey()), it.getDepth(),
                     tree.isNodeOccupied(*it));
  }
  return out;
}

std::string BinaryBytes(const octomap::OcTree& tree) {
  std::ostringstream out;
  tree.writeBinaryConst(out);
  return out.str();
}

std::string FullBytes(const octomap::OcTree& tree) {
  std::ostringstream out;
  tree.write(out);
  return out.str();
}

// A .bt file of `size` nodes whose data is `data`.
std::string BinaryFile(const std::string& size, const std::string& data,
                       const std::string& id = "OcTree", const std::string& res = "0.05") {
  return std::string(mapping::kOctomapBinaryHeader) + "\n# comment\nid " + id + "\nsize " + size +
         "\nres " + res + "\ndata\n" + data;
}

// The message of the InputError reading `bytes` as a file throws; "" if none.
std::string ErrorReading(const std::string& bytes, double max_cells = kNoBudget) {
  test::TempDir dir;
  const std::string path = test::WriteFile(dir, "map.bt", bytes);
  try {
    (void)io::ReadOcTreeFile(path, max_cells);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    return message;
  }
  return "";
}

TEST(OcTreeFile, BothFormatsReadBackTheTreeOctomapWrote) {
  const octomap::OcTree tree = SampleTree();
  double cells = 0.0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    cells += std::ldexp(1.0, 3 * (16 - static_cast<int>(it.getDepth())));
  }
  EXPECT_GT(cells, static_cast<double>(tree.getNumLeafNodes()));  // a pruned block is in it
  for (const auto& [format, bytes] :
       {std::pair{"bt", BinaryBytes(tree)}, std::pair{"ot", FullBytes(tree)}}) {
    test::TempDir dir;
    const std::string path = test::WriteFile(dir, std::string("map.") + format, bytes);
    io::OcTreeFileInfo info;
    const auto read = io::ReadOcTreeFile(path, kNoBudget, &info);
    EXPECT_EQ(info.format, format);
    EXPECT_EQ(info.tree_type, "OcTree");
    EXPECT_DOUBLE_EQ(info.resolution_m, 0.05);
    EXPECT_EQ(info.nodes, tree.size());
    EXPECT_EQ(info.leaf_cells, cells);
    EXPECT_EQ(Leaves(*read), Leaves(tree)) << format;
    // The budget counts nodes and leaf cells: one less than the file holds is refused.
    EXPECT_NE(ErrorReading(bytes, cells - 1).find("--max-cells"), std::string::npos);
  }
}

TEST(OcTreeFile, TheFuzzSeedsHoldTheSameTreeInBothFormats) {
  for (const std::string name : {"wall", "one_cell"}) {
    const std::string seed = test::SourcePath("fuzz/corpus/octomap/" + name);
    io::OcTreeFileInfo bt;
    io::OcTreeFileInfo ot;
    const auto binary = io::ReadOcTreeFile(seed + ".bt", kNoBudget, &bt);
    const auto full = io::ReadOcTreeFile(seed + ".ot", kNoBudget, &ot);
    EXPECT_EQ(Leaves(*binary), Leaves(*full)) << name;
    EXPECT_EQ(bt.nodes, ot.nodes);
    EXPECT_GT(bt.leaf_cells, 0.0);
  }
}

TEST(OcTreeFile, AnEmptyTreeReadsAsEmpty) {
  EXPECT_EQ(ErrorReading(BinaryFile("0", "")), "");
  EXPECT_NE(ErrorReading(BinaryFile("0", "x")).find("bytes follow"), std::string::npos);
}

TEST(OcTreeFile, BadFilesAreClearErrors) {
  const std::string good = BinaryBytes(SampleTree());
  const std::string size = std::to_string(SampleTree().size());
  const std::string data = good.substr(good.find("data\n") + 5);
  // A root whose child 0 is inner, 17 levels down: one level past OctoMap's finest.
  std::string deep;
  for (int level = 0; level < 17; ++level) deep += std::string("\x03\x00", 2);
  // A float NaN as a .ot node's log-odds.
  std::string nan_node(5, '\0');
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_node.data(), &nan, sizeof nan);
  const std::string full_header =
      std::string(mapping::kOctomapFullHeader) + "\nid OcTree\nsize 1\nres 0.05\ndata\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"# Octomap something else\n", "first line"},
      {"", "empty"},
      {BinaryFile(size, data, "ColorOcTree"), "ColorOcTree"},
      {BinaryFile(size, data, "OcTree", "0"), "'res'"},
      {BinaryFile(size, data, "OcTree", "nan"), "'res'"},
      {BinaryFile(size, data, "OcTree", "0.05m"), "'res'"},
      {BinaryFile("-3", data), "'size'"},
      {BinaryFile(std::to_string(SampleTree().size() + 1), data), "'size'"},
      {BinaryFile(size, data.substr(0, data.size() - 1)), "truncated"},
      {BinaryFile(size, data + "\n"), "bytes follow"},
      {std::string(mapping::kOctomapBinaryHeader) + "\nid OcTree\nsize 1\n", "'data'"},
      {std::string(mapping::kOctomapBinaryHeader) + "\nid OcTree\ncolour blue\ndata\n", "line 3"},
      {std::string(mapping::kOctomapBinaryHeader) + "\nid OcTree\nsize 1\ndata\n", "'res'"},
      {BinaryFile("18", deep), "level 16"},
      {BinaryFile("2", std::string("\x03\x00\x00\x00", 4)), "has none"},
      {BinaryFile("1", std::string("\x00\x00", 2)), "--max-cells"},  // a root leaf: 8^16 cells
      {full_header + nan_node, "finite"},
  };
  for (const auto& [bytes, expected] : cases) {
    const std::string message = ErrorReading(bytes, 1e8);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "' in: " << message;
  }
}

}  // namespace
}  // namespace sonarbench
