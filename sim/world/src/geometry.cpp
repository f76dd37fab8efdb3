#include "sonarbench/sim/world/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

// Projects the triangle (v0, v1, v2) and the box (half size h, centred at the origin) on `axis`;
// true if the projections are disjoint, i.e. `axis` separates them.
bool Separates(const Vector3d& axis, const Vector3d& v0, const Vector3d& v1, const Vector3d& v2,
               const Vector3d& h) {
  const double p0 = axis.dot(v0);
  const double p1 = axis.dot(v1);
  const double p2 = axis.dot(v2);
  const double r =
      h.x() * std::abs(axis.x()) + h.y() * std::abs(axis.y()) + h.z() * std::abs(axis.z());
  return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

}  // namespace

bool TriangleBoxOverlap(const Vector3d& box_centre, const Vector3d& box_half_size,
                        const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d v0 = a - box_centre;
  const Vector3d v1 = b - box_centre;
  const Vector3d v2 = c - box_centre;
  const Vector3d& h = box_half_size;
  // The box's face normals.
  for (int i = 0; i < 3; ++i) {
    if (std::min({v0[i], v1[i], v2[i]}) > h[i] || std::max({v0[i], v1[i], v2[i]}) < -h[i]) {
      return false;
    }
  }
  // The triangle's normal.
  const Vector3d e0 = v1 - v0;
  const Vector3d e1 = v2 - v1;
  const Vector3d e2 = v0 - v2;
  const Vector3d normal = e0.cross(e1);
  if (Separates(normal, v0, v1, v2, h)) return false;
  // The nine cross products of box axes and triangle edges.
  for (const Vector3d& edge : {e0, e1, e2}) {
    for (int i = 0; i < 3; ++i) {
      const Vector3d axis = Vector3d::Unit(i).cross(edge);
      if (axis.squaredNorm() > 0.0 && Separates(axis, v0, v1, v2, h)) return false;
    }
  }
  return true;
}

double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

}  // namespace sonarbench::sim
