#include <sstream>
#include <string>

#include "bindings.hpp"
#include "sonarbench/sim/app/score_map.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"

namespace sonarbench::python {
namespace {

py::object ToPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// The mapper's map as `sonarbench map` writes it to map.bt, read back: what `score` would read.
std::unique_ptr<octomap::OcTree> BinaryCopy(const mapping::Mapper& mapper,
                                            io::OcTreeFileInfo& info) {
  std::stringstream bytes;
  mapping::WriteOctomapBinary(mapper.tree(), bytes);
  auto tree = std::make_unique<octomap::OcTree>(mapper.config().resolution_m);
  // Past the header's lines to the data, as io::ReadOcTreeFile reads it (readBinary would print).
  for (std::string line; std::getline(bytes, line) && line != "data";) {
  }
  tree->readBinaryData(bytes);
  info.format = "bt";
  info.tree_type = "OcTree";
  info.resolution_m = tree->getResolution();
  info.nodes = tree->size();
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    info.leaf_cells += std::ldexp(1.0, 3 * (16 - static_cast<int>(it.getDepth())));
  }
  return tree;
}

py::dict Score(const PyScene& scene, const py::object& map) {
  const sim::Scene& s = *scene.scene;
  sim::MapFileScore score;
  if (IsMapper(map)) {
    const mapping::Mapper& mapper = MapperOf(map);
    const py::gil_scoped_release release;
    io::OcTreeFileInfo info;
    std::unique_ptr<octomap::OcTree> tree = BinaryCopy(mapper, info);
    score = sim::ScoreMapTree(std::move(tree), "the Mapper's map", info, s, s.budgets);
  } else {
    const std::string path = PathArg(map);
    const py::gil_scoped_release release;
    score = sim::ScoreMapFile(path, s, s.budgets);
  }
  py::dict out;
  out["metrics"] = ToPython(sim::MetricsJson(score.score.metrics));
  out["verdict"] = ToPython(sim::VerdictJson(score.score.verdict));
  out["criteria"] = ToPython(sim::CriteriaJson(score.score.verdict));
  out["occupied_in_reach"] = score.occupied_in_reach;
  return out;
}

}  // namespace

void BindScore(py::module_& m) {
  m.def("score", &Score, py::arg("scene"), py::arg("map"),
        "Scores a Mapper's map, or an OctoMap file (.bt or .ot), against `scene` as "
        "`sonarbench score` does: a dict of its report.json's 'metrics', 'verdict' and "
        "'criteria', and the share of occupied cells within the sonar's reach. Raises "
        "InputError for a map in another frame or over the scene's budgets. Releases the GIL.");
}

}  // namespace sonarbench::python
