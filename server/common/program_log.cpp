#include "viscera/common/program_log.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>

#include <pthread.h>

#include <sched.h>
#include <spdlog/async_logger.h>
#include <spdlog/details/thread_pool.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/sinks/basic_file_sink.h>

#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"

namespace viscera::common {

namespace {
// Information on standard output, warnings and errors on standard error: spdlog's console sinks
// write every level to one stream.
class ConsoleSink : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t line;
    formatter_->format(msg, line);
    std::FILE* out = msg.level >= spdlog::level::warn ? stderr : stdout;
    std::fwrite(line.data(), 1, line.size(), out);
    std::fflush(out);
  }
  void flush_() override {
    std::fflush(stdout);
    std::fflush(stderr);
  }
};

// A background log and the thread pool that writes it, released together: the logger first, then
// the pool, whose destructor writes the queued lines and joins its thread.
struct BackgroundLog {
  std::shared_ptr<spdlog::details::thread_pool> pool;
  std::shared_ptr<spdlog::logger> logger;
};
std::weak_ptr<spdlog::details::thread_pool> g_pool;

std::shared_ptr<spdlog::logger> in_background(const std::string& program, const std::vector<spdlog::sink_ptr>& sinks) {
  auto both = std::make_shared<BackgroundLog>();
  both->pool = std::make_shared<spdlog::details::thread_pool>(kQueuedLogLines, 1, [] {
    pthread_setname_np(pthread_self(), "log");
    // Not at the real-time priority it may have inherited: writing lines never competes with
    // the threads that keep time, and may wait for the disk as long as it takes.
    const sched_param normal{};
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
  });
  g_pool = both->pool;
  both->logger =
      std::make_shared<spdlog::async_logger>(program, sinks.begin(), sinks.end(), both->pool, spdlog::async_overflow_policy::overrun_oldest);
  return {both, both->logger.get()};  // shares ownership of both
}

std::shared_ptr<spdlog::logger> configured(std::shared_ptr<spdlog::logger> log, const char* pattern) {
  log->set_pattern(pattern);
  log->set_level(spdlog::level::info);
  log->flush_on(spdlog::level::info);
  return log;
}
}  // namespace

std::size_t log_lines_dropped() {
  const auto pool = g_pool.lock();
  return pool ? pool->overrun_counter() : 0;
}

std::shared_ptr<spdlog::logger> program_log(const std::string& program, const std::string& file, const std::vector<std::string>& inputs,
                                            LogDelivery delivery) {
  std::vector<spdlog::sink_ptr> sinks{std::make_shared<ConsoleSink>()};
  if (!file.empty()) {
    refuse_overwrite(file, inputs, "--log-file");
    if (!std::ofstream(file, std::ios::app))
      throw InputError(file, 0, "--log-file", std::string("cannot be opened for appending: ") + std::strerror(errno));
    sinks.push_back(std::make_shared<spdlog::sinks::basic_file_sink_mt>(file, false));
  }
  constexpr const char* pattern = "%Y-%m-%d %H:%M:%S.%e %l %n: %v";
  if (delivery == LogDelivery::in_line) return configured(std::make_shared<spdlog::logger>(program, sinks.begin(), sinks.end()), pattern);
  return configured(in_background(program, sinks), pattern);
}

std::shared_ptr<spdlog::logger> background_lines(const std::string& program) {
  return configured(in_background(program, {std::make_shared<ConsoleSink>()}), "%v");
}

}  // namespace viscera::common
