// Writes hostile payloads on the command and session topics: garbage, truncated commands,  // SPDX-License-Identifier: Apache-2.0
// another schema, NaN positions, commands for an instrument the sender does not own, and commands
// and releases for an instrument the scene does not have.
// Usage: hostile_publisher DOMAIN SECONDS [--station NAME]
//        hostile_publisher DOMAIN release INSTRUMENT CLIENT [--station NAME]   (a release under
//        another process's client id, as a second run of a client under one id sends it; prints
//        when, Unix seconds)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>

#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/messages.hpp"

using namespace viscera::protocol;

int run(int argc, char** argv) {
  std::string station;
  if (argc > 3 && std::string(argv[argc - 2]) == "--station") {
    station = argv[argc - 1];
    argc -= 2;
  }
  if (argc != 3 && !(argc == 5 && std::string(argv[2]) == "release")) {
    std::fprintf(stderr, "usage: hostile_publisher DOMAIN SECONDS | DOMAIN release INSTRUMENT CLIENT [--station NAME]\n");
    return 2;
  }
  Participant p(static_cast<std::uint32_t>(std::atoi(argv[1])), station);
  Writer commands(p, Stream::instrument_command), sessions(p, Stream::session_request);
  if (argc == 5) {
    SessionRequest r;
    r.client_id = static_cast<std::uint32_t>(std::atoi(argv[4]));
    r.action = Action::release_instrument;
    r.instrument_id = static_cast<std::uint32_t>(std::atoi(argv[3]));
    sessions.wait_for_readers(std::chrono::seconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the server's reader knows this writer
    sessions.write(r.client_id, encode(r));
    std::printf("released at %.6f\n", 1e-9 * static_cast<double>(now_ns()));
    sessions.wait_for_acks(std::chrono::seconds(2));
    return 0;
  }
  std::mt19937_64 rng(99);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[2]));
  long sent = 0;
  while (std::chrono::steady_clock::now() < end) {
    std::vector<std::uint8_t> garbage(8 + rng() % 100);
    for (auto& b : garbage) b = static_cast<std::uint8_t>(rng());
    Command c;
    c.instrument_id = 1;
    c.client_id = 66;  // not the owner
    c.tip_position = {0, 0, 0};
    std::vector<std::uint8_t> good = encode(c);
    std::vector<std::uint8_t> truncated(good.begin(), good.begin() + static_cast<long>(good.size() / 2));
    c.tip_position = {std::nan(""), 0, 0};
    Scene wrong;
    wrong.name = "not a command";
    commands.write(900, garbage);
    commands.write(901, truncated);
    commands.write(902, encode(c));
    commands.write(903, encode(wrong));
    commands.write(904, good);  // valid, but for an instrument owned by someone else
    sessions.write(905, garbage);
    Command unknown = c;
    unknown.instrument_id = 99;  // not in the scene
    unknown.tip_position = {0, 0, 0};
    commands.write(906, encode(unknown));
    sent += 7;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  std::printf("hostile_publisher: sent %ld hostile payloads\n", sent);
  return 0;
}

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const DdsError& e) {  // e.g. DDS Security refused a writer
    std::fprintf(stderr, "hostile_publisher: %s\n", e.what());
    return 3;
  }
}
