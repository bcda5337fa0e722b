#include "viscera/mcap/compression.hpp"

#include <stdexcept>

#include <lz4frame.h>
#include <zstd.h>

#include "viscera/mcap/byte_codec.hpp"

namespace viscera::mcap {

std::vector<std::uint8_t> compress(const std::string& compression, std::span<const std::uint8_t> data) {
  if (compression.empty()) return {data.begin(), data.end()};
  if (compression == "zstd") {
    std::vector<std::uint8_t> out(ZSTD_compressBound(data.size()));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3);  // level 3: zstd's default
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
  }
  if (compression == "lz4") {
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.contentSize = data.size();
    std::vector<std::uint8_t> out(LZ4F_compressFrameBound(data.size(), &prefs));
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), &prefs);
    if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
    out.resize(n);
    return out;
  }
  throw std::invalid_argument("compression '" + compression + "' is not zstd, lz4 or none");
}

std::vector<std::uint8_t> decompress(const std::string& compression, std::span<const std::uint8_t> data, std::uint64_t uncompressed_size) {
  if (uncompressed_size > (std::uint64_t{1} << 34))
    throw FormatError("a chunk of " + std::to_string(uncompressed_size) + " bytes uncompressed is not plausible");
  std::vector<std::uint8_t> out(static_cast<std::size_t>(uncompressed_size));
  if (compression.empty()) {
    if (data.size() != uncompressed_size)
      throw FormatError("uncompressed chunk of " + std::to_string(data.size()) + " bytes, its header says " + std::to_string(uncompressed_size));
    return {data.begin(), data.end()};
  }
  if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(n)) throw FormatError(std::string("zstd: ") + ZSTD_getErrorName(n));
    if (n != uncompressed_size)
      throw FormatError("zstd chunk decompressed to " + std::to_string(n) + " bytes, its header says " + std::to_string(uncompressed_size));
    return out;
  }
  if (compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw std::runtime_error("lz4: cannot create a context");
    std::size_t written = 0, read = 0;
    std::size_t code = 1;
    while (code != 0 && read < data.size() && written <= out.size()) {
      std::size_t dst = out.size() - written, src = data.size() - read;
      code = LZ4F_decompress(ctx, out.data() + written, &dst, data.data() + read, &src, nullptr);
      if (LZ4F_isError(code)) {
        LZ4F_freeDecompressionContext(ctx);
        throw FormatError(std::string("lz4: ") + LZ4F_getErrorName(code));
      }
      written += dst;
      read += src;
      if (dst == 0 && src == 0) break;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (code != 0 || written != uncompressed_size)
      throw FormatError("lz4 chunk decompressed to " + std::to_string(written) + " bytes (frame " + (code ? "incomplete" : "complete") +
                        "), its header says " + std::to_string(uncompressed_size));
    return out;
  }
  throw FormatError("compression '" + compression + "' is not zstd, lz4 or none");
}

}  // namespace viscera::mcap
