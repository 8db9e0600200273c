// The step's scratch buffers (physics/src/scratch_buffer.h): sizing one writes none of its
// elements, so their memory is first written by the threads that fill them; growing one drops
// what it held instead of copying it; large ones start on 2 MB pages.
#include <gtest/gtest.h>

#include <cstdint>

#include "scratch_buffer.h"

namespace tumble::testing {
namespace {

struct Record {
  double value = 1.5;  // a default a std::vector would write into every new element
  std::uint32_t id = 7;
};

// Cut and grown again within its capacity, a buffer still holds what was written there: no
// element was initialised on the way (a std::vector<Record> would hold 1.5 and 7 again).
TEST(ScratchBuffer, SizingWithinItsCapacityWritesNoElement) {
  ScratchBuffer<Record> buffer;
  resize_for_overwrite(buffer, 100);
  for (std::size_t i = 0; i < buffer.size(); ++i)
    buffer[i] = {static_cast<double>(i), static_cast<std::uint32_t>(i)};
  const Record* storage = buffer.data();
  resize_for_overwrite(buffer, 10);
  resize_for_overwrite(buffer, 100);
  ASSERT_EQ(buffer.data(), storage);
  for (std::size_t i = 0; i < buffer.size(); ++i) {
    EXPECT_EQ(buffer[i].value, static_cast<double>(i));
    EXPECT_EQ(buffer[i].id, i);
  }
}

// Past its capacity it doubles at least, so a count that creeps up step after step reallocates
// rarely. What it held is dropped, not copied: its callers write every element.
TEST(ScratchBuffer, GrowingDoublesItsCapacityAtLeast) {
  ScratchBuffer<Record> buffer;
  resize_for_overwrite(buffer, 1000);
  const std::size_t capacity = buffer.capacity();
  ASSERT_GE(capacity, 1000u);
  resize_for_overwrite(buffer, capacity + 1);
  EXPECT_GE(buffer.capacity(), 2 * capacity);
  EXPECT_EQ(buffer.size(), capacity + 1);
  resize_for_overwrite(buffer, 10 * capacity);
  EXPECT_EQ(buffer.size(), 10 * capacity);
}

// Copies and push_back keep their values: only sizing leaves elements unwritten.
TEST(ScratchBuffer, PushBackAndCopiesKeepValues) {
  ScratchBuffer<Record> buffer;
  for (std::uint32_t i = 0; i < 5000; ++i)
    buffer.push_back({0.5 * i, i});
  const ScratchBuffer<Record> copy = buffer;
  ASSERT_EQ(copy.size(), 5000u);
  for (std::uint32_t i = 0; i < 5000; ++i) {
    EXPECT_EQ(copy[i].value, 0.5 * i);
    EXPECT_EQ(copy[i].id, i);
  }
}

// A buffer of two large pages or more starts on one, where the kernel can back it with them; a
// small one is an ordinary allocation.
TEST(ScratchBuffer, LargeBuffersStartOnLargePages) {
  constexpr std::size_t kLargePage = UninitializedAllocator<Record>::kLargePage;
  ScratchBuffer<Record> large;
  resize_for_overwrite(large, 2 * kLargePage / sizeof(Record) + 1);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % kLargePage, 0u);
  large[large.size() - 1] = {2.5, 3};  // the rounded-up allocation holds every element
  EXPECT_EQ(large.back().id, 3u);
  ScratchBuffer<Record> small;
  resize_for_overwrite(small, 10);
  EXPECT_EQ(small.capacity(), 10u);
}

}  // namespace
}  // namespace tumble::testing
