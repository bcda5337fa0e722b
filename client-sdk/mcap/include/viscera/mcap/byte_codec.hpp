#pragma once  // SPDX-License-Identifier: Apache-2.0
// Little-endian encoding of MCAP record fields, both ways. ByteReader checks every read against
// the bytes it has, so a truncated or corrupt record throws FormatError instead of reading past
// its end.
#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace viscera::mcap {

/// A record that does not parse: what, and where (the caller adds the file and offset).
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteWriter {
 public:
  std::vector<std::uint8_t>& bytes() { return bytes_; }
  void clear() { bytes_.clear(); }
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void u16(std::uint16_t v) { le(v); }
  void u32(std::uint32_t v) { le(v); }
  void u64(std::uint64_t v) { le(v); }
  void raw(std::span<const std::uint8_t> b) { bytes_.insert(bytes_.end(), b.begin(), b.end()); }
  void string(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  void bytes32(std::span<const std::uint8_t> b) {
    u32(static_cast<std::uint32_t>(b.size()));
    raw(b);
  }
  void string_map(const std::map<std::string, std::string>& m) {
    const std::size_t at = reserve32();
    for (const auto& [k, v] : m) {
      string(k);
      string(v);
    }
    patch32(at);
  }
  /// Starts a uint32 byte-length prefix; patch32 fills it with the bytes written since.
  std::size_t reserve32() {
    u32(0);
    return bytes_.size();
  }
  void patch32(std::size_t at) {
    const auto n = static_cast<std::uint32_t>(bytes_.size() - at);
    std::memcpy(bytes_.data() + at - 4, &n, 4);
  }
  /// Starts a record (opcode and a uint64 length); end_record fills the length.
  std::size_t begin_record(std::uint8_t opcode) {
    u8(opcode);
    u64(0);
    return bytes_.size();
  }
  void end_record(std::size_t at) {
    const auto n = static_cast<std::uint64_t>(bytes_.size() - at);
    std::memcpy(bytes_.data() + at - 8, &n, 8);
  }

 private:
  template <class T>
  void le(T v) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));  // the project's platforms are little-endian (x86-64, AArch64)
    bytes_.insert(bytes_.end(), b, b + sizeof(T));
  }
  std::vector<std::uint8_t> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> b) : b_(b) {}
  std::size_t position() const { return pos_; }
  std::size_t left() const { return b_.size() - pos_; }
  std::uint8_t u8() { return le<std::uint8_t>(); }
  std::uint16_t u16() { return le<std::uint16_t>(); }
  std::uint32_t u32() { return le<std::uint32_t>(); }
  std::uint64_t u64() { return le<std::uint64_t>(); }
  std::span<const std::uint8_t> raw(std::uint64_t n) {
    need(n, "bytes");
    const auto s = b_.subspan(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
  }
  std::string string() {
    const auto s = raw(u32());
    return std::string(s.begin(), s.end());
  }
  std::vector<std::uint8_t> bytes32() {
    const auto s = raw(u32());
    return {s.begin(), s.end()};
  }
  std::map<std::string, std::string> string_map() {
    ByteReader inner(raw(u32()));
    std::map<std::string, std::string> m;
    while (inner.left() > 0) {
      std::string k = inner.string();
      m[std::move(k)] = inner.string();
    }
    return m;
  }
  std::span<const std::uint8_t> rest() { return raw(left()); }

 private:
  void need(std::uint64_t n, const char* what) const {
    if (n > left())
      throw FormatError(std::string("truncated: ") + what + " of " + std::to_string(n) + " bytes with " + std::to_string(left()) + " left");
  }
  template <class T>
  T le() {
    need(sizeof(T), "integer");
    T v;
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
};

}  // namespace viscera::mcap
