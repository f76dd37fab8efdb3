// BeamSynthesizer's labels: each bin's power split by the path it came by (BinLabel).

#include <algorithm>
#include <cmath>

#include "beam_job.hpp"

namespace sonarbench::sim {

namespace {

// The spreaders' paths, in LabelScratch::spreaders' order.
constexpr std::array<EchoPath, 3> kSpreaderPaths = {EchoPath::kDirect, EchoPath::kSidelobe,
                                                    EchoPath::kMultipath};

}  // namespace

void BeamSynthesizer::BeamJob::StartLabels() {
  labels_ = true;
  LabelScratch& l = scratch_.labels;
  for (PulseSpreader& spreader : l.spreaders) {
    if (spreader.Bins() != bins_) spreader.Reset(bins_);
  }
  for (std::vector<double>& power : l.power) power.assign(bins_, 0.0);
  l.direct_returns.clear();
}

void BeamSynthesizer::BeamJob::LabelScenePaths() {
  LabelScratch& l = scratch_.labels;
  for (std::size_t i = 0; i < kSpreaderPaths.size(); ++i) {
    std::vector<double>& power = LabelPower(kSpreaderPaths[i]);
    l.spreaders[i].AddTo(power);
    for (double& p : power) p /= weight_sum_;
    AddPulseSkirts(s_.sensor_, power);
  }
}

void BeamSynthesizer::BeamJob::LabelAdded(EchoPath path) {
  std::vector<double>& power = LabelPower(path);
  const std::vector<double>& before = scratch_.labels.before;
  const std::vector<double>& echo = scratch_.echo_power;
  for (std::size_t k = 0; k < bins_; ++k) power[k] += echo[k] - before[k];
}

void BeamSynthesizer::BeamJob::FinishLabels(std::span<const double> self_reflection) {
  LabelScratch& l = scratch_.labels;
  std::vector<BinLabel>& labels = out_.labels;
  labels.assign(bins_, BinLabel{});
  const double gain = std::pow(10.0, a_.gain.gain_db / 10.0);
  for (std::size_t k = 0; k < bins_; ++k) {
    const double factor = a_.speckle.on ? gain * scratch_.speckle[k] : gain;
    const double self = k < self_reflection.size() ? self_reflection[k] : 0.0;
    for (std::size_t p = 0; p < kEchoPaths; ++p) {
      const auto path = static_cast<EchoPath>(p);
      const double power = path == EchoPath::kNoise ? l.power[p][k] : l.power[p][k] * factor;
      labels[k].energy[p] = static_cast<float>(path == EchoPath::kVehicle ? power + self : power);
    }
  }
  // Each bin's direct power by mesh, from the returns whose pulse covers it, and each mesh's
  // strongest there, in one pass; the bin's mesh the one with the most, its point that mesh's
  // strongest return's.
  const std::size_t meshes = s_.vehicle_first_mesh_;
  if (meshes == 0) return;
  l.mesh_power.assign(bins_ * meshes, 0.0);
  l.mesh_strongest.assign(bins_ * meshes, 0.0);
  l.strongest.resize(bins_ * meshes);
  const double bins_per_m = 1.0 / g_.bin_size_m;
  const double pulse_bins = a_.pulse.length_m * bins_per_m;
  for (std::size_t i = 0; i < l.direct_returns.size(); ++i) {
    const DirectReturn& r = l.direct_returns[i];
    const double start = r.range * bins_per_m;
    const double end = start + pulse_bins;
    const auto last = std::min(bins_, static_cast<std::size_t>(std::ceil(end)));
    for (auto k = static_cast<std::size_t>(start); k < last; ++k) {
      const double covered =
          std::min(end, static_cast<double>(k + 1)) - std::max(start, static_cast<double>(k));
      const double power = r.power * covered;
      const std::size_t at = k * meshes + r.mesh;
      l.mesh_power[at] += power;
      if (power > l.mesh_strongest[at]) {
        l.mesh_strongest[at] = power;
        l.strongest[at] = i;
      }
    }
  }
  const Eigen::Matrix3f R_sonar_world = T_world_sonar_.linear().transpose().cast<float>();
  for (std::size_t k = 0; k < bins_; ++k) {
    const auto first = l.mesh_power.begin() + static_cast<std::ptrdiff_t>(k * meshes);
    const auto most = std::max_element(first, first + static_cast<std::ptrdiff_t>(meshes));
    if (!(*most > 0.0)) continue;
    const auto mesh = static_cast<std::size_t>(most - first);
    labels[k].mesh = static_cast<std::uint32_t>(mesh);
    const DirectReturn& r = l.direct_returns[l.strongest[k * meshes + mesh]];
    labels[k].point_sonar_m = static_cast<float>(r.range) * (R_sonar_world * r.direction);
  }
}

}  // namespace sonarbench::sim
