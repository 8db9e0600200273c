#version 330 core
// Phong lighting (ambient, diffuse, specular) from one directional light, seen from the camera.
in vec3 world_position;
in vec3 world_normal;
in vec4 base_colour;
in float grid_spacing;

uniform vec3 camera_position;
uniform vec3 light_direction;  // towards the light, unit
uniform float ambient;
uniform float specular_strength;
uniform float shininess;

out vec4 fragment;

void main() {
  vec3 albedo = base_colour.rgb;
  if (grid_spacing > 0.0) {
    // Lines one pixel wide whatever the distance: the distance to the nearest line in cells,
    // over how many cells a pixel spans here.
    vec2 cell = world_position.xy / grid_spacing;
    vec2 per_pixel = max(fwidth(cell), vec2(1e-6));
    vec2 to_line = abs(fract(cell - 0.5) - 0.5) / per_pixel;
    float on_line = 1.0 - min(min(to_line.x, to_line.y), 1.0);
    // Far away, where lines would come closer than a few pixels, they fade out (no moire).
    on_line *= clamp(1.0 - (max(per_pixel.x, per_pixel.y) - 0.15) * 5.0, 0.0, 1.0);
    albedo *= 1.0 - 0.3 * on_line;
  }
  vec3 n = normalize(world_normal);
  vec3 to_camera = normalize(camera_position - world_position);
  float diffuse = max(dot(n, light_direction), 0.0);
  vec3 reflected = reflect(-light_direction, n);
  float specular = diffuse > 0.0 ? pow(max(dot(reflected, to_camera), 0.0), shininess) : 0.0;
  vec3 lit = albedo * (ambient + (1.0 - ambient) * diffuse) +
             vec3(specular_strength * specular);
  fragment = vec4(min(lit, vec3(1.0)), base_colour.a);
}
