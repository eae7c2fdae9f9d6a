// Counting replacements of every global allocation function, for "no heap allocation" tests.
//
// All global operator new/delete overloads are replaced; on glibc, malloc/calloc/realloc/memalign/
// posix_memalign/aligned_alloc are interposed as well (Eigen allocates with malloc, not operator new;
// an executable's definitions take precedence over libc's for every shared object, so allocations
// inside shared libraries such as KDL are counted too). allocCounts() returns the running totals.
//
// Replacement allocation functions may not be inline: include this header in exactly ONE
// translation unit of a test executable.
#pragma once

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_new_calls{0};
std::atomic<long> g_malloc_calls{0};

void* countedNew(std::size_t n) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  if (n == 0) n = 1;
  void* p = std::malloc(n);
  if (!p) throw std::bad_alloc();
  return p;
}

void* countedNewAligned(std::size_t n, std::align_val_t al) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  std::size_t a = static_cast<std::size_t>(al);
  if (a < sizeof(void*)) a = sizeof(void*);
  if (n == 0) n = 1;
  void* p = nullptr;
  if (posix_memalign(&p, a, n) != 0) throw std::bad_alloc();
  return p;
}
}  // namespace

// ---- counting replacements of the global allocation functions ----
void* operator new(std::size_t n) {
  return countedNew(n);
}
void* operator new[](std::size_t n) {
  return countedNew(n);
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return countedNew(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return countedNew(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) {
  return countedNewAligned(n, a);
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return countedNewAligned(n, a);
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return countedNewAligned(n, a);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return countedNewAligned(n, a);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}

#if defined(__GLIBC__)
#define VERESHCHAGIN_TEST_COUNT_MALLOC 1
// Interpose the C allocator (the executable's definitions take precedence over libc's for every
// shared object); forward to glibc's internal entry points.
extern "C" {
void* __libc_malloc(std::size_t);
void __libc_free(void*);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t n) noexcept {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void free(void* p) noexcept {
  __libc_free(p);
}
void* calloc(std::size_t a, std::size_t b) noexcept {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(a, b);
}
void* realloc(void* p, std::size_t n) noexcept {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) noexcept {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) noexcept {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) noexcept {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_memalign(a, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}
#else
#define VERESHCHAGIN_TEST_COUNT_MALLOC 0
#endif

namespace testutil {
struct AllocCounts {
  long news, mallocs;
  long total() const { return news + mallocs; }
};
// Allocations so far: operator new calls and (on glibc) malloc-family calls.
inline AllocCounts allocCounts() {
  return {g_new_calls.load(), g_malloc_calls.load()};
}
}  // namespace testutil
