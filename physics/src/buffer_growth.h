// Resizing the step's buffers without allocating in a warmed-up step.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace tumble {

// A buffer that a step fills to a count and then cuts to what it kept (the pairs, then the
// touching ones) is grown again the next step; std::vector grows to exactly the size asked when
// the increase exceeds its length, so a count that creeps up step after step, as a spreading
// pile's pairs do, would allocate and fault in the whole buffer every step. Growing by half its
// capacity at least makes that rare.
template <typename T>
void resize_reusing(std::vector<T>& buffer, std::size_t size) {
  if (size > buffer.capacity())
    buffer.reserve(std::max(size, buffer.capacity() + buffer.capacity() / 2));
  buffer.resize(size);
}

}  // namespace tumble
