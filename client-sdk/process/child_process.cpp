#include "viscera/process/child_process.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <chrono>
#include <csignal>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <spawn.h>

extern char** environ;

namespace viscera::process {

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& log_path) : log_(log_path) {
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // Never through a symbolic link someone placed at the log's path.
  posix_spawn_file_actions_addopen(&actions, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0600);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  const int rc = posix_spawnp(&pid_, argv.at(0).c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && status_ < 0) stop();
}

bool ChildProcess::alive() {
  if (status_ >= 0) return false;
  int st = 0;
  if (waitpid(pid_, &st, WNOHANG) == pid_) {
    status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return false;
  }
  return true;
}

int ChildProcess::stop() {
  if (!alive()) return status_;
  kill(pid_, SIGTERM);
  for (int k = 0; k < 500 && alive(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (alive()) {
    kill(pid_, SIGKILL);
    int st = 0;
    waitpid(pid_, &st, 0);
    status_ = 128 + SIGKILL;
  }
  return status_;
}

std::string ChildProcess::log_tail(int lines) const {
  std::ifstream in(log_);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back(line);
    if (static_cast<int>(last.size()) > lines) last.pop_front();
  }
  std::string out;
  for (const auto& l : last) out += (out.empty() ? "" : "\n") + l;
  return out;
}

std::string find_program(const std::string& name, const std::string& tree_dir) {
  namespace fs = std::filesystem;
  // This program is at BUILD/tools/<its folder>/ in the build tree.
  const fs::path self = fs::read_symlink("/proc/self/exe").parent_path();
  for (const fs::path& p : {self / name, self / ".." / ".." / tree_dir / name})
    if (fs::exists(p)) return fs::canonical(p).string();
  return name;  // on the PATH
}

}  // namespace viscera::process
