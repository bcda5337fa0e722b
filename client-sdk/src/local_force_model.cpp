#include "viscera/client/local_force_model.hpp"

#include <cmath>

namespace viscera::client {

RenderedForce render_local_model(const protocol::Force& f, const protocol::Vector3& x0, const protocol::Vector3& x, double max_force_n) {
  RenderedForce r;
  if (!f.in_contact) return r;
  const double dx[3] = {x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]};
  for (int i = 0; i < 3; ++i) {
    r.force[i] = f.force[i];
    for (int j = 0; j < 3; ++j) r.force[i] -= f.stiffness[3 * i + j] * dx[j];
  }
  // Push only: a force that would pull the tool into the tissue is no contact.
  const auto& n = f.contact_normal;
  if (r.force[0] * n[0] + r.force[1] * n[1] + r.force[2] * n[2] <= 0) return RenderedForce{};
  const double mag = std::sqrt(r.force[0] * r.force[0] + r.force[1] * r.force[1] + r.force[2] * r.force[2]);
  if (mag > max_force_n) {
    for (double& c : r.force) c *= max_force_n / mag;
    r.clamped = true;
  }
  return r;
}

}  // namespace viscera::client
