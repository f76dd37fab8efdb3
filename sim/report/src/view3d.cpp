#include "sonarbench/sim/report/view3d.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>
#include <vector>

#include "sonarbench/sim/report/scenario_report.hpp"
#include "view3d_assets.hpp"

namespace sonarbench::sim {
namespace {

// Cells and triangles the view draws at most: a map with more is thinned evenly (the legend
// says how many are drawn); meshes past the triangle limit are left out, by name.
constexpr std::size_t kMaxCells = 400000;
constexpr std::size_t kMaxTriangles = 400000;

std::string Joined(const char* const* chunks) {
  std::string text;
  for (; *chunks != nullptr; ++chunks) text += *chunks;
  return text;
}

// Little-endian bytes, as the page's typed arrays read them.
void Put(std::vector<unsigned char>& bytes, std::uint32_t value, int size) {
  for (int i = 0; i < size; ++i) bytes.push_back(static_cast<unsigned char>(value >> (8 * i)));
}
void PutFloat(std::vector<unsigned char>& bytes, float value) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  Put(bytes, bits, 4);
}

struct CellClass {
  std::string name;
  std::string colour;  // "#rrggbb", map_top.png's
  double size = 1.0;   // the cube's edge in cells
  std::vector<octomap::OcTreeKey> keys;
};

bool KeyLess(const octomap::OcTreeKey& a, const octomap::OcTreeKey& b) {
  return std::tie(a[2], a[1], a[0]) < std::tie(b[2], b[1], b[0]);
}

// The occupied cells by class against the score (all one class without it): map_top.png's, with
// its "off surface" split at the ghosts' 2 cells; then the observable surface cells the map
// missed. Each sorted, so the page's bytes do not follow hash order.
std::vector<CellClass> Classify(const MapCells& cells, const SceneScore* score) {
  std::vector<CellClass> classes;
  if (!score) {
    classes.push_back({"occupied", "#ffffff", 1.0, {cells.occupied.begin(), cells.occupied.end()}});
  } else {
    classes = {{"occupied, on a surface", "#00d200", 1.0, {}},
               {"occupied, within 2 cells of a surface", "#00a078", 1.0, {}},
               {"occupied, the detector's ghost", "#e600e6", 1.0, {}},
               {"occupied, off surface (a ghost on an echo's arc)", "#e60000", 1.0, {}},
               {"observable surface missed", "#0078ff", 0.5, {}}};
    for (const octomap::OcTreeKey& k : cells.occupied) {
      const int c = score->truth.contains(k)             ? 0
                    : score->detector_ghosts.contains(k) ? 2
                    : AnyWithin(score->truth, k, 2)      ? 1
                                                         : 3;
      classes[static_cast<std::size_t>(c)].keys.push_back(k);
    }
    for (const octomap::OcTreeKey& k : score->observable) {
      if (score->truth.contains(k) && !cells.occupied.contains(k)) classes[4].keys.push_back(k);
    }
  }
  for (CellClass& c : classes) std::sort(c.keys.begin(), c.keys.end(), KeyLess);
  return classes;
}

// The classes' cells as [u16 x, y, z] relative to the lowest key, every `stride`-th drawn.
nlohmann::json CellsJson(const std::vector<CellClass>& classes, double resolution_m) {
  std::size_t total = 0;
  octomap::OcTreeKey lo(0xffff, 0xffff, 0xffff);
  for (const CellClass& c : classes) {
    total += c.keys.size();
    for (const octomap::OcTreeKey& k : c.keys) {
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], k[a]);
    }
  }
  if (total == 0) lo = octomap::OcTreeKey(32768, 32768, 32768);
  const std::size_t stride = (total + kMaxCells - 1) / kMaxCells;
  nlohmann::json json = nlohmann::json::array();
  for (const CellClass& c : classes) {
    std::vector<unsigned char> bytes;
    std::size_t drawn = 0;
    for (std::size_t i = 0; i < c.keys.size(); i += std::max<std::size_t>(stride, 1), ++drawn) {
      for (int a = 0; a < 3; ++a) Put(bytes, static_cast<std::uint32_t>(c.keys[i][a] - lo[a]), 2);
    }
    json.push_back({{"name", c.name},
                    {"colour", c.colour},
                    {"size", c.size},
                    {"count", c.keys.size()},
                    {"drawn", drawn},
                    {"cells", Base64(bytes)}});
  }
  const auto centre = [&](int a) { return (static_cast<int>(lo[a]) - 32768 + 0.5) * resolution_m; };
  return {{"resolution_m", resolution_m},
          {"origin_m", {centre(0), centre(1), centre(2)}},
          {"classes", json}};
}

