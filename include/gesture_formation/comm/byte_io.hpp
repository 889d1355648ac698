#pragma once
/// \file
/// \brief Bounds-checked big-endian (network order) serialisation primitives used by the
/// envelope and the payload codecs (docs/security.md §3). Doubles travel as their IEEE-754
/// binary64 bit pattern, big-endian. Thread safety: none; one instance per thread.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace gesture_formation::comm {

/// \brief Appends big-endian fields to a byte vector.
class ByteWriter {
 public:
  void u8(std::uint8_t v) { buffer_.push_back(v); }
  void u16(std::uint16_t v) { putBigEndian(v, 2); }
  void u32(std::uint32_t v) { putBigEndian(v, 4); }
  void u64(std::uint64_t v) { putBigEndian(v, 8); }
  void f64(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    putBigEndian(bits, 8);
  }
  void bytes(const std::uint8_t* data, std::size_t size) { buffer_.insert(buffer_.end(), data, data + size); }

  std::size_t size() const { return buffer_.size(); }
  const std::vector<std::uint8_t>& buffer() const { return buffer_; }
  std::vector<std::uint8_t> release() { return std::move(buffer_); }

 private:
  void putBigEndian(std::uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) buffer_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t> buffer_;
};

/// \brief Reads big-endian fields from a borrowed buffer. Every read checks the remaining
/// length first; a read past the end returns false, leaves the output untouched and makes
/// the reader `failed()` for good (later reads fail too).
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool u8(std::uint8_t& v) {
    std::uint64_t x = 0;
    if (!getBigEndian(x, 1)) return false;
    v = static_cast<std::uint8_t>(x);
    return true;
  }
  bool u16(std::uint16_t& v) {
    std::uint64_t x = 0;
    if (!getBigEndian(x, 2)) return false;
    v = static_cast<std::uint16_t>(x);
    return true;
  }
  bool u32(std::uint32_t& v) {
    std::uint64_t x = 0;
    if (!getBigEndian(x, 4)) return false;
    v = static_cast<std::uint32_t>(x);
    return true;
  }
  bool u64(std::uint64_t& v) { return getBigEndian(v, 8); }
  /// Raw binary64; the caller decides whether non-finite values are acceptable.
  bool f64(double& v) {
    std::uint64_t bits = 0;
    if (!getBigEndian(bits, 8)) return false;
    std::memcpy(&v, &bits, sizeof v);
    return true;
  }
  /// A pointer to the next `size` bytes (borrowed), advancing past them.
  bool bytes(std::size_t size, const std::uint8_t*& out) {
    if (failed_ || size > remaining()) {
      failed_ = true;
      return false;
    }
    out = data_ + pos_;
    pos_ += size;
    return true;
  }

  std::size_t remaining() const { return size_ - pos_; }
  std::size_t position() const { return pos_; }
  bool failed() const { return failed_; }

 private:
  bool getBigEndian(std::uint64_t& v, std::size_t bytes) {
    if (failed_ || bytes > remaining()) {
      failed_ = true;
      return false;
    }
    std::uint64_t x = 0;
    for (std::size_t i = 0; i < bytes; ++i) x = (x << 8) | data_[pos_ + i];
    pos_ += bytes;
    v = x;
    return true;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

}  // namespace gesture_formation::comm
