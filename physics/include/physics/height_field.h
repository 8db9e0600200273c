// A heightfield: terrain given as a grid of heights, solid below its surface. Static only.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "physics/math.h"
#include "physics/status.h"

namespace tumble {

// Samples x rows: heights[j * samples_x + i] is the surface's z at
//   x = (i - (samples_x - 1) / 2) * spacing_x,  y = (j - (samples_y - 1) / 2) * spacing_y
// so the grid is centred on its frame's origin. Each cell is two triangles split along its
// diagonal from (i, j) to (i + 1, j + 1). The solid reaches down to `base()`, one cell spacing
// below the lowest height.
// samples_x, samples_y: each 2 to kMaxHeightFieldSide, their product at most
// kMaxHeightFieldSamples (each step's contact search and every query visit cells, and a snapshot
// carries every height); spacing: m, > 0; heights: m, finite, |h| <= kMaxHeightFieldHeight.
inline constexpr std::uint32_t kMaxHeightFieldSide = 8192;
inline constexpr std::size_t kMaxHeightFieldSamples = std::size_t{1} << 22;  // 4,194,304
inline constexpr double kMaxHeightFieldHeight = 1e6;
inline constexpr double kMaxHeightFieldSpacing = 1e4;
struct HeightFieldDef {
  std::uint32_t samples_x = 0, samples_y = 0;
  double spacing_x = 1, spacing_y = 1;
  std::vector<double> heights;
};

// rad: a convex edge whose two triangles turn by less than this is taken as smooth, and only the
// faces on either side touch what lies on it. A body resting across it can sink into the ridge by
// at most half its length times half this angle (2.2 cm for a 1 m box across a 5 degree ridge);
// in return, bodies on gently curved terrain meet faces alone, whose contacts hold still from
// step to step, and no edge is met by GJK where a face would do. Jolt's active edge threshold
// (5 degrees). Measured on the pile of 1000 on the hills (docs/PERFORMANCE.md, "Terrain"): at
// 0.5 degrees 4 boxes dipped over 1 cm (23 mm deepest), at 5 none (9.4 mm, the plane's own).
inline constexpr double kSmoothEdgeAngle = 5 * 3.14159265358979323846 / 180;

// The built heightfield, immutable and shared by the shapes made of it.
class HeightField {
 public:
  // The message names the bad field ("heights[17]: must be finite").
  static Result<HeightField> create(const HeightFieldDef& def);

  const HeightFieldDef& def() const { return def_; }
  std::uint32_t cells_x() const { return def_.samples_x - 1; }
  std::uint32_t cells_y() const { return def_.samples_y - 1; }
  std::size_t triangle_count() const { return 2 * std::size_t{cells_x()} * cells_y(); }
  double min_height() const { return min_height_; }
  double max_height() const { return max_height_; }
  double base() const { return base_; }
  Aabb bounds() const;

  double height(std::uint32_t i, std::uint32_t j) const {
    return def_.heights[std::size_t{j} * def_.samples_x + i];
  }
  Vec3 sample(std::uint32_t i, std::uint32_t j) const {
    return {(i - 0.5 * (def_.samples_x - 1)) * def_.spacing_x,
            (j - 0.5 * (def_.samples_y - 1)) * def_.spacing_y, height(i, j)};
  }
  // Triangle t = 2 * (j * cells_x + i) + k of cell (i, j): k = 0 is (i,j), (i+1,j), (i+1,j+1);
  // k = 1 is (i,j), (i+1,j+1), (i,j+1); both counter-clockwise seen from above.
  std::array<Vec3, 3> triangle(std::size_t t) const;
  // Bit e set: the triangle's edge from its vertex e to vertex e+1 is convex (its neighbour across
  // it slopes away below its plane) or on the boundary. Only such edges may give a contact a
  // normal other than the triangle's own (docs/COLLISION.md, "Heightfields").
  std::uint8_t active_edges(std::size_t t) const { return edge_bits_[t] & 7u; }
  // Bit e set: that edge is convex but turns by no more than kSmoothEdgeAngle (not active): a
  // sphere's or capsule's core can lie beyond both its triangles' feet, where only the edge holds
  // it (docs/COLLISION.md).
  std::uint8_t gentle_edges(std::size_t t) const { return edge_bits_[t] >> 3; }
  // The triangle across edge e of t, or -1 on the boundary.
  std::int64_t neighbour(std::size_t t, int e) const;

  // The surface's height over (x, y) in the field's frame (the nearest edge's beyond the grid).
  double height_at(double x, double y) const;
  // The cells whose columns meet the box (the heightfield's frame), clamped to the grid; false if
  // none do.
  bool cells_under(const Aabb& box, std::uint32_t* i0, std::uint32_t* j0, std::uint32_t* i1,
                   std::uint32_t* j1) const;

 private:
  HeightFieldDef def_;
  double min_height_ = 0, max_height_ = 0, base_ = 0;
  std::vector<std::uint8_t> edge_bits_;  // active edges in bits 0-2, gentle ones in bits 3-5
};

}  // namespace tumble
