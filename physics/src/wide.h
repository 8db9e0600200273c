// Four doubles worked on at once: one lane per contact manifold in the packed contact solver
// (contact_packs.h), four columns of a row in Lemke's eliminations (lemke.cc). GCC's vector
// extensions give SSE2 pairs on a plain x86-64 build and one AVX register where the target has it;
// every operation is the scalar IEEE one lane by lane (contraction into fused multiply-adds is off
// for the whole build), so a lane computes the same bits as the scalar solver whatever the width of
// the machine.
#pragma once

#include <cstdint>

#include "physics/math.h"

// Always inlined, and so must be every helper that takes or returns one of these vectors: a
// function called out of line from an AVX2 clone (target_clones) passes a vector of four in a
// register, a plain one expects it in memory, and the two disagree (a crash seen in the sanitizer
// build, which inlines less). It also keeps the solver's small parts in its innermost loops.
#define TUMBLE_INLINE inline __attribute__((always_inline))

// The hot loops are built twice, for AVX2 and for any x86-64, and the loader picks one per
// machine (an ifunc). ThreadSanitizer instruments the ifunc's resolver, which the loader runs
// before the sanitizer's runtime has started, and the program died before main: a
// ThreadSanitizer build takes the portable loops alone.
#if defined(__x86_64__) && !defined(__SANITIZE_THREAD__)
#define TUMBLE_PER_CPU __attribute__((target_clones("avx2", "default")))
#else
#define TUMBLE_PER_CPU
#endif

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
// A 3-vector in every lane; lane k of a vector of them, in and out.
TUMBLE_INLINE WideVec3 broadcast(const Vec3& v) {
  return {wide(v.x()), wide(v.y()), wide(v.z())};
}
TUMBLE_INLINE void set_lane(WideVec3* wide_vector, int k, const Vec3& v) {
  wide_vector->x[k] = v.x();
  wide_vector->y[k] = v.y();
  wide_vector->z[k] = v.z();
}
TUMBLE_INLINE Vec3 lane_of(const WideVec3& wide_vector, int k) {
  return {wide_vector.x[k], wide_vector.y[k], wide_vector.z[k]};
}
TUMBLE_INLINE WideVec3 select(WideMask mask, const WideVec3& yes, const WideVec3& no) {
  return {select(mask, yes.x, no.x), select(mask, yes.y, no.y), select(mask, yes.z, no.z)};
}

}  // namespace tumble
