// Turns a fuzzer's byte string into typed values: a small deterministic reader that never fails
// (past the end it returns zeros), so every byte string is a valid test case.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace fuzzutil {

class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }

  std::uint64_t u64() {
    std::uint64_t v = 0;
    for (int k = 0; k < 8; ++k) v = (v << 8) | byte();
    return v;
  }

  // Integer in [lo, hi] (hi - lo < 256).
  int integer(int lo, int hi) { return lo + byte() % (hi - lo + 1); }

  // Uniform in [lo, hi] at 16-bit resolution.
  double unit(double lo, double hi) {
    const unsigned v = (static_cast<unsigned>(byte()) << 8) | byte();
    return lo + (hi - lo) * (v / 65535.0);
  }

  // A double meant to exercise every regime: mostly plausible values in [lo, hi], sometimes the
  // same scaled by 10^e (e in [-12, 12]), exact zeros, and occasionally any bit pattern (NaN, Inf,
  // subnormals, 1e308).
  double value(double lo, double hi) {
    const std::uint8_t mode = byte();
    if (mode < 180) return unit(lo, hi);
    if (mode < 220) return unit(lo, hi) * std::pow(10.0, integer(-12, 12));
    if (mode < 240) return 0.0;
    const std::uint64_t bits = u64();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }

  std::size_t remaining() const { return pos_ < size_ ? size_ - pos_ : 0; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace fuzzutil
