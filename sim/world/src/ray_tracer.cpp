#include "sonarbench/sim/world/ray_tracer.hpp"

#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sonarbench/sim/world/geometry.hpp"

namespace sonarbench::sim {

RayTracer::RayTracer(std::span<const TriangleMesh> meshes) : device_(rtcNewDevice(nullptr)) {
  if (!device_) {
    throw std::runtime_error("Embree: cannot create a device (error " +
                             std::to_string(rtcGetDeviceError(nullptr)) + ")");
  }
  scene_.reset(rtcNewScene(device_.get()));
  rtcSetSceneBuildQuality(scene_.get(), RTC_BUILD_QUALITY_HIGH);
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    RTCGeometry geometry = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.vertices.size()));
    auto* indices = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(std::uint32_t), mesh.triangles.size()));
    if (vertices == nullptr || indices == nullptr) {
      rtcReleaseGeometry(geometry);
      throw std::runtime_error("Embree: cannot allocate buffers for mesh " + std::to_string(m));
    }
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      std::memcpy(vertices + 3 * v, mesh.vertices[v].data(), 3 * sizeof(float));
    }
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      std::memcpy(indices + 3 * t, mesh.triangles[t].data(), 3 * sizeof(std::uint32_t));
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene_.get(), geometry, static_cast<unsigned>(m));
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(scene_.get());
  if (const RTCError error = rtcGetDeviceError(device_.get()); error != RTC_ERROR_NONE) {
    throw std::runtime_error("Embree: scene build failed (error " + std::to_string(error) + ")");
  }
}

