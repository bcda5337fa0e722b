#include "viscera/common/file_bytes.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>

#include "viscera/common/input_error.hpp"

namespace viscera::common {

namespace {
struct Close {
  // NOLINTNEXTLINE(cppcoreguidelines-owning-memory): the deleter of the unique_ptr that owns the file
  void operator()(std::FILE* f) const { std::fclose(f); }
};
}  // namespace

std::vector<std::uint8_t> read_file_bytes(const std::string& path, std::uint64_t max_bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path, 0, "", std::filesystem::exists(path, ec) ? "is not a regular file" : "no such file");
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, 0, "", "cannot read its size: " + ec.message());
  if (size > max_bytes) throw InputError(path, 0, "", std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) + " allowed");
  std::unique_ptr<std::FILE, Close> f(std::fopen(path.c_str(), "rb"));
  if (!f) throw InputError(path, 0, "", "cannot open the file");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  if (std::fread(bytes.data(), 1, bytes.size(), f.get()) != bytes.size()) throw InputError(path, 0, "", "cannot read the file");
  return bytes;
}

void write_file_bytes(const std::string& path, std::span<const std::uint8_t> bytes) {
  std::unique_ptr<std::FILE, Close> f(std::fopen(path.c_str(), "wb"));
  if (!f) throw InputError(path, 0, "", "cannot create the file");
  if (std::fwrite(bytes.data(), 1, bytes.size(), f.get()) != bytes.size() || std::fflush(f.get()) != 0)
    throw InputError(path, 0, "", "cannot write the file (disk full?)");
}

}  // namespace viscera::common
