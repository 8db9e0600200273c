// Triangles from the common mesh files (OBJ, STL, PLY and the others Assimp reads), as plain
// arrays: free of the engine's types, so that programs that link none of the engine (the CLI)
// read them too. scenes/mesh_file.h gives the engine's TriangleMeshDef.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace tumble::mesh_files {

// Files larger than this are refused before they are read: a mesh of two million triangles takes
// about 100 MB as binary STL, and text formats take several times the bytes.
inline constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{512} << 20;

struct Arrays {
  std::vector<double> xyz;               // x, y, z of each vertex (m, after scale)
  std::vector<std::uint32_t> triangles;  // three vertex indices each
};

// Every mesh of the file, with its nodes' transforms applied, as one: polygons split into
// triangles, shared corners joined, triangles of no area and points and lines left out; `scale`
// multiplies every coordinate (files are often in cm or mm). The file's axes are kept. Refused,
// naming the file, past max_vertices or max_triangles (before they are copied). Returns "" or the
// error.
std::string read(const std::string& path, double scale, std::size_t max_vertices,
                 std::size_t max_triangles, Arrays* out);

}  // namespace tumble::mesh_files