// The truth's meshes as f32 positions and u32 triangles, up to kMaxTriangles in all.
nlohmann::json SurfacesJson(const SceneScore* score, nlohmann::json& omitted) {
  nlohmann::json json = nlohmann::json::array();
  if (!score) return json;
  std::size_t triangles = 0;
  for (const TriangleMesh& mesh : score->surfaces) {
    triangles += mesh.triangles.size();
    if (triangles > kMaxTriangles) {
      omitted.push_back(mesh.name);
      continue;
    }
    std::vector<unsigned char> positions, indices;
    for (const Eigen::Vector3f& v : mesh.vertices) {
      for (int a = 0; a < 3; ++a) PutFloat(positions, v[a]);
    }
    for (const auto& t : mesh.triangles) {
      for (const std::uint32_t i : t) Put(indices, i, 4);
    }
    json.push_back(
        {{"name", mesh.name}, {"positions", Base64(positions)}, {"triangles", Base64(indices)}});
  }
  return json;
}

// JSON to sit inside <script>: "</" cannot end the element when written "<\/".
std::string ScriptSafe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    out += json[i];
    if (json[i] == '<' && i + 1 < json.size() && json[i + 1] == '/') out += '\\';
  }
  return out;
}

}  // namespace

std::string_view View3dThreeVersion() { return view3d_assets::kThreeVersion; }

std::string View3dHtml(const MapCells& cells, double resolution_m, const SceneScore* score,
                       std::span<const Eigen::Vector3d> sonar_path_m) {
  std::ostringstream html;
  html << "<h2>3D view</h2>\n";
  if (View3dThreeVersion().empty()) {
    html << "<p class=\"view3d-status\">No 3D view: this build of sonarbench has no three.js to "
            "embed (<code>bash ci/install-three.sh</code> fetches it; then build again). The "
            "images below show the map.</p>\n";
    return html.str();
  }
  nlohmann::json data = CellsJson(Classify(cells, score), resolution_m);
  nlohmann::json omitted = nlohmann::json::array();
  data["surfaces"] = SurfacesJson(score, omitted);
  data["surfaces_omitted"] = omitted;
  std::vector<unsigned char> path;
  for (const Eigen::Vector3d& p : sonar_path_m) {
    for (int a = 0; a < 3; ++a) PutFloat(path, static_cast<float>(p[a]));
  }
  data["sonar_path"] = Base64(path);
  html << "<p>The map in three dimensions, world frame, z up: drag to orbit, right-drag (or "
          "shift-drag) to pan, the wheel to zoom; a box in the legend shows or hides its class. "
          "The grid's squares are 1 m; the sonar's path in yellow, a sphere where it starts. "
          "three.js "
       << View3dThreeVersion() << " (MIT licence) is embedded: the page opens offline.</p>\n"
       << "<div id=\"view3d\" class=\"view3d\"><canvas></canvas>"
          "<div class=\"view3d-legend\"></div></div>\n"
       << "<p class=\"view3d-status\">The 3D view needs JavaScript and WebGL.</p>\n"
       << "<script type=\"application/json\" id=\"view3d-data\">" << ScriptSafe(data.dump())
       << "</script>\n"
       << "<script type=\"text/plain\" id=\"three-core\">" << Joined(view3d_assets::kThreeCore)
       << "</script>\n"
       << "<script type=\"text/plain\" id=\"three-module\">" << Joined(view3d_assets::kThreeModule)
       << "</script>\n"
       << "<script type=\"text/plain\" id=\"three-orbit-controls\">"
       << Joined(view3d_assets::kOrbitControls) << "</script>\n"
       << "<script type=\"module\">\n"
       << Joined(view3d_assets::kViewer) << "</script>\n";
  return html.str();
}

}  // namespace sonarbench::sim
