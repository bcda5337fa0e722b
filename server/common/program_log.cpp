#include "viscera/common/program_log.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>

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
}  // namespace

std::shared_ptr<spdlog::logger> program_log(const std::string& program, const std::string& file, const std::vector<std::string>& inputs) {
  std::vector<spdlog::sink_ptr> sinks{std::make_shared<ConsoleSink>()};
  if (!file.empty()) {
    refuse_overwrite(file, inputs, "--log-file");
    if (!std::ofstream(file, std::ios::app))
      throw InputError(file, 0, "--log-file", std::string("cannot be opened for appending: ") + std::strerror(errno));
    sinks.push_back(std::make_shared<spdlog::sinks::basic_file_sink_mt>(file, false));
  }
  auto log = std::make_shared<spdlog::logger>(program, sinks.begin(), sinks.end());
  log->set_pattern("%Y-%m-%d %H:%M:%S.%e %l %n: %v");
  log->set_level(spdlog::level::info);
  log->flush_on(spdlog::level::info);
  return log;
}

}  // namespace viscera::common
