#include "viscera/runtime/contact_proxy.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <limits>

namespace viscera::runtime {

namespace {
/// A proxy that anchored below its offset surface (first touch on a corner, or a goal already in
/// the tissue when the surface changed) rises to it with this time constant: the force fades in.
constexpr double kLiftFadeS = 0.02;
/// Triangles whose normal points more than about 107 degrees away from the proxy's are the far
/// wall of a fold or of a cut's gap, not the surface the proxy slides on.
constexpr double kSlideFacingCos = -0.3;

Vec3 vertex_normal(const ContactSurface& s, std::span<const Vec3> x, std::int32_t node) {
  Vec3 n = Vec3::Zero();
  const auto i = static_cast<std::size_t>(node);
  if (i + 1 >= s.incident_begin.size()) return n;
  for (std::uint32_t k = s.incident_begin[i]; k < s.incident_begin[i + 1]; ++k) {
    const auto& t = s.triangles[s.incident[k]];
    n += (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);  // area-weighted
  }
  const double norm = n.norm();
  return norm > 0 ? Vec3(n / norm) : n;
}
}  // namespace

std::optional<SurfacePoint> nearest_surface_point(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p, double reach,
                                                  const Vec3* facing) {
  std::optional<SurfacePoint> best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < surface.triangles.size(); ++k) {
    const auto& t = surface.triangles[k];
    const Vec3& a = x[t[0]];
    const double broad = reach + 3.0 * surface.longest_rest_edge_m[k];  // as ProbeContact's broad phase
    if ((p - a).squaredNorm() > broad * broad) continue;
    const Vec3 &b = x[t[1]], &c = x[t[2]];
    if (facing) {
      const Vec3 n = (b - a).cross(c - a);
      const double area2 = n.norm();
      if (!(area2 > 0) || n.dot(*facing) < kSlideFacingCos * area2) continue;
    }
    Vec3 w;
    const Vec3 q = closest_point_on_triangle(p, a, b, c, &w);
    const double d2 = (p - q).squaredNorm();
    if (d2 > reach * reach || d2 >= best_d2) continue;
    best_d2 = d2;
    best = SurfacePoint{k, w, q};
  }
  return best;
}

Vec3 smooth_normal(const ContactSurface& surface, std::span<const Vec3> x, std::size_t triangle, const Vec3& w) {
  const auto& t = surface.triangles[triangle];
  Vec3 n = w[0] * vertex_normal(surface, x, t[0]) + w[1] * vertex_normal(surface, x, t[1]) + w[2] * vertex_normal(surface, x, t[2]);
  double norm = n.norm();
  if (!(norm > 1e-9)) {  // opposite vertex normals (a sliver fold): the face's own
    n = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
    norm = n.norm();
  }
  return norm > 0 ? Vec3(n / norm) : Vec3::UnitZ();
}

ContactProxy::ContactProxy(std::shared_ptr<const ContactSurface> surface, const ContactProxyParameters& p) : surface_(std::move(surface)), p_(p) {}

Vec3 ContactProxy::normal(std::span<const Vec3> x) const {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < footprint_.size(); ++i) n += share_[i] * vertex_normal(*surface_, x, footprint_[i]);
  const double norm = n.norm();
  return norm > 1e-9 ? Vec3(n / norm) : smooth_normal(*surface_, x, at_.triangle, at_.weights);
}

Vec3 ContactProxy::point(std::span<const Vec3> x) const {
  Vec3 q = offset_;
  for (std::size_t i = 0; i < footprint_.size(); ++i) q += share_[i] * x[static_cast<std::size_t>(footprint_[i])];
  return q;
}

void ContactProxy::anchor(const SurfacePoint& at, std::span<const Vec3> x) {
  at_ = at;
  anchored_ = true;
  // The footprint: the surface nodes within the tip's radius of the anchor (at least the anchor
  // triangle's), reached through the triangles around them, weighted by (1 - (d / rho)^2)^2.
  const auto& t = surface_->triangles[at.triangle];
  const double longest = std::max({(x[t[1]] - x[t[0]]).norm(), (x[t[2]] - x[t[1]]).norm(), (x[t[0]] - x[t[2]]).norm()});
  const double rho = std::max(p_.tip_radius_m, longest);
  footprint_.assign(t.begin(), t.end());
  for (std::size_t next = 0; next < footprint_.size(); ++next) {
    const auto i = static_cast<std::size_t>(footprint_[next]);
    if ((x[i] - at.point).norm() >= rho) continue;
    for (std::uint32_t k = surface_->incident_begin[i]; k < surface_->incident_begin[i + 1]; ++k)
      for (const auto v : surface_->triangles[surface_->incident[k]])
        if (std::find(footprint_.begin(), footprint_.end(), v) == footprint_.end()) footprint_.push_back(v);
  }
  share_.clear();
  double total = 0;
  std::size_t kept = 0;
  for (const auto v : footprint_) {
    const double u = (x[static_cast<std::size_t>(v)] - at.point).squaredNorm() / (rho * rho);
    if (u >= 1) continue;
    footprint_[kept++] = v;
    share_.push_back((1 - u) * (1 - u));
    total += share_.back();
  }
  footprint_.resize(kept);
  for (auto& s : share_) s /= total;
  offset_ = Vec3::Zero();
  offset_ = at.point - point(x);
}

