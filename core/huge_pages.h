// Large fresh buffers backed by transparent huge pages (Linux; elsewhere plain allocations).
//
// The first touch of fresh memory costs one page fault per 4 KB page. Debian's default THP mode
// is `madvise`, so a buffer has to ask for huge pages before it is first written. Advised, such
// buffers fault once per 2 MB, which matters at full HD (bench_integrator 0 film measures it).
// Header-only: the core, the reconstruction library and the Python module share it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace gdpt {

inline constexpr size_t kHugePageBytes = size_t(2) << 20;

// Asks the kernel to back the whole 2 MB pages inside [data, data + bytes) with huge pages; call
// it before anything touches them. A no-op for buffers without a whole 2 MB page inside.
inline void advise_huge_pages([[maybe_unused]] const void* data, [[maybe_unused]] size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = kHugePageBytes;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

// Memory for `bytes`, aligned to `alignment` (a power of two up to kHugePageBytes): buffers of
// 2 MB and more start on a 2 MB boundary, so every page of them can be a huge page, and are
// advised. Release with free_huge(). Throws std::bad_alloc.
inline void* allocate_huge(size_t bytes, size_t alignment = alignof(std::max_align_t)) {
  const size_t align =
      bytes >= kHugePageBytes ? kHugePageBytes : std::max(alignment, alignof(std::max_align_t));
  // aligned_alloc wants a size that is a multiple of the alignment.
  const size_t size = std::max((bytes + align - 1) & ~(align - 1), align);
  void* p = std::aligned_alloc(align, size);
  if (!p) throw std::bad_alloc();
  advise_huge_pages(p, bytes);
  return p;
}
inline void free_huge(void* p) noexcept {
  std::free(p);
}

// A std allocator over allocate_huge(), for large per-pixel vectors (films, pass read-outs).
template <typename T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(size_t n) {
    if (n > size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(allocate_huge(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, size_t) noexcept { free_huge(p); }
  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

// HugePageAllocator whose resize() leaves new elements default-initialised (for arithmetic types:
// unwritten): a buffer written in full by a parallel loop is then first touched, and its pages
// faulted, by the threads that write it, instead of by a serial zero fill.
template <typename T>
struct FreshHugePageAllocator : HugePageAllocator<T> {
  template <typename U>
  struct rebind {
    using other = FreshHugePageAllocator<U>;
  };
  FreshHugePageAllocator() = default;
  template <typename U>
  FreshHugePageAllocator(const FreshHugePageAllocator<U>&) noexcept {}
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0)
      ::new (static_cast<void*>(p)) U;
    else
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using FreshHugeVector = std::vector<T, FreshHugePageAllocator<T>>;

// For plain std::vectors (APIs that hand them on): an empty vector with room for n elements, its
// fresh pages advised (filled later without a zero fill); v.resize(n), a new allocation advised
// before it is zeroed; and a vector of n value-initialised elements made so.
template <class T>
void reserve_fresh(std::vector<T>& v, size_t n) {
  v.clear();
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
}
template <class T>
void resize_huge(std::vector<T>& v, size_t n) {
  if (v.capacity() < n) {
    std::vector<T> fresh;
    reserve_fresh(fresh, n);
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

}  // namespace gdpt
