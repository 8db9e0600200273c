#include "renderer.h"

#include <cmath>
#include <numbers>

#include "shaders.h"

namespace tumble::viewer {
namespace {

// The instance buffer is the Instance array itself: 16 floats of matrix, 4 of colour, 4 of
// material.
static_assert(sizeof(Instance) == 24 * sizeof(float));

GLuint compile(const Gl& gl, GLenum kind, const char* source, std::string* error) {
  const GLuint shader = gl.CreateShader(kind);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    *error = std::string(kind == GL_VERTEX_SHADER ? "phong.vert: " : "phong.frag: ") + log;
    gl.DeleteShader(shader);
    return 0;
  }
  return shader;
}

}  // namespace

Eigen::Matrix4f Camera::view() const {
  const Eigen::Vector3f forward = (target - eye).normalized();
  const Eigen::Vector3f right = forward.cross(up).normalized();
  const Eigen::Vector3f true_up = right.cross(forward);
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<1, 3>(0, 0) = right.transpose();
  m.block<1, 3>(1, 0) = true_up.transpose();
  m.block<1, 3>(2, 0) = -forward.transpose();
  m(0, 3) = -right.dot(eye);
  m(1, 3) = -true_up.dot(eye);
  m(2, 3) = forward.dot(eye);
  return m;
}

Eigen::Matrix4f Camera::projection(float aspect) const {
  const float f = 1.0f / std::tan(fov_y_degrees * std::numbers::pi_v<float> / 360);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
  m(2, 3) = 2 * far_plane * near_plane / (near_plane - far_plane);
  m(3, 2) = -1;
  return m;
}

Renderer::~Renderer() {
  for (GpuMesh& mesh : meshes_) {
    const GLuint buffers[] = {mesh.vertices, mesh.indices, mesh.instances};
    gl_.DeleteBuffers(3, buffers);
    gl_.DeleteVertexArrays(1, &mesh.vertex_array);
  }
  if (program_ != 0) gl_.DeleteProgram(program_);
}

bool Renderer::init(std::string* error) {
  const GLuint vertex = compile(gl_, GL_VERTEX_SHADER, kPhongVertexShader, error);
  if (vertex == 0) return false;
  const GLuint fragment = compile(gl_, GL_FRAGMENT_SHADER, kPhongFragmentShader, error);
  if (fragment == 0) {
    gl_.DeleteShader(vertex);
    return false;
  }
  program_ = gl_.CreateProgram();
  gl_.AttachShader(program_, vertex);
  gl_.AttachShader(program_, fragment);
  gl_.LinkProgram(program_);
  gl_.DeleteShader(vertex);
  gl_.DeleteShader(fragment);
  GLint linked = 0;
  gl_.GetProgramiv(program_, GL_LINK_STATUS, &linked);
  if (!linked) {
    char log[2048] = {};
    gl_.GetProgramInfoLog(program_, sizeof log, nullptr, log);
    *error = std::string("phong program: ") + log;
    return false;
  }
  box_ = add_mesh(unit_box());
  sphere_ = add_mesh(unit_sphere());
  ground_ = add_mesh(ground_square(1));
  return true;
}

int Renderer::add_mesh(const Mesh& mesh) {
  GpuMesh gpu;
  gl_.GenVertexArrays(1, &gpu.vertex_array);
  gl_.BindVertexArray(gpu.vertex_array);
  GLuint buffers[3];
  gl_.GenBuffers(3, buffers);
  gpu.vertices = buffers[0];
  gpu.indices = buffers[1];
  gpu.instances = buffers[2];
  gl_.BindBuffer(GL_ARRAY_BUFFER, gpu.vertices);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(float)),
                 mesh.vertices.data(), GL_STATIC_DRAW);
  gl_.EnableVertexAttribArray(0);
  gl_.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  gl_.EnableVertexAttribArray(1);
  gl_.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
  gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.indices);
  gl_.BufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t)),
                 mesh.indices.data(), GL_STATIC_DRAW);
  gpu.index_count = static_cast<GLsizei>(mesh.indices.size());
  // Per instance: a column-major 4x4 model matrix (4 attributes) and a colour.
  gl_.BindBuffer(GL_ARRAY_BUFFER, gpu.instances);
  constexpr GLsizei stride = sizeof(Instance);
  for (GLuint column = 0; column < 4; ++column) {
    gl_.EnableVertexAttribArray(2 + column);
    gl_.VertexAttribPointer(2 + column, 4, GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<void*>(column * 4 * sizeof(float)));
    gl_.VertexAttribDivisor(2 + column, 1);
  }
  gl_.EnableVertexAttribArray(6);
  gl_.VertexAttribPointer(6, 4, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<void*>(16 * sizeof(float)));
  gl_.VertexAttribDivisor(6, 1);
  gl_.EnableVertexAttribArray(7);
  gl_.VertexAttribPointer(7, 4, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<void*>(20 * sizeof(float)));
  gl_.VertexAttribDivisor(7, 1);
  gl_.BindVertexArray(0);
  meshes_.push_back(gpu);
  return static_cast<int>(meshes_.size()) - 1;
}

void Renderer::draw(const std::vector<std::vector<Instance>>& instances, const Camera& camera,
                    const Lighting& lighting, int width, int height,
                    const std::vector<std::vector<Instance>>& overlay) {
  gl_.Viewport(0, 0, width, height);
  gl_.ClearColor(lighting.background.x(), lighting.background.y(), lighting.background.z(), 1);
  gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl_.Enable(GL_DEPTH_TEST);
  gl_.UseProgram(program_);
  const Eigen::Matrix4f view_projection =
      camera.projection(static_cast<float>(width) / static_cast<float>(height)) * camera.view();
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(program_, "view_projection"), 1, GL_FALSE,
                       view_projection.data());
  gl_.Uniform3f(gl_.GetUniformLocation(program_, "camera_position"), camera.eye.x(), camera.eye.y(),
                camera.eye.z());
  const Eigen::Vector3f light = lighting.towards_light.normalized();
  gl_.Uniform3f(gl_.GetUniformLocation(program_, "light_direction"), light.x(), light.y(),
                light.z());
  gl_.Uniform1f(gl_.GetUniformLocation(program_, "ambient"), lighting.ambient);
  gl_.Uniform1f(gl_.GetUniformLocation(program_, "specular_strength"), lighting.specular);
  gl_.Uniform1f(gl_.GetUniformLocation(program_, "shininess"), lighting.shininess);
  const auto draw_all = [&](const std::vector<std::vector<Instance>>& by_mesh) {
    for (std::size_t m = 0; m < by_mesh.size() && m < meshes_.size(); ++m) {
      if (by_mesh[m].empty()) continue;
      const GpuMesh& mesh = meshes_[m];
      gl_.BindVertexArray(mesh.vertex_array);
      gl_.BindBuffer(GL_ARRAY_BUFFER, mesh.instances);
      gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(by_mesh[m].size() * sizeof(Instance)),
                     by_mesh[m].data(), GL_STREAM_DRAW);
      gl_.DrawElementsInstanced(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr,
                                static_cast<GLsizei>(by_mesh[m].size()));
    }
  };
  draw_all(instances);
  if (!overlay.empty()) {
    // Over everything drawn so far, still depth-tested among themselves.
    gl_.Clear(GL_DEPTH_BUFFER_BIT);
    draw_all(overlay);
  }
  gl_.BindVertexArray(0);
}

}  // namespace tumble::viewer
