#include "viscera/common/file_bytes.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include <sys/stat.h>
#include <unistd.h>

#include <fcntl.h>

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
  // O_NONBLOCK: opening a FIFO with no reader would block for ever; it is refused below.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
  if (fd < 0) {
    const int e = errno;
    if (e == ELOOP) throw InputError(path, 0, "", "is a symbolic link: an output is never written through one (remove it, or name another path)");
    if (e == EISDIR) throw InputError(path, 0, "", "is a directory");
    if (e == ENXIO) throw InputError(path, 0, "", "is not a regular file: an output is written to a file only");  // a FIFO no one reads
    throw InputError(path, 0, "", std::string("cannot create the file: ") + std::strerror(e));
  }
  struct Fd {
    int fd;
    ~Fd() {
      if (fd >= 0) ::close(fd);
    }
  } guard{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) throw InputError(path, 0, "", "is not a regular file: an output is written to a file only");
  if (::ftruncate(fd, 0) != 0) throw InputError(path, 0, "", std::string("cannot truncate the file: ") + std::strerror(errno));
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw InputError(path, 0, "", std::string("cannot write the file: ") + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
  guard.fd = -1;
  if (::close(fd) != 0) throw InputError(path, 0, "", std::string("cannot write the file: ") + std::strerror(errno));
}

void create_output_folder(const std::string& dir, const std::string& what) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir, 0, what, "cannot create the folder: " + ec.message());
  if (!std::filesystem::is_directory(dir, ec)) throw InputError(dir, 0, what, "is not a folder");
}

void write_file_text(const std::string& path, std::string_view text) {
  write_file_bytes(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

}  // namespace viscera::common
