// Buffers that a step writes whole before it reads them (the rows, the packs), sized without
// writing a byte: their memory is first touched by the team's threads that fill them.
//
// A std::vector that grows value-initialises its new elements (a memset) and copies the old ones
// into the new storage, both on the stepping thread. While a pile lands its contacts grow every
// step, and the first write to each new page is a page fault (about 5 us on a virtual machine):
// the falling pile of 4000 faulted in 70 MB that way over its first 1.5 s, a millisecond a step
// of serial time, more than Jolt's whole step on 16 threads (docs/PERFORMANCE.md, "Beside
// Jolt"). Jolt avoids it by allocating its step's memory from one block it keeps.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

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
  T* allocate(std::size_t n) { return std::allocator<T>{}.allocate(n); }
  void deallocate(T* p, std::size_t n) noexcept { std::allocator<T>{}.deallocate(p, n); }
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
// instead of copying it, and grows by half its capacity at least (a count that creeps up step
// after step reallocates rarely).
template <class T>
void resize_for_overwrite(ScratchBuffer<T>& buffer, std::size_t size) {
  if (size > buffer.capacity()) {
    const std::size_t capacity = std::max(size, buffer.capacity() + buffer.capacity() / 2);
    buffer.clear();
    buffer.reserve(capacity);
  }
  buffer.resize(size);
}

}  // namespace tumble