namespace {

// Sets every field of `ray` that Embree reads. (The queries are filled in place: a zero-initialised
// query built on the stack and copied in made the bundle 2.5 times slower in synthesis_bench.)
void SetRay(RTCRay& ray, const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
            float max_distance, unsigned id) {
  ray.org_x = origin.x();
  ray.org_y = origin.y();
  ray.org_z = origin.z();
  ray.tnear = 0.0f;
  ray.dir_x = direction.x();
  ray.dir_y = direction.y();
  ray.dir_z = direction.z();
  ray.time = 0.0f;
  ray.tfar = max_distance;
  ray.mask = std::numeric_limits<unsigned>::max();
  ray.id = id;
  ray.flags = 0;
}

void SetQuery(RTCRayHit& query, const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
              float max_distance, unsigned id) {
  SetRay(query.ray, origin, direction, max_distance, id);
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

std::optional<Hit> HitOf(const RTCRayHit& query) {
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  Hit hit;
  hit.distance = query.ray.tfar;
  hit.normal = Eigen::Vector3f(query.hit.Ng_x, query.hit.Ng_y, query.hit.Ng_z).normalized();
  hit.mesh = query.hit.geomID;
  return hit;
}

// The streams' queries, per thread and kept between calls: a beam traces several streams, and
// allocating theirs afresh each time cost as much as a tenth of the synthesis.
std::vector<RTCRayHit>& HitQueries() {
  thread_local std::vector<RTCRayHit> queries;
  return queries;
}

// Traces one query per hit, query i set by set_query(query, i), as one stream (rtcIntersect1M)
// with `flags`, and writes the hits.
template <typename SetQueryI>
void IntersectMany(RTCScene scene, RTCIntersectContextFlags flags,
                   std::span<std::optional<Hit>> hits, SetQueryI set_query) {
  std::vector<RTCRayHit>& queries = HitQueries();
  queries.resize(hits.size());
  for (std::size_t i = 0; i < queries.size(); ++i) set_query(queries[i], i);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = flags;
  rtcIntersect1M(scene, &context, queries.data(), static_cast<unsigned>(queries.size()),
                 sizeof(RTCRayHit));
  for (std::size_t i = 0; i < queries.size(); ++i) hits[i] = HitOf(queries[i]);
}

void CheckSizes(const char* what, std::size_t results, std::size_t rays) {
  if (results != rays) {
    throw std::invalid_argument(std::string("RayTracer::") + what + ": " + std::to_string(results) +
                                " results for " + std::to_string(rays) + " rays");
  }
}

}  // namespace

std::size_t RayQueryLog::RayCount() const {
  std::size_t rays = 0;
  for (const Entry& entry : entries) rays += entry.rays.size();
  return rays;
}

void RayTracer::Log(RayQueryLog::Query query, std::vector<Ray> rays) const {
  log_->entries.push_back({.query = query, .rays = std::move(rays)});
}

std::optional<Hit> RayTracer::Intersect(const Eigen::Vector3f& origin,
                                        const Eigen::Vector3f& direction,
                                        float max_distance) const {
  if (log_) Log(RayQueryLog::Query::kSingle, {{origin, direction, max_distance}});
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query{};
  SetQuery(query, origin, direction, max_distance, 0);
  rtcIntersect1(scene_.get(), &context, &query);
  return HitOf(query);
}

void RayTracer::IntersectBundle(const Eigen::Vector3f& origin,
                                std::span<const Eigen::Vector3f> directions, float max_distance,
                                std::span<std::optional<Hit>> hits) const {
  CheckSizes("IntersectBundle", hits.size(), directions.size());
  if (log_) {
    std::vector<Ray> rays;
    rays.reserve(directions.size());
    for (const Eigen::Vector3f& d : directions) rays.push_back({origin, d, max_distance});
    Log(RayQueryLog::Query::kBundle, std::move(rays));
  }
  IntersectMany(scene_.get(), RTC_INTERSECT_CONTEXT_FLAG_COHERENT, hits,
                [&](RTCRayHit& query, std::size_t i) {
                  SetQuery(query, origin, directions[i], max_distance, static_cast<unsigned>(i));
                });
}

void RayTracer::IntersectStream(std::span<const Ray> rays,
                                std::span<std::optional<Hit>> hits) const {
  CheckSizes("IntersectStream", hits.size(), rays.size());
  if (log_) Log(RayQueryLog::Query::kStream, {rays.begin(), rays.end()});
  IntersectMany(scene_.get(), RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT, hits,
                [&](RTCRayHit& query, std::size_t i) {
                  const Ray& ray = rays[i];
                  SetQuery(query, ray.origin, ray.direction, ray.max_distance,
                           static_cast<unsigned>(i));
                });
}

void RayTracer::OccludedStream(std::span<const Ray> rays, std::vector<bool>& occluded) const {
  if (log_) Log(RayQueryLog::Query::kOccludedStream, {rays.begin(), rays.end()});
  thread_local std::vector<RTCRay> queries;
  queries.resize(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    SetRay(queries[i], rays[i].origin, rays[i].direction, rays[i].max_distance,
           static_cast<unsigned>(i));
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcOccluded1M(scene_.get(), &context, queries.data(), static_cast<unsigned>(queries.size()),
                sizeof(RTCRay));
  occluded.resize(rays.size());
  // Embree marks an occluded ray by setting tfar to -inf.
  for (std::size_t i = 0; i < queries.size(); ++i) occluded[i] = queries[i].tfar < 0.0f;
}

bool RayTracer::Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                         float max_distance) const {
  if (log_) Log(RayQueryLog::Query::kSingleOccluded, {{origin, direction, max_distance}});
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  SetRay(ray, origin, direction, max_distance, 0);
  rtcOccluded1(scene_.get(), &context, &ray);
  // Embree marks an occluded ray by setting tfar to -inf.
  return ray.tfar < 0.0f;
}

namespace {

struct NearestQuery {
  RTCScene scene;
  Eigen::Vector3d point;
  double best = -1.0;
};

// Embree calls this for every triangle whose bounds meet the query sphere; shrinking the radius
// to the best distance so far prunes the rest of the BVH.
bool NearestTriangle(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<NearestQuery*>(args->userPtr);
  RTCGeometry geometry = rtcGetGeometry(q->scene, args->geomID);
  const auto* v =
      static_cast<const float*>(rtcGetGeometryBufferData(geometry, RTC_BUFFER_TYPE_VERTEX, 0));
  const auto* t = static_cast<const std::uint32_t*>(
      rtcGetGeometryBufferData(geometry, RTC_BUFFER_TYPE_INDEX, 0));
  auto vertex = [&](std::uint32_t i) {
    return Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  };
  const std::uint32_t* tri = t + 3 * args->primID;
  const double d = PointTriangleDistance(q->point, vertex(tri[0]), vertex(tri[1]), vertex(tri[2]));
  if (d < args->query->radius) {
    args->query->radius = static_cast<float>(d);
    q->best = d;
    return true;
  }
  return false;
}

}  // namespace

std::optional<double> RayTracer::NearestSurfaceDistance(const Eigen::Vector3d& point,
                                                        double max_distance) const {
  RTCPointQuery query;
  query.x = static_cast<float>(point.x());
  query.y = static_cast<float>(point.y());
  query.z = static_cast<float>(point.z());
  query.time = 0.0f;
  query.radius = static_cast<float>(max_distance);
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  NearestQuery nearest{scene_.get(), point, -1.0};
  rtcPointQuery(scene_.get(), &query, &context, NearestTriangle, &nearest);
  if (nearest.best < 0.0) return std::nullopt;
  return nearest.best;
}

}  // namespace sonarbench::sim
