// Scenes: a world's settings and initial bodies, read from JSON (docs/SCENES.md lists every
// field with its unit) or made by the standard generators (standard.h).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "physics/body.h"
#include "physics/status.h"
#include "physics/world.h"

namespace tumble {

// A joint of a scene: its definition, with the bodies named by their place in the scene's list
// (JointDef's ids are filled in when the world is made).
struct SceneJoint {
  JointDef def;
  std::size_t a = 0;
  std::optional<std::size_t> b;  // none: the world
};

struct SceneDef {
  std::string name = "unnamed";
  WorldSettings world;
  double dt = 1.0 / 60;  // s per step
  double duration = 10;  // s: how long a run of the scene lasts unless told otherwise
  std::vector<BodyDef> bodies;
  std::vector<SceneJoint> joints;
};

// Parses and validates a whole scene; nothing partial comes back. Errors name the field's path,
// e.g. "bodies[3].size[1]: must be > 0".
// With `max_bodies`, a scene of more bodies (or of more JSON values than such a scene needs) is
// refused as RESOURCE_EXHAUSTED after a counting pass that builds nothing, before it is parsed.
inline constexpr std::size_t kNoBodyLimit = static_cast<std::size_t>(-1);
// With `max_bodies`, a scene of more than this many joints per allowed body is refused too.
inline constexpr std::size_t kJointsPerBody = 2;
Result<SceneDef> parse_scene(std::string_view json_text, std::size_t max_bodies = kNoBodyLimit);
// Reads a file and parses it; errors start with the file's path.
Result<SceneDef> load_scene_file(const std::string& path);
// The scene as JSON that parse_scene reads back to the same scene (numbers round-trip exactly).
std::string scene_to_json(const SceneDef& scene);

// A world with the scene's settings, bodies and joints.
Result<World> make_world(const SceneDef& scene);

// The scene built into every binary: boxes falling on a floor.
std::string_view default_scene_json();

}  // namespace tumble
