// Four doubles worked on at once: one lane per contact manifold in the packed contact solver
// (contact_packs.h), four columns of a row in Lemke's eliminations (lemke.cc). GCC's vector
// extensions give SSE2 pairs on a plain x86-64 build and one AVX register where the target has it;
// every operation is the scalar IEEE one lane by lane (contraction into fused multiply-adds is off
// for the whole build), so a lane computes the same bits as the scalar solver whatever the width of
// the machine.
#pragma once

#include <cstdint>

// Always inlined: a vector of four doubles passed to an out-of-line function goes through memory
// on a build without AVX, and the solver's small parts are called in its innermost loops.
#define TUMBLE_INLINE inline __attribute__((always_inline))

// GCC warns that passing these vectors by value has another ABI with AVX than without; every
// function taking or returning one is inlined, so no call passes them.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace tumble {

constexpr int kWideLanes = 4;

// Aligned to their size on every target: GCC would align them to 16 bytes where AVX is off and
// to 32 where it is on, and the solver's AVX clone shares its structs with the rest.
using Wide = double __attribute__((vector_size(kWideLanes * sizeof(double)), aligned(32)));
// A comparison's result: all bits set in the lanes where it holds.
using WideMask =
    std::int64_t __attribute__((vector_size(kWideLanes * sizeof(double)), aligned(32)));

TUMBLE_INLINE Wide wide(double value) {
  return Wide{value, value, value, value};
}

// One blend instruction with AVX (packs are swept only there: packed_sweeps()).
TUMBLE_INLINE Wide select(WideMask mask, Wide yes, Wide no) {
  return mask ? yes : no;
}
// std::max's and std::abs's results lane by lane, including which operand a tie or a signed zero
// returns (max(a, b) is b only when a < b).
TUMBLE_INLINE Wide wide_max(Wide a, Wide b) {
  return select(a < b, b, a);
}
TUMBLE_INLINE Wide wide_abs(Wide a) {
  return reinterpret_cast<Wide>(reinterpret_cast<WideMask>(a) & INT64_MAX);
}
TUMBLE_INLINE bool any(WideMask mask) {
  return (mask[0] | mask[1] | mask[2] | mask[3]) != 0;
}
// The largest lane, in lane order as a scalar loop over std::max would take it.
TUMBLE_INLINE double largest_lane(Wide a) {
  double largest = a[0];
  for (int k = 1; k < kWideLanes; ++k)
    largest = largest < a[k] ? a[k] : largest;
  return largest;
}

struct WideVec3 {
  Wide x, y, z;
};

TUMBLE_INLINE WideVec3 operator+(const WideVec3& a, const WideVec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
TUMBLE_INLINE WideVec3 operator-(const WideVec3& a, const WideVec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
// Summed in Eigen's order for a 3-vector, (x + y) + z, so that lanes match the scalar solver.
TUMBLE_INLINE Wide dot(const WideVec3& a, const WideVec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
// a - s b and a + s b, component by component.
TUMBLE_INLINE WideVec3 minus_scaled(const WideVec3& a, Wide s, const WideVec3& b) {
  return {a.x - s * b.x, a.y - s * b.y, a.z - s * b.z};
}
TUMBLE_INLINE WideVec3 plus_scaled(const WideVec3& a, Wide s, const WideVec3& b) {
  return {a.x + s * b.x, a.y + s * b.y, a.z + s * b.z};
}
TUMBLE_INLINE WideVec3 select(WideMask mask, const WideVec3& yes, const WideVec3& no) {
  return {select(mask, yes.x, no.x), select(mask, yes.y, no.y), select(mask, yes.z, no.z)};
}

}  // namespace tumble
