#include "viscera/tissue/cutting/blade_sweep.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>

namespace viscera::tissue {

namespace {

// Segment p -> q against triangle (A, B, C): p + s (q - p) = A + u (B - A) + v (C - A), solved by
// Cramer's rule (Moller-Trumbore). A triangle edge shared by the patch's two triangles belongs to
// both, so a segment through it is found by one of them.
std::optional<double> segment_triangle(const Vec3& p, const Vec3& q, const Vec3& A, const Vec3& B, const Vec3& C) {
  const Vec3 d = q - p, e1 = B - A, e2 = C - A;
  const Vec3 h = d.cross(e2);
  const double det = e1.dot(h);
  // Parallel (or a degenerate triangle: the blade did not move): no crossing.
  const double scale = d.norm() * e1.norm() * e2.norm();
  if (!(std::fabs(det) > 1e-12 * scale)) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3 w = p - A;
  const double u = w.dot(h) * inv;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const Vec3 g = w.cross(e1);
  const double v = d.dot(g) * inv;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double s = e2.dot(g) * inv;
  if (s < 0.0 || s > 1.0) return std::nullopt;
  return s;
}

}  // namespace

Box BladeSweep::bounds() const {
  Box b{a0, a0};
  for (const Vec3* p : {&b0, &a1, &b1}) {
    b.lo = b.lo.cwiseMin(*p);
    b.hi = b.hi.cwiseMax(*p);
  }
  return b;
}

std::optional<double> sweep_crossing(const BladeSweep& sweep, const Vec3& p, const Vec3& q) {
  if (auto s = segment_triangle(p, q, sweep.a0, sweep.b0, sweep.b1)) return s;
  return segment_triangle(p, q, sweep.a0, sweep.b1, sweep.a1);
}

}  // namespace viscera::tissue
