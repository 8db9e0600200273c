// Draws bodies as Phong-lit instanced meshes with an OpenGL 3.3 core context that the front end
// made current (OSMesa off screen, or a GLFW window). Knows nothing of the engine: it is given
// meshes, and per frame a model matrix and colour per instance.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "gl.h"
#include "mesh.h"

namespace tumble::viewer {

struct Camera {
  Eigen::Vector3f eye{8, -12, 6}, target{0, 0, 1}, up{0, 0, 1};  // m, z up
  float fov_y_degrees = 45, near_plane = 0.05f, far_plane = 1000;
  Eigen::Matrix4f view() const;
  Eigen::Matrix4f projection(float aspect) const;
};

struct Instance {
  Eigen::Matrix4f model = Eigen::Matrix4f::Identity();  // mesh space to world
  Eigen::Vector4f colour{0.8f, 0.8f, 0.8f, 1};          // linear RGBA in [0, 1]
  // x: spacing (m) of grid lines drawn on the surface in world x and y (the ground); 0: none.
  Eigen::Vector4f material = Eigen::Vector4f::Zero();
};

struct Lighting {
  Eigen::Vector3f towards_light = Eigen::Vector3f(0.3f, -0.5f, 1).normalized();
  float ambient = 0.25f, specular = 0.35f, shininess = 32;
  Eigen::Vector3f background{0.62f, 0.72f, 0.82f};
};

class Renderer {
 public:
  explicit Renderer(const Gl& gl) : gl_(gl) {}
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Compiles the shaders (the compiler's log on failure) and uploads the built-in meshes.
  bool init(std::string* error);
  // A mesh for later draws; its handle.
  int add_mesh(const Mesh& mesh);
  int box_mesh() const { return box_; }
  int sphere_mesh() const { return sphere_; }
  int ground_mesh() const { return ground_; }

  // instances[m]: the instances of mesh m this frame (missing or empty: not drawn).
  // `overlay` (by mesh, as `instances`) is drawn over everything else: markers that must show
  // inside a pile.
  void draw(const std::vector<std::vector<Instance>>& instances, const Camera& camera,
            const Lighting& lighting, int width, int height,
            const std::vector<std::vector<Instance>>& overlay = {});

 private:
  struct GpuMesh {
    GLuint vertex_array = 0, vertices = 0, indices = 0, instances = 0;
    GLsizei index_count = 0;
  };
  const Gl& gl_;
  GLuint program_ = 0;
  std::vector<GpuMesh> meshes_;
  int box_ = -1, sphere_ = -1, ground_ = -1;
};

}  // namespace tumble::viewer
