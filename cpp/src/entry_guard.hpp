// Detection of two threads inside one solver object (hd_solver.hpp, "Threads"): every method
// that writes the object takes the object's flag at entry (acquire) and gives it back at exit
// (release); a call that finds it taken is refused with E_CONCURRENT_CALL without touching the
// object. The flag is not a lock: nobody waits, so the solve path stays bounded and allocation-free.
#pragma once

#include <atomic>

namespace vereshchagin {
namespace detail {

class EntryGuard {
 public:
  explicit EntryGuard(std::atomic<bool>& busy)
      : busy_(busy), entered_(!busy.exchange(true, std::memory_order_acquire)) {}
  ~EntryGuard() {
    if (entered_) busy_.store(false, std::memory_order_release);
  }
  EntryGuard(const EntryGuard&) = delete;
  EntryGuard& operator=(const EntryGuard&) = delete;
  // False: another thread is inside a call on the object; do not touch it.
  explicit operator bool() const { return entered_; }

 private:
  std::atomic<bool>& busy_;
  const bool entered_;
};

}  // namespace detail
}  // namespace vereshchagin
