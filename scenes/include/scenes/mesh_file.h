// Triangle meshes for the engine from the common mesh files (scenes/mesh_file_reader.h reads
// them).
#pragma once

#include <string>

#include "physics/shape.h"
#include "physics/status.h"
#include "physics/triangle_mesh.h"

namespace tumble {

// The file's triangles (mesh_files::read: every mesh with its transforms, polygons split, shared
// corners joined, triangles of no area left out; `scale` multiplies every coordinate; the file's
// axes kept, so a y-up file is turned z-up by the body's orientation). Errors name the file. The
// counts are checked against the engine's limits; the rest (a degenerate triangle Assimp let
// through) where the mesh is built, TriangleMesh::create.
Result<TriangleMeshDef> read_mesh_file(const std::string& path, double scale = 1);

// A hull of the file's vertices, read as read_mesh_file reads them: every vertex up to
// kMaxHullPoints, past that the farthest towards each of kMaxHullPoints directions spread over
// the sphere (mesh_files::hull_point_indices). Errors name the file; the hull is built, and its
// own errors named, by Shape::create.
Result<HullDef> read_hull_file(const std::string& path, double scale = 1);

}  // namespace tumble
