#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sonarbench/sim/report/view3d.hpp"

namespace sonarbench::sim {
namespace {

std::vector<unsigned char> Unbase64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    if (c == '=') break;
    bits = bits << 6 | static_cast<std::uint32_t>(alphabet.find(c));
    if ((count += 6) >= 8) {
      count -= 8;
      out.push_back(static_cast<unsigned char>(bits >> count));
    }
  }
  return out;
}

std::vector<int> U16s(const std::string& base64) {
  const std::vector<unsigned char> b = Unbase64(base64);
  std::vector<int> out;
  for (std::size_t i = 0; i + 1 < b.size(); i += 2) out.push_back(b[i] | b[i + 1] << 8);
  return out;
}

std::vector<float> F32s(const std::string& base64) {
  const std::vector<unsigned char> b = Unbase64(base64);
  std::vector<float> out(b.size() / 4);
  std::memcpy(out.data(), b.data(), out.size() * 4);
  return out;
}

// The JSON the section hands its script.
nlohmann::json ViewData(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"view3d-data\">";
  const std::size_t from = html.find(open);
  EXPECT_NE(from, std::string::npos);
  const std::size_t to = html.find("</script>", from);
  return nlohmann::json::parse(html.substr(from + open.size(), to - from - open.size()));
}

octomap::OcTreeKey Key(int x, int y, int z) {
  return {static_cast<std::uint16_t>(32768 + x), static_cast<std::uint16_t>(32768 + y),
          static_cast<std::uint16_t>(32768 + z)};
}

// Occupied: one on a surface, one within 2 cells of one, one ghost, one off surface; one
// observable surface cell missed.
struct Fixture {
  MapCells cells;
  SceneScore score;
  Fixture() {
    score.truth = {Key(0, 0, 0), Key(1, 0, 0), Key(5, 5, 5)};
    score.observable = {Key(0, 0, 0), Key(1, 0, 0), Key(2, 2, 2)};
    score.detector_ghosts = {Key(-3, 4, 0)};
    cells.occupied = {Key(0, 0, 0), Key(3, 1, 1), Key(-3, 4, 0), Key(2, -1, 7)};
    cells.free = {Key(9, 9, 9)};
    TriangleMesh wall;
    wall.name = "wall </script><b>";
    wall.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}};
    wall.triangles = {{0, 1, 2}};
    score.surfaces.push_back(wall);
  }
};

TEST(View3dHtml, DrawsEachClassOfCellsAtTheirCentresWithTheSurfacesAndPath) {
  const Fixture f;
  const std::vector<Eigen::Vector3d> path = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}};
  const std::string html = View3dHtml(f.cells, 0.05, &f.score, path);
  if (View3dThreeVersion().empty()) {
    EXPECT_NE(html.find("No 3D view"), std::string::npos);
    EXPECT_EQ(html.find("<script"), std::string::npos);
    GTEST_SKIP() << "this build embeds no three.js: its page says so (checked)";
  }
  for (const char* id : {"three-core", "three-module", "three-orbit-controls"}) {
    EXPECT_NE(html.find(std::string("id=\"") + id + "\">"), std::string::npos) << id;
  }
  const nlohmann::json data = ViewData(html);
  EXPECT_DOUBLE_EQ(data["resolution_m"], 0.05);
  // The lowest key of the drawn cells, (-3, -1, 0), at its centre.
  const std::vector<double> origin = data["origin_m"];
  EXPECT_NEAR(origin[0], -2.5 * 0.05, 1e-12);
  EXPECT_NEAR(origin[1], -0.5 * 0.05, 1e-12);
  EXPECT_NEAR(origin[2], 0.5 * 0.05, 1e-12);
  const std::vector<std::pair<std::string, std::vector<int>>> expected = {
      {"occupied, on a surface", {3, 1, 0}},
      {"occupied, within 2 cells of a surface", {6, 2, 1}},
      {"occupied, the detector's ghost", {0, 5, 0}},
      {"occupied, off surface (a ghost on an echo's arc)", {5, 0, 7}},
      {"observable surface missed", {4, 1, 0}}};
  ASSERT_EQ(data["classes"].size(), expected.size());
  for (std::size_t c = 0; c < expected.size(); ++c) {
    const nlohmann::json& cls = data["classes"][c];
    EXPECT_EQ(cls["name"], expected[c].first);
    EXPECT_EQ(cls["count"], 1);
    EXPECT_EQ(cls["drawn"], 1);
    EXPECT_EQ(U16s(cls["cells"]), expected[c].second) << expected[c].first;
  }
  EXPECT_EQ(data["classes"][4]["size"], 0.5);
  ASSERT_EQ(data["surfaces"].size(), 1u);
  EXPECT_EQ(data["surfaces"][0]["name"], "wall </script><b>");
  EXPECT_EQ(F32s(data["surfaces"][0]["positions"]),
            (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0.5f}));
  EXPECT_EQ(F32s(data["sonar_path"]), (std::vector<float>{0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f}));
  // A name cannot end the data's <script> early.
  EXPECT_EQ(html.find("</script><b>"), std::string::npos);
}

TEST(View3dHtml, TheSameCellsGiveTheSameBytesWhateverTheirOrder) {
  Fixture a;
  Fixture b;
  b.cells.occupied.clear();
  for (const octomap::OcTreeKey& k : {Key(2, -1, 7), Key(3, 1, 1), Key(0, 0, 0), Key(-3, 4, 0)}) {
    b.cells.occupied.insert(k);
  }
  EXPECT_EQ(View3dHtml(a.cells, 0.05, &a.score, {}), View3dHtml(b.cells, 0.05, &b.score, {}));
}

TEST(View3dHtml, AMapWithoutAScoreIsOneClassAndAHugeOneIsThinnedEvenly) {
  if (View3dThreeVersion().empty()) GTEST_SKIP() << "this build embeds no three.js";
  MapCells cells;
  // 400 010 cells: over the 400 000 the view draws, so every second one is drawn.
  for (int z = 0; z < 10; ++z) {
    for (int y = 0; y < 200; ++y) {
      for (int x = 0; x < 200; ++x) cells.occupied.insert(Key(x, y, z));
    }
  }
  for (int i = 0; i < 10; ++i) cells.occupied.insert(Key(i, 0, 10));
  const nlohmann::json data = ViewData(View3dHtml(cells, 0.1, nullptr, {}));
  ASSERT_EQ(data["classes"].size(), 1u);
  EXPECT_EQ(data["classes"][0]["name"], "occupied");
  EXPECT_EQ(data["classes"][0]["count"], 400010);
  EXPECT_EQ(data["classes"][0]["drawn"], 200005);
  const std::vector<int> keys = U16s(data["classes"][0]["cells"]);
  ASSERT_EQ(keys.size(), 3u * 200005);
  EXPECT_EQ((std::vector<int>(keys.begin(), keys.begin() + 6)),
            (std::vector<int>{0, 0, 0, 2, 0, 0}));
  EXPECT_TRUE(data["surfaces"].empty());
}

}  // namespace
}  // namespace sonarbench::sim
