#pragma once
// Rendering the server's local contact model at the device rate (HAPTICS.md section 2): between
// server updates and across network delay the client renders F(x) = F0 - K (x - x0), with x0 the
// tip position the server computed F0 for and K = -dF/dx, pushing only out of the tissue (along
// the contact normal) and never beyond the device's force limit.
#include "viscera/protocol/messages.hpp"

namespace viscera::client {

struct RenderedForce {
  protocol::Vector3 force{};
  bool clamped = false;  ///< limited to the device's maximum force
};

/// x0: the tip position of the command the force answers; x: the tip position now.
RenderedForce render_local_model(const protocol::Force& f, const protocol::Vector3& x0, const protocol::Vector3& x,
                                 double max_force_n);

}  // namespace viscera::client
