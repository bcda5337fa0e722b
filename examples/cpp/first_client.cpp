// A first haptic client: claims probe 1, presses it 2 cm into the organ at 1 kHz, prints the force.  // SPDX-License-Identifier: Apache-2.0
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include <viscera/client/client.hpp>

int main(int argc, char** argv) {
  using namespace std::chrono;
  viscera::client::Client client(argc > 1 ? std::atoi(argv[1]) : 0, 42);  // DDS domain, this client's id
  const auto scene = client.wait_for_scene(seconds(10));
  if (!scene || !client.claim(1, seconds(5))) {
    std::fputs("no viscera-server on this domain, or its probe 1 is taken\n", stderr);
    return 1;
  }
  const auto &lo = scene->bounds_min, &hi = scene->bounds_max;
  auto next = steady_clock::now();
  for (int ms = 0; ms <= 4000; ++ms, next += milliseconds(1)) {
    const double z = hi[2] + 0.01 - 0.03 * (ms < 2000 ? ms : 4000 - ms) / 2000.0;  // [m] down and back
    client.send_tip(1, {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, z});
    const auto f = client.wait_force(1, next + milliseconds(1));
    if (f && ms % 250 == 0) std::printf("t %.2f s  tip z %.4f m  force z %.3f N\n", ms / 1000.0, z, f->force[2]);
    std::this_thread::sleep_until(next + milliseconds(1));
  }
}
