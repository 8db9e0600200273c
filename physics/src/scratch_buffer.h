// Buffers that a step writes whole before it reads them (the rows, the packs, the pair records),
// sized without writing a byte, so that their memory is first touched by the team's threads that
// fill them; the large ones on 2 MB pages.
//
// A std::vector that grows value-initialises its new elements (a memset) and copies the old ones
// into the new storage, both on the stepping thread. While a pile lands its contacts grow every
// step, and the first write to each new 4 KB page is a page fault (about 5 us on a virtual
// machine): the falling pile of 4000 faulted in 70 MB that way over its first 1.5 s, about a
// millisecond a step, all of it serial (docs/PERFORMANCE.md, "The landing pile's page faults").
// Jolt allocates its step's memory from one block it keeps. Here a buffer of 4 MB or more is also
// asked to be backed by 2 MB pages (Linux's transparent huge pages, madvise): one fault per 2 MB,
// and fewer TLB misses while the sweeps stream through the packs. Where the kernel does not give
// them, the hint changes nothing.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tumble {

// std::allocator, but resize() leaves new elements unwritten. Only for types whose objects the
// allocation itself creates (implicit-lifetime aggregates with trivial destructors: C++20
// [intro.object]) and whose every element is assigned whole before it is read.
template <class T>
struct UninitializedAllocator {
  using value_type = T;
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  // Buffers of two large pages or more are laid out on whole ones (rounded up: less than a third
  // of the buffer wasted).
  static constexpr std::size_t kLargePage = std::size_t{2} << 20;
  static bool on_large_pages(std::size_t n) { return n * sizeof(T) >= 2 * kLargePage; }
  T* allocate(std::size_t n) {
    if (!on_large_pages(n)) return std::allocator<T>{}.allocate(n);
    if (n > std::allocator_traits<std::allocator<T>>::max_size(std::allocator<T>{}))
      throw std::bad_array_new_length();
    const std::size_t bytes = (n * sizeof(T) + kLargePage - 1) / kLargePage * kLargePage;
    void* p = ::operator new(bytes, std::align_val_t{kLargePage});
#ifdef MADV_HUGEPAGE
    madvise(p, bytes, MADV_HUGEPAGE);  // a hint: refused, the buffer keeps small pages
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (!on_large_pages(n)) return std::allocator<T>{}.deallocate(p, n);
    ::operator delete(p, std::align_val_t{kLargePage});
  }
  template <class U>
  void construct(U*) noexcept {
    static_assert(std::is_trivially_destructible_v<U> &&
                      (std::is_aggregate_v<U> || std::is_trivially_default_constructible_v<U>),
                  "left unwritten, an element must be an object its storage creates");
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const UninitializedAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using ScratchBuffer = std::vector<T, UninitializedAllocator<T>>;

// Sizes a buffer whose elements the caller then writes whole: growing, it drops what it held
// instead of copying it, and doubles its capacity at least, as std::vector does (a count that
// creeps up step after step reallocates rarely; grown by half, the falling pile of 1000 faulted
// in a quarter more pages than doubled).
template <class T>
void resize_for_overwrite(ScratchBuffer<T>& buffer, std::size_t size) {
  if (size > buffer.capacity()) {
    const std::size_t capacity = std::max(size, 2 * buffer.capacity());
    buffer.clear();
    buffer.reserve(capacity);
  }
  buffer.resize(size);
}

}  // namespace tumble
