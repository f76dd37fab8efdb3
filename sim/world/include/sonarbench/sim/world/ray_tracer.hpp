#pragma once

#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {

/// The first surface along a ray.
struct Hit {
  /// Distance from the ray origin [m].
  float distance = 0.0f;
  /// Unit geometric normal of the triangle hit (either side).
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  /// Index of the mesh hit, in the order the meshes were given.
  std::uint32_t mesh = 0;
};

/// A ray segment: from `origin` along `direction` (unit) for up to `max_distance` [m].
struct Ray {
  Eigen::Vector3f origin;
  Eigen::Vector3f direction;
  float max_distance = 0.0f;
};

/// The queries a RayTracer answered while recording (RayTracer::Record), in order, each with
/// its rays: for replaying the same rays through Embree alone (synthesis_bench).
struct RayQueryLog {
  /// Which of RayTracer's queries an entry was: IntersectBundle, IntersectStream, OccludedStream,
  /// Intersect or Occluded.
  enum class Query { kBundle, kStream, kOccludedStream, kSingle, kSingleOccluded };
  struct Entry {
    Query query = Query::kSingle;
    std::vector<Ray> rays;
  };
  std::vector<Entry> entries;

  /// Rays over all entries.
  [[nodiscard]] std::size_t RayCount() const;
};

/// An Embree scene over a set of triangle meshes. Thread-safe for queries once constructed,
/// except while recording them.
class RayTracer {
 public:
  explicit RayTracer(std::span<const TriangleMesh> meshes);

  /// Distance [m] from `point` to the nearest triangle of any mesh, if one lies within
  /// `max_distance` (Embree's BVH point query; exact point-triangle distances).
  [[nodiscard]] std::optional<double> NearestSurfaceDistance(const Eigen::Vector3d& point,
                                                             double max_distance) const;

  /// The first hit along `direction` (unit) from `origin` within `max_distance` [m].
  [[nodiscard]] std::optional<Hit> Intersect(const Eigen::Vector3f& origin,
                                             const Eigen::Vector3f& direction,
                                             float max_distance) const;

  /// The first hits of a bundle of rays from one `origin`, traced together as one coherent
  /// stream (Embree's rtcIntersect1M, which packs neighbouring rays into SIMD packets):
  /// `hits[i]` is ray i's hit along `directions[i]` (unit) within `max_distance` [m], or
  /// nothing. The same hits as Intersect() ray by ray, to within Embree's float rounding.
  void IntersectBundle(const Eigen::Vector3f& origin, std::span<const Eigen::Vector3f> directions,
                       float max_distance, std::span<std::optional<Hit>> hits) const;

  /// The first hits of rays from anywhere in any direction (the mirrored rays of one bounce of
  /// a beam's multipath), traced as one incoherent stream (rtcIntersect1M): `hits[i]` is
  /// `rays[i]`'s, as Intersect() would find it.
  void IntersectStream(std::span<const Ray> rays, std::span<std::optional<Hit>> hits) const;

  /// Whether any surface lies along each of `rays` (rtcOccluded1M, one incoherent stream):
  /// `occluded[i]` is Occluded() of `rays[i]`.
  void OccludedStream(std::span<const Ray> rays, std::vector<bool>& occluded) const;

  /// Whether any surface lies along `direction` (unit) from `origin` within `max_distance` [m].
  [[nodiscard]] bool Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                              float max_distance) const;

  /// Appends every query answered from now on to `log` (nullptr stops recording). While it
  /// records, the tracer must be queried from one thread only.
  void Record(RayQueryLog* log) const { log_ = log; }

 private:
  /// Appends a query to log_, if recording.
  void Log(RayQueryLog::Query query, std::vector<Ray> rays) const;

  struct DeviceDeleter {
    void operator()(RTCDeviceTy* device) const { rtcReleaseDevice(device); }
  };
  struct SceneDeleter {
    void operator()(RTCSceneTy* scene) const { rtcReleaseScene(scene); }
  };
  std::unique_ptr<RTCDeviceTy, DeviceDeleter> device_;
  std::unique_ptr<RTCSceneTy, SceneDeleter> scene_;
  mutable RayQueryLog* log_ = nullptr;
};

}  // namespace sonarbench::sim
