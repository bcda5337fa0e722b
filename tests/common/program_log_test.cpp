// The programs' log (server/common/program_log): where each level goes, the line's form, the file  // SPDX-License-Identifier: Apache-2.0
// appended to and never an input.
#include "viscera/common/program_log.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"

namespace {
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(VISCERA_TEST_TMP) / "program_log";
  fs::create_directories(dir);
  fs::remove(dir / name);
  return dir / name;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ProgramLog, InformationOnStandardOutputErrorsOnStandardErrorOneLineEach) {
  auto log = viscera::common::program_log("viscera-test");
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  log->info("scene {} loaded", "liver");
  log->error("{}: {}: {}", "a.json", "rate_hz", "-5 is outside [10, 10000]");
  const std::string out = testing::internal::GetCapturedStdout(), err = testing::internal::GetCapturedStderr();
  const std::regex line(R"(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3} (info|error) viscera-test: .*\n)");
  EXPECT_TRUE(std::regex_match(out, line)) << out;
  EXPECT_NE(out.find("info viscera-test: scene liver loaded"), std::string::npos) << out;
  EXPECT_TRUE(std::regex_match(err, line)) << err;
  EXPECT_NE(err.find("error viscera-test: a.json: rate_hz: -5 is outside [10, 10000]"), std::string::npos) << err;
}

TEST(ProgramLog, AFileGetsTheSameLinesAppendedToWhatItHeld) {
  const fs::path file = scratch("service.log");
  std::ofstream(file) << "an earlier run\n";
  {
    auto log = viscera::common::program_log("viscera-test", file.string());
    testing::internal::CaptureStdout();
    log->info("first");
    log->warn("second");
    testing::internal::GetCapturedStdout();
  }
  const std::string text = read(file);
  EXPECT_EQ(text.rfind("an earlier run\n", 0), 0u) << text;
  EXPECT_NE(text.find("info viscera-test: first\n"), std::string::npos) << text;
  EXPECT_NE(text.find("warning viscera-test: second\n"), std::string::npos) << text;
}

TEST(ProgramLog, AnInputIsNeverTheLogFileWhateverItsPathSays) {
  const fs::path input = scratch("scene.json"), link = scratch("scene-link.log");
  std::ofstream(input) << "{}\n";
  ASSERT_EQ(::link(input.c_str(), link.c_str()), 0);
  try {
    viscera::common::program_log("viscera-test", link.string(), {input.string()});
    FAIL() << "a hard link to the input was taken as the log";
  } catch (const viscera::common::InputError& e) {
    EXPECT_EQ(e.field(), "--log-file");
  }
  EXPECT_EQ(read(input), "{}\n");
}

TEST(ProgramLog, ALogFileThatCannotBeOpenedIsNamed) {
  const std::string path = (fs::path(VISCERA_TEST_TMP) / "no-such-folder" / "x.log").string();
  try {
    viscera::common::program_log("viscera-test", path);
    FAIL() << "no error";
  } catch (const viscera::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace
