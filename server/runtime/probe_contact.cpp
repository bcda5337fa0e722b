#include "viscera/runtime/probe_contact.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

namespace viscera::runtime {

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3* w) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return *w = Vec3(1, 0, 0), a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return *w = Vec3(0, 1, 0), b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return *w = Vec3(1 - v, v, 0), a + v * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return *w = Vec3(0, 0, 1), c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double v = d2 / (d2 - d6);
    return *w = Vec3(1 - v, 0, v), a + v * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return *w = Vec3(0, 1 - v, v), b + v * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc), v = vb * denom, u = vc * denom;
  return *w = Vec3(1 - v - u, v, u), a + v * ab + u * ac;
}

std::shared_ptr<const ContactSurface> make_contact_surface(std::vector<tissue::Triangle> triangles, std::span<const Vec3> rest) {
  auto s = std::make_shared<ContactSurface>();
  s->longest_rest_edge_m.reserve(triangles.size());
  for (const auto& t : triangles) {
    const Vec3 &a = rest[t[0]], &b = rest[t[1]], &c = rest[t[2]];
    s->longest_rest_edge_m.push_back(std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}));
  }
  std::size_t nodes = 0;
  for (const auto& t : triangles)
    for (const auto v : t) nodes = std::max(nodes, static_cast<std::size_t>(v) + 1);
  s->incident_begin.assign(nodes + 1, 0);
  for (const auto& t : triangles)
    for (const auto v : t) ++s->incident_begin[static_cast<std::size_t>(v) + 1];
  for (std::size_t i = 0; i < nodes; ++i) s->incident_begin[i + 1] += s->incident_begin[i];
  s->incident.resize(3 * triangles.size());
  std::vector<std::uint32_t> fill(s->incident_begin.begin(), s->incident_begin.end() - 1);
  for (std::size_t k = 0; k < triangles.size(); ++k)
    for (const auto v : triangles[k]) s->incident[fill[static_cast<std::size_t>(v)]++] = static_cast<std::uint32_t>(k);
  s->triangles = std::move(triangles);
  return s;
}

ProbeContact::ProbeContact(std::shared_ptr<const ContactSurface> surface, double tip_radius_m, double stiffness_n_per_m, double max_depth_m,
                           double damping_s_per_m)
    : surface_(std::move(surface)), radius_(tip_radius_m), stiffness_(stiffness_n_per_m), max_depth_(max_depth_m), damping_(damping_s_per_m) {}

ContactResult ProbeContact::apply(const Vec3& centre, const Vec3& tool_velocity, const tissue::BoundaryConditions::FieldEvaluation& field) const {
  const auto x = field.x, v = field.v;
  const auto f = field.f;
  const auto node_stiffness = field.stiffness, node_damping = field.damping;
  ContactResult r;
  // First pass: the triangles the tip sphere touches, with their depths.
  touching_.clear();
  double total = 0.0;
  const auto& triangles = surface_->triangles;
  const auto& longest = surface_->longest_rest_edge_m;
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    const auto& t = triangles[k];
    const Vec3& a = x[t[0]];
    const double reach = radius_ + max_depth_ + 3.0 * longest[k];
    if ((centre - a).squaredNorm() > reach * reach) continue;  // broad phase
    const Vec3 &b = x[t[1]], &c = x[t[2]];
    Vec3 n = (b - a).cross(c - a);
    const double area2 = n.norm();
    if (area2 <= 0) continue;
    n /= area2;
    Vec3 w;
    const Vec3 q = closest_point_on_triangle(centre, a, b, c, &w);
    const double s = (centre - q).dot(n);
    if (s >= radius_ || s < -max_depth_) continue;
    // Off the triangle's interior, only a tip outside the surface touches its edge or corner, and
    // it penetrates by what the sphere overlaps it there: at a sharp edge (the lip of a cut, whose
    // face stands at right angles to the top) the distance along the normal is near 0 while the
    // tip only grazes the edge, and taken as the depth it pushed the lip with the tip's whole radius.
    const bool interior = w.minCoeff() > 0;
    const double distance = (centre - q).norm();
    if (!interior && (s < 0 || distance >= radius_)) continue;
    const double depth = interior ? radius_ - s : radius_ - distance;
    touching_.push_back({k, n, w, q, depth});
    total += depth;
    if (depth > r.depth_m) {
      r.depth_m = depth;
      r.deepest_triangle = t;
      r.deepest_weights = w;
    }
  }
  if (touching_.empty()) return r;
  // Second pass: one contact of stiffness k at the deepest penetration, shared among the touched
  // triangles by depth, so the force does not grow with the number of triangles under the tip
  // (a finer mesh would otherwise push harder for the same indentation).
  // Each touched triangle carries its share of the spring at the deepest penetration, plus a
  // dashpot on its own rate of penetration (its contact point's velocity relative to the tool,
  // along its normal), never pulling. Per triangle, so the damping is symmetric and only removes
  // energy (one rate applied to every triangle can feed a triangle moving against it). The
  // dashpot grows with the depth (Hunt and Crossley 1975: k d (1 + alpha rate)), so the force is
  // continuous when contact begins: a dashpot of fixed strength jumps at the first touch. The
  // spring's own part, k dt rate, is the depth it will have at the end of the step (backward
  // Euler); it changes the force at the first touch by k dt rate only.
  const bool moving = !v.empty();
  const double dashpot = damping_ * stiffness_ * r.depth_m;  // [N s/m]
  const double rate_gain = moving ? dashpot + stiffness_ * field.dt_s : 0.0;  // [N s/m]
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
  Vec3 weighted_point = Vec3::Zero();
  for (const auto& c : touching_) {
    const double share = c.depth / total;
    double normal_force = stiffness_ * r.depth_m * share;
    if (rate_gain > 0) {
      const auto& t = triangles[c.triangle];
      const Vec3 vq = c.weights[0] * v[t[0]] + c.weights[1] * v[t[1]] + c.weights[2] * v[t[2]];
      normal_force = std::max(0.0, normal_force + rate_gain * share * (vq - tool_velocity).dot(c.normal));
    }
    const Vec3 push = normal_force * c.normal;  // on the tool, out of the tissue
    const auto& t = triangles[c.triangle];
    if (!f.empty())
      for (int k = 0; k < 3; ++k) f[t[k]] -= c.weights[k] * push;
    if (!node_stiffness.empty())
      for (int k = 0; k < 3; ++k) node_stiffness[t[k]] += std::sqrt(3.0) * stiffness_ * share * c.weights[k];
    if (moving && dashpot > 0 && !node_damping.empty())
      for (int k = 0; k < 3; ++k) node_damping[t[k]] += std::sqrt(3.0) * dashpot * share * c.weights[k];
    r.force_on_tool += push;
    K += stiffness_ * share * c.normal * c.normal.transpose();
    weighted_point += share * c.point;
  }
  r.triangles_in_contact = static_cast<int>(touching_.size());
  r.in_contact = true;
  r.point = weighted_point;
  const double fn = r.force_on_tool.norm();
  if (fn > 0) r.normal = r.force_on_tool / fn;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.stiffness[3 * i + j] = K(i, j);
  return r;
}

}  // namespace viscera::runtime
