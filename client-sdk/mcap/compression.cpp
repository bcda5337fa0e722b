#include "viscera/mcap/compression.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <memory>
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

namespace {

/// Decompresses into a buffer that grows with what actually comes out (doubling from 1 MiB up to
/// one byte more than the chunk's header claims), so a forged size costs no memory and more
/// output than claimed is caught. `step(dst, capacity, &produced)` decompresses more into `dst`.
enum class Progress { more, done, stuck };  // stuck: neither input read nor output made
template <typename Step>
std::vector<std::uint8_t> grow_decompress(const char* name, std::uint64_t claim, Step step) {
  const std::size_t limit = static_cast<std::size_t>(claim) + 1;
  std::vector<std::uint8_t> out(std::min<std::size_t>(limit, std::size_t{1} << 20));
  std::size_t written = 0;
  for (Progress p = Progress::more; p == Progress::more;) {
    if (written == out.size()) {
      if (out.size() == limit) break;
      out.resize(std::min(limit, 2 * out.size()));
    }
    std::size_t produced = 0;
    p = step(out.data() + written, out.size() - written, &produced);
    written += produced;
  }
  if (written != claim)
    throw FormatError(std::string(name) + " chunk decompressed to " +
                      (written > claim ? "more than " + std::to_string(claim) : std::to_string(written)) + " bytes, its header says " +
                      std::to_string(claim));
  out.resize(written);
  return out;
}

}  // namespace

std::vector<std::uint8_t> decompress(const std::string& compression, std::span<const std::uint8_t> data, std::uint64_t uncompressed_size) {
  if (uncompressed_size > kMaxChunkBytes)
    throw FormatError("a chunk of " + std::to_string(uncompressed_size) + " bytes uncompressed is more than this reader takes (" +
                      std::to_string(kMaxChunkBytes) + ")");
  if (compression.empty()) {
    if (data.size() != uncompressed_size)
      throw FormatError("uncompressed chunk of " + std::to_string(data.size()) + " bytes, its header says " + std::to_string(uncompressed_size));
    return {data.begin(), data.end()};
  }
  if (compression == "zstd") {
    std::unique_ptr<ZSTD_DCtx, std::size_t (*)(ZSTD_DCtx*)> ctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
    if (!ctx) throw std::runtime_error("zstd: cannot create a context");
    ZSTD_inBuffer in{data.data(), data.size(), 0};
    bool input_left = true;
    auto out = grow_decompress("zstd", uncompressed_size, [&](std::uint8_t* dst, std::size_t capacity, std::size_t* produced) {
      ZSTD_outBuffer o{dst, capacity, 0};
      const std::size_t before = in.pos;
      const std::size_t r = ZSTD_decompressStream(ctx.get(), &o, &in);
      if (ZSTD_isError(r)) throw FormatError(std::string("zstd: ") + ZSTD_getErrorName(r));
      *produced = o.pos;
      input_left = in.pos < in.size;
      if (r == 0 && !input_left) return Progress::done;
      if (o.pos == 0 && in.pos == before) {
        if (r != 0) throw FormatError("zstd chunk: its frame is incomplete");
        return Progress::stuck;
      }
      return Progress::more;
    });
    if (input_left) throw FormatError("zstd chunk: bytes after its last frame");
    return out;
  }
  if (compression == "lz4") {
    LZ4F_dctx* raw = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) throw std::runtime_error("lz4: cannot create a context");
    std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> ctx(raw, LZ4F_freeDecompressionContext);
    std::size_t read = 0;
    return grow_decompress("lz4", uncompressed_size, [&](std::uint8_t* dst, std::size_t capacity, std::size_t* produced) {
      std::size_t src = data.size() - read;
      *produced = capacity;
      const std::size_t code = LZ4F_decompress(ctx.get(), dst, produced, data.data() + read, &src, nullptr);
      if (LZ4F_isError(code)) throw FormatError(std::string("lz4: ") + LZ4F_getErrorName(code));
      read += src;
      if (code == 0) return read == data.size() ? Progress::done : Progress::more;  // another frame may follow
      if (*produced == 0 && src == 0) throw FormatError("lz4 chunk: its frame is incomplete");
      return Progress::more;
    });
  }
  throw FormatError("compression '" + compression + "' is not zstd, lz4 or none");
}

}  // namespace viscera::mcap
