#pragma once  // SPDX-License-Identifier: Apache-2.0
// A child process (the lockstep viscera-server of a re-simulation, a replay the console opens):
// started with its output in a log file, stopped with SIGTERM (then SIGKILL), its last lines at
// hand for an error message.
#include <string>
#include <vector>

#include <sys/types.h>

namespace viscera::process {

class ChildProcess {
 public:
  /// Starts `argv` (argv[0] a path); throws std::runtime_error if it cannot.
  ChildProcess(const std::vector<std::string>& argv, const std::string& log_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  bool alive();
  /// SIGTERM, up to 5 s, then SIGKILL; returns the exit status (or 128 + signal).
  int stop();
  /// The log's last `lines` lines.
  std::string log_tail(int lines = 5) const;

 private:
  pid_t pid_ = -1;
  int status_ = -1;
  std::string log_;
};

/// The program `name` next to this program (installed), or in the build tree at `tree_dir` (from
/// the build's top, e.g. "server/runtime"), or else on the PATH.
std::string find_program(const std::string& name, const std::string& tree_dir);

}  // namespace viscera::process
