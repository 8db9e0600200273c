// What a Shape is made of, as World::save_state writes it (state_format.cc). Private to the
// engine with the rest of the state format.
#pragma once

#include <memory>

#include "physics/compound.h"
#include "physics/math.h"
#include "physics/polyhedron.h"
#include "physics/shape.h"

namespace tumble {

// Everything a Shape is made of, for saving a world and restoring it bit for bit (the radii
// derived from it are recomputed).
struct ShapeState {
  ShapeType type = ShapeType::kSphere;
  double radius = 0, half_height = 0;
  Vec3 half_extents = Vec3::Zero();
  std::shared_ptr<const ConvexPolyhedron> polyhedron;  // hulls only (a box rebuilds its own)
  std::shared_ptr<const HeightFieldDef> height_field;  // heightfields only
  std::shared_ptr<const TriangleMeshDef> mesh;         // meshes only
  // Compounds only: their parts, each built from its own state (of_parts checks the poses).
  std::shared_ptr<const Compound> compound;
};

}  // namespace tumble
