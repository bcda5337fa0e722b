#pragma once  // SPDX-License-Identifier: Apache-2.0
// The whole loop of a haptic device on a viscera server, for any Device: at the device rate it
// reads the device, sends the tip, renders the server's local force model back, keeps its commands
// in phase after the server's physics ticks, claims the instrument again after a scene load, stands
// by while an instructor has taken the instrument over, fades the force out when the server or the
// instrument is lost, and (with reconnect) claims again when a server comes back. The decisions are
// DeviceLoop's (device_loop.hpp, unit-tested); this is their I/O on a Client and the wall clock.
// A device vendor implements Device and calls run_device after claiming the instrument.
#include <cstdint>
#include <functional>
#include <string>

#include "viscera/client/client.hpp"
#include "viscera/client/device.hpp"
#include "viscera/client/device_loop.hpp"

namespace viscera::client {

struct DeviceRunOptions {
  DeviceLoopOptions loop;
  double rate_hz = 1000;  ///< device periods per second
  double duration_s = 4;  ///< the run ends after this long (or when the device says it is finished)
  double tick_phase_us = 100;  ///< commands this long after each server tick when rate_hz is the physics rate; < 0: loop free
};

/// One driven period, for a caller that shows or keeps them.
struct DevicePeriod {
  double t_s;
  const DeviceSample& device;
  const protocol::Force& force;  ///< the newest answer from the server
  const RenderedForce& rendered;  ///< what the device was told to render (after the slew limit)
  double model_age_s;
  std::uint64_t model_age_commands;  ///< commands sent since the one the model answers
};

struct DeviceRunHooks {
  std::function<void(const std::string&)> note;  ///< a line for the user (a change of state)
  std::function<void(const DevicePeriod&)> period;  ///< after each driven period's render
};

struct DeviceRunResult {
  std::uint64_t clamps = 0;  ///< periods whose force was limited to max_force_n
  std::uint64_t phased = 0, near_phase = 0;  ///< periods timed by the phase lock; of them within 50 us of the target
  double server_lost_t_s = -1, faded_t_s = -1, instrument_lost_t_s = -1;
  int server_returns = 0, taken_over = 0, instrument_losses = 0;
  double stall_s = 0, stall_end_t_s = -1;  ///< the longest time the loop did not run beyond the lease, and when the last such ended (DeviceLoop)
  bool lost = false;  ///< ended because the server was gone
  /// The longest time without a new model while the loop sent commands [s] (a server that was
  /// gone and came back included), and when it ended (-1: none): a server or network that fell
  /// silent (the liveliness lease runs out at 0.5 s).
  double longest_silence_s = 0, longest_silence_end_t_s = -1;
  /// Periods whose force the slew limit changed, and the largest change per period the renderer
  /// asked for [N] (what the hand would have felt without the limit).
  long slew_limited = 0;
  double largest_step_asked_n = 0;
};

/// Runs the loop; `generation` is that of the scene in which the instrument was claimed.
DeviceRunResult run_device(Client& client, Device& device, const DeviceRunOptions& options, std::uint32_t generation,
                           const DeviceRunHooks& hooks = {});

}  // namespace viscera::client
