#version 330 core
// One mesh drawn once per instance: each instance brings its model matrix and colour.
layout(location = 0) in vec3 position;  // mesh space
layout(location = 1) in vec3 normal;
layout(location = 2) in mat4 model;     // locations 2..5
layout(location = 6) in vec4 colour;
layout(location = 7) in vec4 material;  // x: grid spacing (m), 0 for none

uniform mat4 view_projection;

out vec3 world_position;
out vec3 world_normal;
out vec4 base_colour;
out float grid_spacing;

void main() {
  vec4 world = model * vec4(position, 1.0);
  world_position = world.xyz;
  // Models are rotations, translations and per-axis scales: the inverse transpose keeps normals
  // perpendicular to scaled faces.
  world_normal = normalize(transpose(inverse(mat3(model))) * normal);
  base_colour = colour;
  grid_spacing = material.x;
  gl_Position = view_projection * world;
}
