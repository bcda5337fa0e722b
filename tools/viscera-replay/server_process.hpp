#pragma once
// A child process (the lockstep viscera-server of a re-simulation): started with its output in a
// log file, stopped with SIGTERM (then SIGKILL), its last lines at hand for an error message.
#include <string>
#include <vector>

#include <sys/types.h>

namespace viscera::replay {

class ServerProcess {
 public:
  /// Starts `argv` (argv[0] a path); throws std::runtime_error if it cannot.
  ServerProcess(const std::vector<std::string>& argv, const std::string& log_path);
  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;
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

/// The viscera-server next to this program (installed) or in the build tree beside it.
std::string find_server_program();

}  // namespace viscera::replay
