// BeamSynthesizer's labels: each bin's power split by the path it came by (BinLabel).

#include <algorithm>
#include <cmath>
#include <limits>

#include "beam_job.hpp"

namespace sonarbench::sim {

namespace {

// The paths of the scene's echoes as the rays deposit them, before their share of the rays'
// weights (BeamJob::weight_sum_).
constexpr std::array<EchoPath, 3> kScenePaths = {EchoPath::kDirect, EchoPath::kSidelobe,
                                                 EchoPath::kMultipath};

}  // namespace

void BeamSynthesizer::BeamJob::StartLabels() {
  labels_ = true;
  LabelScratch& l = scratch_.labels;
  for (PulseSpreader& spreader : l.spreaders) {
    if (spreader.Bins() != bins_) spreader.Reset(bins_);
  }
  for (std::vector<double>& power : l.power) power.assign(bins_, 0.0);
  l.slot_of_mesh.assign(s_.vehicle_first_mesh_, -1);
  l.mesh_of_slot.clear();
}

std::int32_t LabelScratch::NewSlot(std::uint32_t mesh) {
  const std::size_t slot = mesh_of_slot.size();
  mesh_of_slot.push_back(mesh);
  if (meshes.size() == slot) meshes.emplace_back();
  MeshDirect& m = meshes[slot];
  const std::size_t bins = spreaders[0].Bins();  // the beam's (StartLabels)
  if (m.spreader.Bins() != bins) m.spreader.Reset(bins);
  m.strongest.assign(bins, 0.0);
  m.point.resize(bins);
  slot_of_mesh[mesh] = static_cast<std::int32_t>(slot);
  return static_cast<std::int32_t>(slot);
}

void BeamSynthesizer::BeamJob::LabelScenePaths() {
  LabelScratch& l = scratch_.labels;
  std::vector<double>& direct = LabelPower(EchoPath::kDirect);
  for (std::size_t slot = 0; slot < l.mesh_of_slot.size(); ++slot) {
    MeshDirect& m = l.meshes[slot];
    m.power.assign(bins_, 0.0);
    m.spreader.AddTo(m.power);
    for (std::size_t k = 0; k < bins_; ++k) direct[k] += m.power[k];
  }
  l.spreaders[0].AddTo(LabelPower(EchoPath::kSidelobe));
  l.spreaders[1].AddTo(LabelPower(EchoPath::kMultipath));
  // Their skirts here, their share of the rays' weights in FinishLabels (both linear).
  for (const EchoPath path : kScenePaths) {
    std::vector<double>& power = LabelPower(path);
    if (std::any_of(power.begin(), power.end(), [](double p) { return p != 0.0; })) {
      AddPulseSkirts(s_.sensor_, power);
    }
  }
}

void BeamSynthesizer::BeamJob::LabelAdded(EchoPath path) {
  std::vector<double>& power = LabelPower(path);
  const std::vector<double>& before = scratch_.labels.before;
  const std::vector<double>& echo = scratch_.echo_power;
  for (std::size_t k = 0; k < bins_; ++k) power[k] = echo[k] - before[k];
}

void BeamSynthesizer::BeamJob::FinishLabels(std::span<const double> self_reflection) {
  LabelScratch& l = scratch_.labels;
  std::vector<BinLabel>& labels = out_.labels;
  labels.resize(bins_);
  const double gain = std::pow(10.0, a_.gain.gain_db / 10.0);
  // Each path's factor: the gain (and the rays' weight share for the scene's rays' paths), the
  // speckle per bin after; the noise as drawn.
  std::array<double, kEchoPaths> scale{};
  for (std::size_t p = 0; p < kEchoPaths; ++p) {
    const auto path = static_cast<EchoPath>(p);
    const bool rays = std::find(kScenePaths.begin(), kScenePaths.end(), path) != kScenePaths.end();
    scale[p] = rays ? gain / weight_sum_ : gain;
  }
  constexpr auto kNoise = static_cast<std::size_t>(EchoPath::kNoise);
  constexpr auto kVehicle = static_cast<std::size_t>(EchoPath::kVehicle);
  for (std::size_t k = 0; k < bins_; ++k) {
    const double speckle = a_.speckle.on ? scratch_.speckle[k] : 1.0;
    BinLabel& label = labels[k];
    for (std::size_t p = 0; p < kEchoPaths; ++p) {
      label.energy[p] = static_cast<float>(l.power[p][k] * scale[p] * speckle);
    }
    label.energy[kNoise] = static_cast<float>(l.power[kNoise][k]);
    if (k < self_reflection.size()) {
      label.energy[kVehicle] =
          static_cast<float>(l.power[kVehicle][k] * gain * speckle + self_reflection[k]);
    }
    label.mesh = kNoMesh;
    label.point_sonar_m = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  }
  LabelMeshes();
}

// Each bin's mesh: the one with the most main-lobe direct power in it; its point: that mesh's
// strongest return starting from a pulse length (whole bins) before the bin to the bin's end.
void BeamSynthesizer::BeamJob::LabelMeshes() {
  const LabelScratch& l = scratch_.labels;
  const std::size_t slots = l.mesh_of_slot.size();
  if (slots == 0) return;
  const auto window = static_cast<std::size_t>(std::ceil(a_.pulse.length_m / g_.bin_size_m - 1e-9));
  const Eigen::Matrix3f R_sonar_world = T_world_sonar_.linear().transpose().cast<float>();
  std::vector<BinLabel>& labels = out_.labels;
  for (std::size_t k = 0; k < bins_; ++k) {
    std::size_t best = slots;
    double most = 0.0;
    for (std::size_t slot = 0; slot < slots; ++slot) {
      if (l.meshes[slot].power[k] > most) {
        most = l.meshes[slot].power[k];
        best = slot;
      }
    }
    if (best == slots) continue;
    const MeshDirect& m = l.meshes[best];
    std::size_t from = k >= window ? k - window : 0;
    for (std::size_t j = from + 1; j <= k; ++j) {
      if (m.strongest[j] > m.strongest[from]) from = j;
    }
    if (!(m.strongest[from] > 0.0)) continue;  // a rounding residue past the pulse's end
    labels[k].mesh = l.mesh_of_slot[best];
    labels[k].point_sonar_m = R_sonar_world * m.point[from];
  }
}

}  // namespace sonarbench::sim