void ContactProxy::track(const Vec3& goal, std::span<const Vec3> x, double dt_s) {
  const double r = p_.tip_radius_m;
  if (anchored_) {
    lift_m_ *= std::exp(-dt_s / kLiftFadeS);
    const Vec3 q = point(x), n = normal(x);
    const Vec3 d = goal - (q + (r + lift_m_) * n);
    const double dn = -d.dot(n);  // the goal's depth behind the proxy
    if (dn > 0) {
      const Vec3 tangential = d + dn * n;
      const double lag = tangential.norm();
      // A stuck proxy breaks away beyond the static cone; a sliding one goes on sliding while the
      // goal pulls beyond the kinetic cone, and sticks again below it. Stuck, the anchor moves
      // with the tissue; sliding, it goes toward the goal until the tangential force is on the
      // kinetic cone.
      sliding_ = lag > (sliding_ ? p_.friction.kinetic_mu : p_.friction.static_mu) * dn;
      if (sliding_) {
        const double kept = std::min(lag, p_.friction.kinetic_mu * dn);
        const Vec3 target = q + (1 - kept / lag) * tangential;
        if (const auto s = nearest_surface_point(*surface_, x, target, (target - q).norm() + r, &n)) {
          const double lift = lift_m_;
          anchor(*s, x);
          lift_m_ = lift;
        }
      }
      return;
    }
    release();  // the goal is back out of the proxy's sphere
  }
  // Free: the proxy is the goal, and anchors where the goal's sphere touches the surface.
  const auto s = nearest_surface_point(*surface_, x, goal, r + p_.max_depth_m);
  if (!s) return;
  const double distance = (goal - s->point).norm();
  anchor(*s, x);
  const double along = (goal - s->point).dot(normal(x));
  if (!(distance < r || along < 0) || along < -p_.max_depth_m) {
    release();
    return;
  }
  sliding_ = false;
  // Starts where the goal is along the normal: no force at the first touch, whatever the corner.
  lift_m_ = std::min(0.0, along - r);
}

ContactResult ContactProxy::apply(const Vec3& goal, const Vec3& goal_velocity, const tissue::BoundaryConditions::FieldEvaluation& field) const {
  ContactResult res;
  if (!anchored_) return res;
  const auto x = field.x, v = field.v;
  const Vec3 q = point(x), n = normal(x);
  const Vec3 d = goal - (q + (p_.tip_radius_m + lift_m_) * n);
  const double dn = -d.dot(n), k = p_.stiffness_n_per_m;
  const bool moving = !v.empty();
  double fn = k * dn, dashpot = 0;
  if (moving) {
    Vec3 vq = Vec3::Zero();
    for (std::size_t i = 0; i < footprint_.size(); ++i) vq += share_[i] * v[static_cast<std::size_t>(footprint_[i])];
    dashpot = p_.damping_s_per_m * k * std::max(dn, 0.0);  // [N s/m]
    fn += (dashpot + k * field.dt_s) * (vq - goal_velocity).dot(n);
  }
  fn = std::min(fn, p_.force_limit_n);
  if (!(fn > 0)) return res;
  const bool stuck = !sliding_ && p_.friction.static_mu > 0;
  Vec3 ft = -k * (d + dn * n);  // the coupling's pull back toward the proxy
  const double cone = (stuck ? p_.friction.static_mu : p_.friction.kinetic_mu) * fn, pull = ft.norm();
  if (pull > cone) ft *= cone / pull;
  Vec3 on_tool = fn * n + ft;
  if (const double f = on_tool.norm(); f > p_.force_limit_n) on_tool *= p_.force_limit_n / f;
  for (std::size_t i = 0; i < footprint_.size(); ++i) {
    const auto node = static_cast<std::size_t>(footprint_[i]);
    if (!field.f.empty()) field.f[node] -= share_[i] * on_tool;
    if (!field.stiffness.empty()) field.stiffness[node] += std::sqrt(3.0) * k * share_[i];
    if (dashpot > 0 && !field.damping.empty()) field.damping[node] += std::sqrt(3.0) * dashpot * share_[i];
  }
  res.in_contact = true;
  res.stuck = stuck;
  res.friction_mu = stuck ? p_.friction.static_mu : p_.friction.kinetic_mu;
  res.force_on_tool = on_tool;
  res.point = q;
  res.normal = n;
  res.depth_m = std::max(dn, 0.0);
  res.triangles_in_contact = 1;
  res.deepest_triangle = surface_->triangles[at_.triangle];
  res.deepest_weights = at_.weights;
  const Eigen::Matrix3d K = stuck ? Eigen::Matrix3d(k * Eigen::Matrix3d::Identity()) : Eigen::Matrix3d(k * n * n.transpose());
  std::size_t next = 0;  // row-major
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) res.stiffness[next++] = K(i, j);
  return res;
}

ContactResult ContactProxy::query(const Vec3& goal, std::span<const Vec3> x) const {
  ContactProxy p = *this;
  p.track(goal, x, 0.0);
  return p.apply(goal, Vec3::Zero(), {x, {}, {}, {}, {}, 0.0});
}

Vec3 ContactProxy::centre(const Vec3& goal, std::span<const Vec3> x) const {
  if (!anchored_) return goal;
  return point(x) + (p_.tip_radius_m + lift_m_) * normal(x);
}

}  // namespace viscera::runtime
