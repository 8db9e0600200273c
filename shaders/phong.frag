#version 330 core
// Phong lighting (ambient, diffuse, specular) from one directional light, seen from the camera.
in vec3 world_position;
in vec3 world_normal;
in vec4 base_colour;

uniform vec3 camera_position;
uniform vec3 light_direction;  // towards the light, unit
uniform float ambient;
uniform float specular_strength;
uniform float shininess;

out vec4 fragment;

void main() {
  vec3 n = normalize(world_normal);
  vec3 to_camera = normalize(camera_position - world_position);
  float diffuse = max(dot(n, light_direction), 0.0);
  vec3 reflected = reflect(-light_direction, n);
  float specular = diffuse > 0.0 ? pow(max(dot(reflected, to_camera), 0.0), shininess) : 0.0;
  vec3 lit = base_colour.rgb * (ambient + (1.0 - ambient) * diffuse) +
             vec3(specular_strength * specular);
  fragment = vec4(min(lit, vec3(1.0)), base_colour.a);
}
