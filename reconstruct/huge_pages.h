// Large image buffers backed by transparent huge pages (Linux; elsewhere plain allocations).
//
// A 1080p RGB solve touches 25-50 MB buffers that are freshly mapped on every call (glibc serves
// them with mmap). With 4 KiB pages the first touch takes one page fault per 4 KiB: measured on
// a 2-core EPYC VM, touching 50 MB cost 200-300 ms with 4 KiB pages and 13 ms after
// madvise(MADV_HUGEPAGE) — more than the whole DCT pair of the L2 solve. Debian's default THP
// mode is "madvise", so the buffers have to ask for it before they are first written.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace gdpt::detail {

// Buffers below this size are left alone.
inline constexpr size_t kHugePageMinBytes = size_t(4) << 20;

// Best effort: marks the whole 4 KiB pages inside [p, p + bytes) for huge pages. Call it before
// the memory is first written (pages already faulted in stay small).
inline void advise_huge_pages(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kPage = 4096;
  if (bytes < kHugePageMinBytes) return;
  const uintptr_t begin = (uintptr_t(p) + kPage - 1) & ~(kPage - 1);
  const uintptr_t end = (uintptr_t(p) + bytes) & ~(kPage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

// v.resize(n) (value-initialised); a new allocation is advised for huge pages before it is zeroed.
template <class T>
void resize_huge(std::vector<T>& v, size_t n) {
  if (v.capacity() < n) {
    std::vector<T> fresh;
    fresh.reserve(n);
    advise_huge_pages(fresh.data(), n * sizeof(T));
    fresh.assign(v.begin(), v.end());
    v.swap(fresh);
  }
  v.resize(n);
}

template <class T>
std::vector<T> huge_vector(size_t n) {
  std::vector<T> v;
  resize_huge(v, n);
  return v;
}

}  // namespace gdpt::detail
