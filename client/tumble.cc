// tumble: the command-line client. Spawns and removes bodies, steers the run, saves and restores
// the world, and streams frames to stdout as JSON lines or CSV, or into a recording to replay.
//   tumble --server 127.0.0.1:50051 spawn box --size 1,1,1 --mass 2 --pos 0,0,5
//   tumble stream --format jsonl --frames 100
// `tumble COMMAND --help` describes each command.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string_view>
#include <thread>

#include "client.h"
#include "frame_format.h"
#include "recording.h"
#include "scenes/hull_points.h"
#include "scenes/mesh_file_reader.h"
#include "tumble/command_line.h"

using namespace tumble;
using tumble::wire::Result;
using tumble::wire::Status;

namespace {

int fail(const std::string& what, const Status& status) {
  std::fprintf(stderr, "tumble: %s: %s\n", what.c_str(), status.message().c_str());
  return 1;
}

void set_vec(const std::vector<double>& v, v1::Vec3* out) {
  out->set_x(v[0]);
  out->set_y(v[1]);
  out->set_z(v[2]);
}

void print_line(const std::string& text) {
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fputc('\n', stdout);
}

Result<std::string> read_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Status::error(path + ": cannot open");
  std::stringstream bytes;
  bytes << file.rdbuf();
  return std::move(bytes).str();
}

struct SpawnOptions {
  std::string shape;
  std::vector<double> size{1, 1, 1}, position{0, 0, 0}, velocity{0, 0, 0}, spin{0, 0, 0};
  double radius = 0.5, half_height = 0.5, mass = 0;
  std::uint32_t colour = 0;
  bool is_static = false;
  bool is_kinematic = false;
  std::string heights_file;  // heightfield: rows of heights (read by read_heights)
  std::vector<double> spacing{1, 1};
  v1::HeightField height_field;
  std::string mesh_file;  // mesh: an OBJ, STL, PLY, ... file (read by read_mesh_file)
  double mesh_scale = 1;
  v1::Mesh mesh;
  std::vector<std::string> parts;  // compound: "box:1,1,0.1@0,0,1[@w,x,y,z]" each
  v1::Compound compound;
  std::vector<std::string> points;  // hull: "x,y,z" each
  v1::Hull hull;
  std::optional<double> gravity_scale, linear_damping, angular_damping;
  std::vector<double> force, torque;
  std::optional<std::uint32_t> layers, mask;

  v1::BodySpec spec() const {
    v1::BodySpec spec;
    if (shape == "box") {
      set_vec(size, spec.mutable_shape()->mutable_box()->mutable_size());
    } else if (shape == "sphere") {
      spec.mutable_shape()->mutable_sphere()->set_radius(radius);
    } else if (shape == "heightfield") {
      *spec.mutable_shape()->mutable_heightfield() = height_field;
      spec.mutable_shape()->mutable_heightfield()->set_spacing_x(spacing[0]);
      spec.mutable_shape()->mutable_heightfield()->set_spacing_y(spacing[1]);
      spec.set_type(v1::BODY_TYPE_STATIC);
    } else if (shape == "mesh") {
      *spec.mutable_shape()->mutable_mesh() = mesh;
      spec.set_type(v1::BODY_TYPE_STATIC);
    } else if (shape == "compound") {
      *spec.mutable_shape()->mutable_compound() = compound;
    } else if (shape == "hull") {
      *spec.mutable_shape()->mutable_hull() = hull;
    } else {
      spec.mutable_shape()->mutable_capsule()->set_radius(radius);
      spec.mutable_shape()->mutable_capsule()->set_half_height(half_height);
    }
    if (mass > 0) spec.set_mass(mass);
    if (is_static) spec.set_type(v1::BODY_TYPE_STATIC);
    if (is_kinematic) spec.set_type(v1::BODY_TYPE_KINEMATIC);
    set_vec(position, spec.mutable_position());
    set_vec(velocity, spec.mutable_linear_velocity());
    set_vec(spin, spec.mutable_angular_velocity());
    spec.set_color(colour);
    if (gravity_scale) spec.set_gravity_scale(*gravity_scale);
    if (linear_damping) spec.set_linear_damping(*linear_damping);
    if (angular_damping) spec.set_angular_damping(*angular_damping);
    if (!force.empty()) set_vec(force, spec.mutable_force());
    if (!torque.empty()) set_vec(torque, spec.mutable_torque());
    if (layers) spec.set_collision_layers(*layers);
    if (mask) spec.set_collision_mask(*mask);
    return spec;
  }
};

// The most samples a heightfield may have (the engine's kMaxHeightFieldSamples: the server refuses
// more); reading stops there, so a huge file is not read whole.
constexpr int kMaxHeightSamples = 1 << 22;
// The most vertices and triangles a mesh may have (the engine's kMaxMeshVertices and
// kMaxMeshTriangles: the server refuses more).
constexpr std::size_t kMaxMeshVertices = std::size_t{1} << 21;
constexpr std::size_t kMaxMeshTriangles = std::size_t{1} << 21;
// The most points a hull may be given (the engine's kMaxHullPoints: the server refuses more).
constexpr std::size_t kMaxHullPoints = mesh_files::kMaxHullInputPoints;

// A heightfield's heights from a text file: one row of samples along x per line, the rows along
// y from the lowest y up, numbers parted by spaces or commas; blank lines and lines starting with
// '#' skipped. The message names the file and the line.
Status read_heights(const std::string& path, v1::HeightField* out) {
  std::ifstream file(path);
  if (!file) return Status::error(path + ": cannot open");
  std::string line;
  int number = 0;
  while (std::getline(file, line)) {
    ++number;
    std::replace(line.begin(), line.end(), ',', ' ');
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream words(line);
    std::string word;
    std::uint32_t count = 0;
    while (words >> word) {
      char* end = nullptr;
      const double value = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0')
        return Status::error(path + ":" + std::to_string(number) + ": '" + word +
                             "' is not a number");
      out->add_heights(value);
      ++count;
      if (out->heights_size() > kMaxHeightSamples)
        return Status::error(path + ": more than the " + std::to_string(kMaxHeightSamples) +
                             " samples a heightfield may have");
    }
    if (out->samples_y() == 0) out->set_samples_x(count);
    if (count != out->samples_x())
      return Status::error(path + ":" + std::to_string(number) + ": " + std::to_string(count) +
                           " heights, the first row has " + std::to_string(out->samples_x()));
    out->set_samples_y(out->samples_y() + 1);
  }
  return Status::ok();
}

// Numbers parted by commas ("1,0.5,2"); false on anything else.
bool read_numbers(const std::string& text, std::vector<double>* out) {
  out->clear();
  std::istringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) return false;
    out->push_back(value);
  }
  return !text.empty() && text.back() != ',';
}

// A compound's part from --part: "box:SX,SY,SZ", "sphere:R" or "capsule:R,HALF_HEIGHT", then
// "@X,Y,Z" (m, in the body's frame) and optionally "@W,X,Y,Z" (its orientation). The server
// checks the sizes; this only reads the numbers and names the part that does not parse.
Status read_part(const std::string& text, std::size_t index, v1::CompoundPart* out) {
  const std::string field = "--part[" + std::to_string(index) + "]";
  const std::string usage = field + ": '" + text +
                            "' is not KIND:SIZES@X,Y,Z[@W,X,Y,Z] (box:SX,SY,SZ, sphere:R or "
                            "capsule:R,HALF_HEIGHT)";
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) return Status::error(usage);
  const std::string kind = text.substr(0, colon);
  std::vector<std::string> pieces;
  std::istringstream rest(text.substr(colon + 1));
  for (std::string piece; std::getline(rest, piece, '@');)
    pieces.push_back(piece);
  if (pieces.size() < 2 || pieces.size() > 3) return Status::error(usage);
  std::vector<double> sizes, at, turn;
  if (!read_numbers(pieces[0], &sizes) || !read_numbers(pieces[1], &at) || at.size() != 3 ||
      (pieces.size() == 3 && (!read_numbers(pieces[2], &turn) || turn.size() != 4)))
    return Status::error(usage);
  if (kind == "box" && sizes.size() == 3) {
    set_vec(sizes, out->mutable_shape()->mutable_box()->mutable_size());
  } else if (kind == "sphere" && sizes.size() == 1) {
    out->mutable_shape()->mutable_sphere()->set_radius(sizes[0]);
  } else if (kind == "capsule" && sizes.size() == 2) {
    out->mutable_shape()->mutable_capsule()->set_radius(sizes[0]);
    out->mutable_shape()->mutable_capsule()->set_half_height(sizes[1]);
  } else {
    return Status::error(usage);
  }
  set_vec(at, out->mutable_position());
  if (!turn.empty()) {
    out->mutable_orientation()->set_w(turn[0]);
    out->mutable_orientation()->set_x(turn[1]);
    out->mutable_orientation()->set_y(turn[2]);
    out->mutable_orientation()->set_z(turn[3]);
  }
  return Status::ok();
}

// A compound's --part options into its parts; --part belongs to a compound only.
Status read_parts(SpawnOptions* options) {
  if (options->shape != "compound") {
    if (!options->parts.empty()) return Status::error("--part: only a compound has parts");
    return Status::ok();
  }
  if (options->parts.empty())
    return Status::error("--part: a compound needs at least one (KIND:SIZES@X,Y,Z)");
  for (std::size_t i = 0; i < options->parts.size(); ++i)
    if (Status s = read_part(options->parts[i], i, options->compound.add_parts()); !s) return s;
  return Status::ok();
}

// A hull of a mesh file's vertices: all of them up to kMaxHullPoints, past that the farthest
// towards each of kMaxHullPoints directions (mesh_files::hull_point_indices), said on stderr.
Status read_hull_file(SpawnOptions* options) {
  mesh_files::Arrays mesh;
  if (std::string error = mesh_files::read(options->mesh_file, options->mesh_scale,
                                           kMaxMeshVertices, kMaxMeshTriangles, &mesh);
      !error.empty())
    return Status::error("--file: " + error);
  const std::size_t vertices = mesh.xyz.size() / 3;
  const std::vector<std::size_t> kept = mesh_files::hull_point_indices(mesh.xyz, kMaxHullPoints);
  if (kept.size() < vertices)
    std::fprintf(stderr,
                 "%s: %zu vertices, more than the %zu a hull may be given: its hull is made of the "
                 "%zu farthest towards %zu directions spread over the sphere\n",
                 options->mesh_file.c_str(), vertices, kMaxHullPoints, kept.size(), kMaxHullPoints);
  for (std::size_t i : kept)
    for (int k = 0; k < 3; ++k)
      options->hull.add_points(mesh.xyz[3 * i + k]);
  return Status::ok();
}

// A hull's --point options (or --file) into its points; --point belongs to a hull only, --file to
// a hull or a mesh. The server builds the hull and names what is wrong with it (fewer than four
// points spanning a volume).
Status read_points(SpawnOptions* options) {
  if (!options->mesh_file.empty() && options->shape != "hull" && options->shape != "mesh")
    return Status::error("--file: only a hull or a mesh comes from a file");
  if (options->shape != "hull") {
    if (!options->points.empty()) return Status::error("--point: only a hull has points");
    return Status::ok();
  }
  if (!options->mesh_file.empty()) {
    if (!options->points.empty())
      return Status::error("--file: a hull comes from --point or from --file, not both");
    return read_hull_file(options);
  }
  if (options->points.empty())
    return Status::error("--point: a hull needs its points (X,Y,Z each, at least four), or --file");
  if (options->points.size() > kMaxHullPoints)
    return Status::error("--point: " + std::to_string(options->points.size()) +
                         " points, more than the " + std::to_string(kMaxHullPoints) +
                         " a hull may have");
  for (std::size_t i = 0; i < options->points.size(); ++i) {
    std::vector<double> xyz;
    if (!read_numbers(options->points[i], &xyz) || xyz.size() != 3)
      return Status::error("--point[" + std::to_string(i) + "]: '" + options->points[i] +
                           "' is not X,Y,Z");
    for (double value : xyz)
      options->hull.add_points(value);
  }
  return Status::ok();
}

// The options a shape spawn, overlap and cast share lists: a compound's parts, a hull's points.
Status read_listed_shape(SpawnOptions* options) {
  if (Status s = read_parts(options); !s) return s;
  return read_points(options);
}

// The shape's options spawn and overlap share; spawn also takes terrain.
void add_shape_options(CLI::App* command, SpawnOptions* options, bool terrain = false) {
  const std::vector<std::string> shapes =
      terrain ? std::vector<std::string>{"box",         "sphere", "capsule", "hull",
                                         "heightfield", "mesh",   "compound"}
              : std::vector<std::string>{"box", "sphere", "capsule", "hull", "compound"};
  command
      ->add_option("shape", options->shape,
                   terrain ? "box, sphere, capsule, hull, heightfield, mesh or compound"
                           : "box, sphere, capsule, hull or compound")
      ->required()
      ->check(CLI::IsMember(shapes));
  if (terrain) {
    command
        ->add_option("--heights", options->heights_file,
                     "heightfield: a text file of heights (m), one row along x a line, rows "
                     "from the lowest y up")
        ->check(cli::existing_file);
    command->add_option("--spacing", options->spacing, "heightfield: x,y between samples (m)")
        ->delimiter(',')
        ->expected(2);
  }
  command
      ->add_option("--file", options->mesh_file,
                   std::string(terrain ? "mesh: a mesh file (OBJ, STL, PLY and the others Assimp "
                                         "reads); its triangles face the side their corners run "
                                         "counter-clockwise from. "
                                       : "") +
                       "hull: the convex hull of a mesh file's vertices (past 1024 of them, of "
                       "the farthest towards 1024 directions spread over the sphere)")
      ->check(cli::existing_file);
  command->add_option("--scale", options->mesh_scale,
                      "mesh, hull: multiplies every coordinate of the file (0.01 for cm)");
  command->add_option("--part", options->parts,
                      "compound: one part, KIND:SIZES@X,Y,Z[@W,X,Y,Z] (box:SX,SY,SZ, sphere:R or "
                      "capsule:R,HALF_HEIGHT at X,Y,Z in the body's frame); repeat for each");
  command->add_option("--point", options->points,
                      "hull: one point X,Y,Z (m, in the body's frame; the body is their convex "
                      "hull); repeat for each, at least four");
  command->add_option("--size", options->size, "box: full extents x,y,z (m)")
      ->delimiter(',')
      ->expected(3);
  command->add_option("--radius", options->radius, "sphere, capsule: radius (m)");
  command->add_option("--half-height", options->half_height, "capsule: half the core length (m)");
}

// The options spawn and set-state share: what acts on a body beyond gravity and contacts, and
// its collision filter.
void add_body_force_options(CLI::App* command, std::optional<double>* gravity_scale,
                            std::optional<double>* linear_damping,
                            std::optional<double>* angular_damping, std::vector<double>* force,
                            std::vector<double>* torque, std::optional<std::uint32_t>* layers,
                            std::optional<std::uint32_t>* mask) {
  command->add_option("--gravity-scale", *gravity_scale, "the world's gravity times this acts on it");
  command->add_option("--linear-damping", *linear_damping, "1/s: v -> v / (1 + c dt) each step");
  command->add_option("--angular-damping", *angular_damping, "1/s, as --linear-damping");
  command->add_option("--force", *force, "x,y,z (N, world): held every step until changed")
      ->delimiter(',')
      ->expected(3);
  command->add_option("--torque", *torque, "x,y,z (N m, world): held every step until changed")
      ->delimiter(',')
      ->expected(3);
  command->add_option("--layers", *layers, "collision layers the body is in (bits; default 1)");
  command->add_option("--mask", *mask,
                      "collision layers it collides with (bits; default 4294967295, all)");
}

struct StreamOptions {
  std::string format = "jsonl";
  std::uint64_t frames = 0;
  double rate = 0;
  bool velocities = false, contacts = false, stats = false, joints = false;
  std::vector<std::uint64_t> ids;
  bool changes_only = false;
  double full_every = 0;

  void add_to(CLI::App* command, bool with_format) {
    if (with_format)
      command->add_option("--format", format, "jsonl or csv")
          ->check(CLI::IsMember({"jsonl", "csv"}));
    command->add_option("--frames", frames, "stop after this many frames (0: until interrupted)");
    command->add_option("--rate", rate, "at most this many frames per second (0: every step)")
        ->check(cli::non_negative);
    command->add_flag("--velocities", velocities, "include velocities");
    command->add_flag("--contacts", contacts, "include contact points");
    command->add_flag("--stats", stats, "include the step statistics");
    command->add_flag("--joints", joints, "include every joint's state and the joints' catalogue");
    command->add_option("--ids", ids, "only these bodies (default: all)")->delimiter(',');
    command->add_flag("--changes-only", changes_only,
                      "list only the bodies changed since the previous frame (the first frame, "
                      "and the first after the world is replaced, list all)");
    command
        ->add_option("--full-every", full_every,
                     "with --changes-only: a frame of every body at least every this many "
                     "seconds (0: only when needed)")
        ->check(cli::non_negative);
  }
  v1::StreamFramesRequest request() const {
    v1::StreamFramesRequest request;
    request.set_max_rate(rate);
    request.set_velocities(velocities);
    request.set_contacts(contacts);
    request.set_stats(stats);
    request.set_joints(joints);
    request.mutable_ids()->Add(ids.begin(), ids.end());
    request.set_changes_only(changes_only);
    request.set_full_frame_interval(full_every);
    return request;
  }
};

void print_frame(const v1::Frame& frame, const StreamOptions& options) {
  if (options.format == "csv")
    std::fputs(client::frame_to_csv_rows(frame, options.velocities).c_str(), stdout);
  else
    print_line(client::frame_to_json_line(frame));
  std::fflush(stdout);
}

// "exact" for SOLVER_KIND_EXACT: the enum's own names, lowercase, without the prefix.
std::string solver_name(v1::SolverKind kind) {
  std::string name = v1::SolverKind_Name(kind);
  name.erase(0, std::string_view("SOLVER_KIND_").size());
  for (char& c : name)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

std::optional<v1::SolverKind> solver_kind(const std::string& name) {
  if (name == "exact") return v1::SOLVER_KIND_EXACT;
  if (name == "pgs") return v1::SOLVER_KIND_PGS;
  if (name == "soft") return v1::SOLVER_KIND_SOFT;
  if (name == "auto") return v1::SOLVER_KIND_AUTO;
  return std::nullopt;
}

// A joint's motor (speed, max_force) and spring (target, stiffness, damping) from the CLI's lists.
void put_motor(const std::vector<double>& m, v1::JointMotor* out) {
  out->set_speed(m[0]);
  out->set_max_force(m[1]);
}
void put_spring(const std::vector<double>& s, v1::JointSpring* out) {
  out->set_target(s[0]);
  out->set_stiffness(s[1]);
  out->set_damping(s[2]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tumble: talks to a tumble-server (spawn, remove, control, stream, record)."};
  cli::keep_conventions(app, "tumble");
  app.require_subcommand(1);
  client::Connection connection;
  app.add_option("--server", connection.address, "the server's address")->envname("TUMBLE_SERVER");
  app.add_option("--token", connection.token, "bearer token, when the server asks for one")
      ->envname("TUMBLE_TOKEN");
  app.add_option("--tls-ca", connection.tls_ca_file,
                 "use TLS, trusting the certificate authority in this PEM file")
      ->envname("TUMBLE_TLS_CA");

  CLI::App* info = app.add_subcommand("info", "the server's version, step, time and bodies");
  CLI::App* health =
      app.add_subcommand("health", "the standard gRPC health check; exit 0 when serving");

  CLI::App* spawn = app.add_subcommand("spawn", "add one body; prints its id");
  SpawnOptions body;
  add_shape_options(spawn, &body, true);
  spawn->add_option("--mass", body.mass, "kg (default: from a density of 1000 kg/m^3)");
  spawn->add_option("--position,--pos", body.position, "x,y,z (m)")->delimiter(',')->expected(3);
  spawn->add_option("--linear-velocity,--vel", body.velocity, "x,y,z (m/s)")
      ->delimiter(',')
      ->expected(3);
  spawn->add_option("--angular-velocity,--spin", body.spin, "x,y,z (rad/s)")
      ->delimiter(',')
      ->expected(3);
  spawn->add_option("--color", body.colour, "drawing colour 0xRRGGBBAA (0: the viewer's choice)");
  auto* still = spawn->add_flag("--static", body.is_static, "a body that never moves");
  spawn
      ->add_flag("--kinematic", body.is_kinematic,
                 "a body moved only by its velocity (--velocity, --spin; set-state changes it), "
                 "which pushes dynamic bodies and is never pushed back")
      ->excludes(still);
  add_body_force_options(spawn, &body.gravity_scale, &body.linear_damping, &body.angular_damping,
                         &body.force, &body.torque, &body.layers, &body.mask);

  CLI::App* spawn_scene = app.add_subcommand("spawn-scene", "replace the world with a scene file");
  std::string scene_file;
  spawn_scene->add_option("file", scene_file, "a scene (JSON, docs/SCENES.md)")
      ->required()
      ->check(cli::existing_file);

  CLI::App* remove = app.add_subcommand("remove", "remove bodies by id");
  std::vector<std::uint64_t> ids;
  remove->add_option("ids", ids, "body ids, by spaces or commas")->required()->delimiter(',');

  CLI::App* bodies = app.add_subcommand("bodies", "bodies' states as JSON lines");
  bodies->add_option("ids", ids, "body ids, by spaces or commas (default: all)")->delimiter(',');

  CLI::App* set_state =
      app.add_subcommand("set-state", "replace a body's position, orientation or velocities");
  std::uint64_t body_id = 0;
  std::vector<double> position, orientation, linear_velocity, angular_velocity;
  set_state->add_option("id", body_id, "the body's id")->required();
  set_state->add_option("--position,--pos", position, "x,y,z (m)")->delimiter(',')->expected(3);
  set_state->add_option("--orientation", orientation, "a unit quaternion w,x,y,z")
      ->delimiter(',')
      ->expected(4);
  set_state->add_option("--linear-velocity,--vel", linear_velocity, "x,y,z (m/s)")
      ->delimiter(',')
      ->expected(3);
  set_state->add_option("--angular-velocity,--spin", angular_velocity, "x,y,z (rad/s)")
      ->delimiter(',')
      ->expected(3);
  std::optional<double> gravity_scale, linear_damping, angular_damping;
  std::vector<double> force, torque, force_point;
  std::optional<std::uint32_t> layers, mask;
  add_body_force_options(set_state, &gravity_scale, &linear_damping, &angular_damping, &force,
                         &torque, &layers, &mask);
  set_state
      ->add_option("--force-point", force_point,
                   "x,y,z (m, world): where --force acts (the torque becomes its moment)")
      ->delimiter(',')
      ->expected(3);

  CLI::App* ray = app.add_subcommand("ray", "cast a ray: the bodies it meets, as JSON lines");
  std::vector<double> ray_origin, ray_direction;
  double ray_max_distance = 1000;
  std::optional<std::uint32_t> ray_mask;
  std::uint32_t ray_hits = 0;
  ray->add_option("--origin,--from", ray_origin, "x,y,z (m, world)")
      ->required()
      ->delimiter(',')
      ->expected(3);
  ray->add_option("--direction,--dir", ray_direction, "x,y,z (any length but zero)")
      ->required()
      ->delimiter(',')
      ->expected(3);
  ray->add_option("--max-distance", ray_max_distance, "m (default 1000)");
  ray->add_option("--mask", ray_mask, "meet only bodies in these collision layers (bits)");
  ray->add_option("--hits", ray_hits, "up to this many hits, nearest first (default: the nearest)");

  CLI::App* overlap =
      app.add_subcommand("overlap", "the bodies a shape placed in the world overlaps, as JSON");
  SpawnOptions probe;
  add_shape_options(overlap, &probe);
  overlap->add_option("--position,--pos", probe.position, "x,y,z (m)")
      ->delimiter(',')
      ->expected(3);
  std::optional<std::uint32_t> overlap_mask;
  overlap->add_option("--mask", overlap_mask, "meet only bodies in these collision layers (bits)");

  CLI::App* cast = app.add_subcommand(
      "cast", "sweep a shape along a straight path: the first body it meets, as JSON");
  SpawnOptions swept;
  add_shape_options(cast, &swept);
  cast->add_option("--position,--pos", swept.position, "x,y,z (m): where the sweep starts")
      ->delimiter(',')
      ->expected(3);
  std::vector<double> cast_orientation, cast_translation;
  cast->add_option("--orientation", cast_orientation, "w,x,y,z (the shape does not turn)")
      ->delimiter(',')
      ->expected(4);
  cast->add_option("--translation,--by", cast_translation, "x,y,z (m, world): the sweep")
      ->required()
      ->delimiter(',')
      ->expected(3);
  std::optional<std::uint32_t> cast_mask;
  cast->add_option("--mask", cast_mask, "meet only bodies in these collision layers (bits)");

  CLI::App* closest =
      app.add_subcommand("closest", "the point of a body's surface nearest to a point, as JSON");
  std::uint64_t closest_id = 0;
  std::vector<double> closest_to;
  double closest_max = 1000;
  closest->add_option("id", closest_id, "the body's id")->required();
  closest->add_option("--point", closest_to, "x,y,z (m, world)")
      ->required()
      ->delimiter(',')
      ->expected(3);
  closest->add_option("--max-distance", closest_max, "m: farther, nothing is found (default 1000)");

  CLI::App* impulse = app.add_subcommand("impulse", "apply an impulse to a body (it wakes)");
  std::vector<double> impulse_value, impulse_point;
  impulse->add_option("id", body_id, "the body's id")->required();
  impulse->add_option("--impulse", impulse_value, "x,y,z (N s, world frame)")
      ->required()
      ->delimiter(',')
      ->expected(3);
  impulse
      ->add_option("--point", impulse_point,
                   "x,y,z (m, world) where it acts (default: the centre of mass, no torque)")
      ->delimiter(',')
      ->expected(3);

  CLI::App* joint =
      app.add_subcommand("joint", "join body A to body B (or the world); prints its id");
  std::string joint_kind;
  std::uint64_t joint_a = 0, joint_b = 0;
  std::vector<double> anchor, anchor_b, axis, limit, motor, spring;
  double length = 0, max_swing = 0, friction = 0;
  bool collide = false, motor_off = false, spring_off = false;
  joint->add_option("kind", joint_kind, "ball, hinge, fixed, distance or slider")
      ->required()
      ->check(CLI::IsMember({"ball", "hinge", "fixed", "distance", "slider"}));
  joint->add_option("a", joint_a, "a body's id")->required();
  joint->add_option("b", joint_b, "another body's id (default: the world)");
  joint->add_option("--anchor", anchor, "x,y,z (m, world): where the joint is")
      ->required()
      ->delimiter(',')
      ->expected(3);
  joint->add_option("--anchor-b", anchor_b, "x,y,z (m): a distance joint's end on b")
      ->delimiter(',')
      ->expected(3);
  joint->add_option("--axis", axis, "x,y,z: a hinge's or slider's axis, a ball's twist axis")
      ->delimiter(',')
      ->expected(3);
  joint->add_option("--length", length, "a distance joint's length (m; default: as made)");
  joint->add_option("--limit", limit, "lower,upper of the angle (rad) or offset (m)")
      ->delimiter(',')
      ->expected(2);
  joint->add_option("--motor", motor, "speed,max_force (rad/s,N m or m/s,N)")
      ->delimiter(',')
      ->expected(2);
  joint->add_option("--spring", spring, "target,stiffness,damping")->delimiter(',')->expected(3);
  joint->add_option("--max-swing", max_swing, "a ball's cone (rad)");
  joint->add_option("--friction", friction,
                    "the joint's own friction (N m: ball, hinge; N: slider; default 0)");
  joint->add_flag("--collide", collide, "the two bodies still collide");

  CLI::App* joints = app.add_subcommand("joints", "joints' definitions and states as JSON lines");
  joints->add_option("ids", ids, "joint ids, by spaces or commas (default: all)")->delimiter(',');
  CLI::App* unjoint = app.add_subcommand("remove-joints", "remove joints by id");
  unjoint->add_option("ids", ids, "joint ids, by spaces or commas")->required()->delimiter(',');
  CLI::App* drive = app.add_subcommand("drive", "change a joint's motor or spring while it runs");
  std::uint64_t joint_id = 0;
  drive->add_option("id", joint_id, "the joint's id")->required();
  drive->add_option("--motor", motor, "speed,max_force")->delimiter(',')->expected(2);
  drive->add_option("--spring", spring, "target,stiffness,damping")->delimiter(',')->expected(3);
  drive->add_flag("--motor-off", motor_off, "remove the motor");
  drive->add_flag("--spring-off", spring_off, "remove the spring");

  CLI::App* play = app.add_subcommand("play", "run continuously");
  CLI::App* pause = app.add_subcommand("pause", "stop after the current step");
  CLI::App* reset = app.add_subcommand("reset", "back to the scene as loaded");
  CLI::App* step = app.add_subcommand("step", "run N steps, pause, and return when they are done");
  std::uint32_t steps = 1;
  step->add_option("n", steps, "steps")->check(cli::positive);

  CLI::App* set = app.add_subcommand("set", "change run settings (only those given)");
  std::optional<double> dt, real_time_factor;
  std::optional<std::uint32_t> substeps, iterations, joint_position_passes;
  std::string solver;
  std::vector<double> gravity;
  set->add_option("--dt", dt, "s per step");
  set->add_option("--real-time-factor", real_time_factor, "1: real time; 0: as fast as possible");
  set->add_option("--substeps", substeps, "substeps of the soft solver");
  set->add_option("--iterations", iterations, "velocity sweeps a step of the pgs solver");
  set->add_option("--joint-position-passes", joint_position_passes,
                  "position passes over the joints solved joint by joint (soft, pgs) after each "
                  "move: fewer cost less and hold the joints less");
  set->add_option("--solver", solver, "exact, pgs, soft or auto")
      ->check(CLI::IsMember({"exact", "pgs", "soft", "auto"}));
  set->add_option("--gravity", gravity, "x,y,z (m/s^2)")->delimiter(',')->expected(3);
  std::optional<bool> sleeping;
  set->add_option("--sleeping", sleeping,
                  "on or off: bodies at rest fall asleep and cost nothing until touched (off "
                  "wakes every sleeper)");

  CLI::App* snapshot = app.add_subcommand("snapshot", "save the whole world to a file");
  CLI::App* restore = app.add_subcommand("restore", "replace the world with a saved one");
  std::string state_file;
  snapshot->add_option("file", state_file, "where to write")->required();
  restore->add_option("file", state_file, "a file written by snapshot")
      ->required()
      ->check(cli::existing_file);

  CLI::App* stream = app.add_subcommand("stream", "frames to stdout, one per line (csv: per body)");
  StreamOptions stream_options;
  stream_options.add_to(stream, true);

  CLI::App* record = app.add_subcommand("record", "frames into a recording file");
  std::string recording_file;
  record->add_option("file", recording_file, "where to write")->required();
  StreamOptions record_options;
  record_options.add_to(record, false);

  CLI::App* replay = app.add_subcommand("replay", "a recording to stdout, as stream prints it");
  replay->add_option("file", recording_file, "a file written by record")
      ->required()
      ->check(cli::existing_file);
  StreamOptions replay_options;
  bool paced = false;
  replay->add_option("--format", replay_options.format, "jsonl or csv")
      ->check(CLI::IsMember({"jsonl", "csv"}));
  replay->add_flag("--paced", paced, "at the recorded simulated-time pace, not at once");
  if (const int exit_status = cli::parse(app, argc, argv); exit_status >= 0) return exit_status;

  if (*replay) {  // needs no server
    Result<client::RecordingReader> reader = client::RecordingReader::open(recording_file);
    if (!reader) return fail("replay", reader.status());
    v1::Frame frame;
    double first_time = -1;
    const auto start = std::chrono::steady_clock::now();
    while (reader.value().next(&frame)) {
      // A recording holds velocities in every frame or in none: the first frame says which, and
      // the CSV header follows it.
      if (reader.value().frames() == 1) {
        replay_options.velocities = frame.linear_velocities_size() > 0;
        if (replay_options.format == "csv")
          print_line(client::csv_header(replay_options.velocities));
      }
      if (paced) {
        if (first_time < 0) first_time = frame.time();
        std::this_thread::sleep_until(
            start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::duration<double>(frame.time() - first_time)));
      }
      print_frame(frame, replay_options);
    }
    if (!reader.value().status())
      return fail("replay", reader.value().status().within(recording_file + ": "));
    return 0;
  }

  if (*stream && stream_options.format == "csv" &&
      (stream_options.contacts || stream_options.stats || stream_options.joints))
    return fail("stream", Status::error("--contacts, --stats and --joints need --format jsonl: a "
                                        "CSV row holds one body's pose"));

  Result<client::Client> connected = client::Client::connect(connection);
  if (!connected) return fail("--tls-ca", connected.status());
  client::Client& client = connected.value();
  if (*info) {
    Result<v1::GetInfoResponse> got = client.info();
    if (!got) return fail("info", got.status());
    const v1::GetInfoResponse& i = got.value();
    print_line(nlohmann::json{{"version", i.version()},
                              {"step", i.step()},
                              {"time", i.time()},
                              {"bodies", i.body_count()},
                              {"joints", i.joint_count()},
                              {"running", i.running()},
                              {"subscribers", i.subscribers()},
                              {"achieved_real_time_factor", i.achieved_real_time_factor()},
                              {"behind", i.behind()}}
                   .dump());
  } else if (*health) {
    Result<bool> serving = client.healthy();
    if (!serving) return fail("health", serving.status());
    print_line(serving.value() ? "SERVING" : "NOT_SERVING");
    return serving.value() ? 0 : 1;
  } else if (*spawn) {
    if (Status s = read_listed_shape(&body); !s) return fail("spawn", s);
    if (body.shape == "heightfield") {
      if (body.heights_file.empty())
        return fail("spawn", Status::error("--heights: required for a heightfield"));
      if (Status s = read_heights(body.heights_file, &body.height_field); !s)
        return fail("spawn", s);
    }
    if (body.shape == "mesh") {
      if (body.mesh_file.empty())
        return fail("spawn", Status::error("--file: required for a mesh"));
      // The server checks the mesh against its limits and names what is wrong; these bounds
      // only stop a huge file from being copied into a request that would be refused.
      mesh_files::Arrays mesh;
      if (std::string error = mesh_files::read(body.mesh_file, body.mesh_scale, kMaxMeshVertices,
                                               kMaxMeshTriangles, &mesh);
          !error.empty())
        return fail("spawn", Status::error(error));
      body.mesh.mutable_vertices()->Assign(mesh.xyz.begin(), mesh.xyz.end());
      body.mesh.mutable_triangles()->Assign(mesh.triangles.begin(), mesh.triangles.end());
    }
    Result<std::vector<std::uint64_t>> made = client.spawn({body.spec()});
    if (!made) return fail("spawn", made.status());
    print_line(std::to_string(made.value()[0]));
  } else if (*spawn_scene) {
    Result<std::string> text = read_file(scene_file);
    if (!text) return fail("spawn-scene", text.status());
    v1::LoadSceneRequest request;
    request.set_scene_json(text.value());
    Result<v1::LoadSceneResponse> loaded = client.load_scene(request);
    if (!loaded) return fail(scene_file, loaded.status());
    std::printf("%s: %d bodies\n", loaded.value().name().c_str(), loaded.value().ids_size());
  } else if (*remove) {
    if (Status s = client.remove(ids); !s) return fail("remove", s);
  } else if (*joint) {
    const auto kinds = std::map<std::string, v1::JointKind>{{"ball", v1::JOINT_KIND_BALL},
                                                            {"hinge", v1::JOINT_KIND_HINGE},
                                                            {"fixed", v1::JOINT_KIND_FIXED},
                                                            {"distance", v1::JOINT_KIND_DISTANCE},
                                                            {"slider", v1::JOINT_KIND_SLIDER}};
    const auto put = [](const std::vector<double>& x, v1::Vec3* out) {
      out->set_x(x[0]);
      out->set_y(x[1]);
      out->set_z(x[2]);
    };
    v1::JointSpec spec;
    spec.set_kind(kinds.at(joint_kind));
    spec.set_a(joint_a);
    spec.set_b(joint_b);
    put(anchor, spec.mutable_anchor());
    if (!anchor_b.empty()) put(anchor_b, spec.mutable_anchor_b());
    if (!axis.empty()) put(axis, spec.mutable_axis());
    spec.set_length(length);
    spec.set_collide_connected(collide);
    if (!limit.empty()) {
      spec.mutable_limit()->set_lower(limit[0]);
      spec.mutable_limit()->set_upper(limit[1]);
    }
    if (!motor.empty()) put_motor(motor, spec.mutable_motor());
    if (!spring.empty()) put_spring(spring, spec.mutable_spring());
    if (max_swing != 0) spec.set_max_swing(max_swing);
    spec.set_friction(friction);
    Result<std::vector<std::uint64_t>> made = client.create_joints({spec});
    if (!made) return fail("joint", made.status());
    print_line(std::to_string(made.value()[0]));
  } else if (*joints) {
    Result<v1::GetJointsResponse> got = client.joints(ids);
    if (!got) return fail("joints", got.status());
    const auto v = [](const v1::Vec3& x) { return nlohmann::json{x.x(), x.y(), x.z()}; };
    for (int i = 0; i < got.value().ids_size(); ++i) {
      const v1::JointSpec& spec = got.value().specs(i);
      const v1::JointState& state = got.value().states(i);
      std::string kind = v1::JointKind_Name(spec.kind()).substr(std::string("JOINT_KIND_").size());
      for (char& c : kind)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      print_line(nlohmann::json{{"id", got.value().ids(i)},
                                {"kind", kind},
                                {"a", spec.a()},
                                {"b", spec.b()},
                                {"position", state.position()},
                                {"speed", state.speed()},
                                {"effort", state.effort()},
                                {"force", v(state.force())},
                                {"torque", v(state.torque())},
                                {"error", state.error()}}
                     .dump());
    }
  } else if (*unjoint) {
    if (Status s = client.remove_joints(ids); !s) return fail("remove-joints", s);
  } else if (*drive) {
    v1::JointDriveUpdate update;
    update.set_id(joint_id);
    if (!motor.empty()) put_motor(motor, update.mutable_motor());
    if (!spring.empty()) put_spring(spring, update.mutable_spring());
    update.set_motor_off(motor_off);
    update.set_spring_off(spring_off);
    if (Status s = client.set_joint_drives({update}); !s) return fail("drive", s);
  } else if (*bodies) {
    Result<v1::GetBodiesResponse> got = client.bodies(ids);
    if (!got) return fail("bodies", got.status());
    for (int i = 0; i < got.value().states_size(); ++i) {
      const v1::BodyState& s = got.value().states(i);
      const v1::BodyDescription& d = got.value().descriptions(i);
      const auto v = [](const v1::Vec3& x) { return nlohmann::json{x.x(), x.y(), x.z()}; };
      const v1::Quat& q = s.orientation();
      nlohmann::json line{{"id", s.id()},
                          {"p", v(s.position())},
                          {"q", {q.w(), q.x(), q.y(), q.z()}},
                          {"v", v(s.linear_velocity())},
                          {"w", v(s.angular_velocity())},
                          {"asleep", s.asleep()}};
      if (d.type() == v1::BODY_TYPE_STATIC) line["static"] = true;
      if (d.type() == v1::BODY_TYPE_KINEMATIC) line["kinematic"] = true;
      // What acts on it beyond gravity and contacts, where anything does.
      if (d.gravity_scale() != 1) line["gravity_scale"] = d.gravity_scale();
      if (d.linear_damping() != 0) line["linear_damping"] = d.linear_damping();
      if (d.angular_damping() != 0) line["angular_damping"] = d.angular_damping();
      const auto nonzero = [](const v1::Vec3& x) { return x.x() != 0 || x.y() != 0 || x.z() != 0; };
      if (nonzero(d.force())) line["force"] = v(d.force());
      if (nonzero(d.torque())) line["torque"] = v(d.torque());
      if (d.collision_layers() != 1 || d.collision_mask() != 0xFFFFFFFFu) {
        line["collision_layers"] = d.collision_layers();
        line["collision_mask"] = d.collision_mask();
      }
      print_line(line.dump());
    }
  } else if (*set_state) {
    v1::BodyStateUpdate update;
    update.set_id(body_id);
    if (!position.empty()) set_vec(position, update.mutable_position());
    if (!orientation.empty()) {
      v1::Quat* q = update.mutable_orientation();
      q->set_w(orientation[0]);
      q->set_x(orientation[1]);
      q->set_y(orientation[2]);
      q->set_z(orientation[3]);
    }
    if (!linear_velocity.empty()) set_vec(linear_velocity, update.mutable_linear_velocity());
    if (!angular_velocity.empty()) set_vec(angular_velocity, update.mutable_angular_velocity());
    if (!force.empty()) set_vec(force, update.mutable_force());
    if (!torque.empty()) set_vec(torque, update.mutable_torque());
    if (!force_point.empty()) set_vec(force_point, update.mutable_force_point());
    if (gravity_scale) update.set_gravity_scale(*gravity_scale);
    if (linear_damping) update.set_linear_damping(*linear_damping);
    if (angular_damping) update.set_angular_damping(*angular_damping);
    if (layers) update.set_collision_layers(*layers);
    if (mask) update.set_collision_mask(*mask);
    if (Status s = client.set_states({update}); !s) return fail("set-state", s);
  } else if (*ray) {
    v1::QueryRequest request;
    request.mutable_ray_origins()->Add(ray_origin.begin(), ray_origin.end());
    request.mutable_ray_directions()->Add(ray_direction.begin(), ray_direction.end());
    request.add_ray_max_distances(ray_max_distance);
    if (ray_mask) request.set_ray_mask(*ray_mask);
    request.set_hits_per_ray(ray_hits);
    Result<v1::QueryResponse> found = client.query(request);
    if (!found) return fail("ray", found.status());
    const v1::QueryResponse& r = found.value();
    for (int k = 0; k < r.hit_ids_size(); ++k) {
      const auto triple = [k](const auto& values) {
        return nlohmann::json{values[3 * k], values[3 * k + 1], values[3 * k + 2]};
      };
      print_line(nlohmann::json{{"id", r.hit_ids(k)},
                                {"distance", r.hit_distances(k)},
                                {"fraction", r.hit_fractions(k)},
                                {"point", triple(r.hit_points())},
                                {"normal", triple(r.hit_normals())}}
                     .dump());
    }
    if (r.hits_left_out()) std::fprintf(stderr, "ray: more hits were left out (--hits)\n");
  } else if (*overlap) {
    v1::QueryRequest request;
    v1::OverlapQuery* query = request.add_overlaps();
    if (Status s = read_listed_shape(&probe); !s) return fail("overlap", s);
    const v1::BodySpec spec = probe.spec();
    *query->mutable_shape() = spec.shape();
    *query->mutable_position() = spec.position();
    if (overlap_mask) query->set_mask(*overlap_mask);
    Result<v1::QueryResponse> found = client.query(request);
    if (!found) return fail("overlap", found.status());
    print_line(nlohmann::json{{"ids", found.value().overlap_ids()}}.dump());
  } else if (*cast) {
    v1::QueryRequest request;
    v1::ShapeCastQuery* query = request.add_shape_casts();
    if (Status s = read_listed_shape(&swept); !s) return fail("cast", s);
    const v1::BodySpec spec = swept.spec();
    *query->mutable_shape() = spec.shape();
    *query->mutable_position() = spec.position();
    if (!cast_orientation.empty()) {
      v1::Quat* q = query->mutable_orientation();
      q->set_w(cast_orientation[0]);
      q->set_x(cast_orientation[1]);
      q->set_y(cast_orientation[2]);
      q->set_z(cast_orientation[3]);
    }
    set_vec(cast_translation, query->mutable_translation());
    if (cast_mask) query->set_mask(*cast_mask);
    Result<v1::QueryResponse> found = client.query(request);
    if (!found) return fail("cast", found.status());
    const v1::QueryResponse& r = found.value();
    if (!r.cast_hits(0)) {
      print_line(nlohmann::json{{"hit", false}}.dump());
    } else {
      const auto triple = [](const auto& v) { return nlohmann::json{v[0], v[1], v[2]}; };
      print_line(nlohmann::json{{"hit", true},
                                {"id", r.cast_ids(0)},
                                {"fraction", r.cast_fractions(0)},
                                {"point", triple(r.cast_points())},
                                {"normal", triple(r.cast_normals())},
                                {"converged", r.cast_converged(0)}}
                     .dump());
    }
  } else if (*closest) {
    v1::QueryRequest request;
    v1::ClosestPointQuery* query = request.add_closest_points();
    query->set_id(closest_id);
    set_vec(closest_to, query->mutable_point());
    query->set_max_distance(closest_max);
    Result<v1::QueryResponse> found = client.query(request);
    if (!found) return fail("closest", found.status());
    const v1::QueryResponse& r = found.value();
    if (!r.closest_found(0)) {
      print_line(nlohmann::json{{"found", false}}.dump());
    } else {
      const auto triple = [](const auto& v) { return nlohmann::json{v[0], v[1], v[2]}; };
      print_line(nlohmann::json{{"found", true},
                                {"distance", r.closest_distances(0)},
                                {"point", triple(r.closest_surface_points())},
                                {"normal", triple(r.closest_normals())}}
                     .dump());
    }
  } else if (*impulse) {
    v1::Impulse applied;
    applied.set_id(body_id);
    set_vec(impulse_value, applied.mutable_impulse());
    if (!impulse_point.empty()) set_vec(impulse_point, applied.mutable_point());
    if (Status s = client.apply_impulses({applied}); !s) return fail("impulse", s);
  } else if (*play || *pause || *reset || *step || *set) {
    v1::ControlRequest request;
    if (*play) request.set_play(true);
    if (*pause) request.set_pause(true);
    if (*reset) request.set_reset(true);
    if (*step) request.set_step(steps);
    v1::RunSettings* settings = request.mutable_settings();
    if (dt) settings->set_dt(*dt);
    if (real_time_factor) settings->set_real_time_factor(*real_time_factor);
    if (substeps) settings->set_substeps(*substeps);
    if (iterations) settings->set_iterations(*iterations);
    if (joint_position_passes) settings->set_joint_position_passes(*joint_position_passes);
    if (!solver.empty()) settings->set_solver(*solver_kind(solver));
    if (!gravity.empty()) set_vec(gravity, settings->mutable_gravity());
    if (sleeping) settings->set_sleeping(*sleeping);
    Result<v1::ControlResponse> done = client.control(request);
    if (!done) return fail("control", done.status());
    if (*step) {  // returns once the steps are done, so that the next command sees them
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(10);
      while (done.value().running() && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        Result<v1::GetInfoResponse> now = client.info();
        if (!now) return fail("step", now.status());
        done.value().set_running(now.value().running());
        done.value().set_step(now.value().step());
      }
    }
    const v1::RunSettings& now = done.value().settings();
    print_line(
        nlohmann::json{{"running", done.value().running()},
                       {"step", done.value().step()},
                       {"dt", now.dt()},
                       {"real_time_factor", now.real_time_factor()},
                       {"substeps", now.substeps()},
                       {"iterations", now.iterations()},
                       {"joint_position_passes", now.joint_position_passes()},
                       {"solver", solver_name(now.solver())},
                       {"sleeping", now.sleeping()},
                       {"gravity", {now.gravity().x(), now.gravity().y(), now.gravity().z()}}}
            .dump());
  } else if (*snapshot) {
    Result<v1::SnapshotResponse> saved = client.snapshot();
    if (!saved) return fail("snapshot", saved.status());
    std::ofstream file(state_file, std::ios::binary | std::ios::trunc);
    file << saved.value().state();
    if (!file.flush()) return fail("snapshot", Status::error(state_file + ": cannot write"));
    std::printf("step %llu: %zu bytes to %s\n",
                static_cast<unsigned long long>(saved.value().step()), saved.value().state().size(),
                state_file.c_str());
  } else if (*restore) {
    Result<std::string> state = read_file(state_file);
    if (!state) return fail("restore", state.status());
    Result<v1::RestoreResponse> restored = client.restore(state.value());
    if (!restored) return fail(state_file, restored.status());
    std::printf("restored step %llu\n", static_cast<unsigned long long>(restored.value().step()));
  } else if (*stream) {
    if (stream_options.format == "csv") print_line(client::csv_header(stream_options.velocities));
    std::uint64_t received = 0;
    Status sound = Status::ok();
    const Status ended = client.stream(stream_options.request(), [&](const v1::Frame& frame) {
      sound = client::check_frame(frame);
      if (!sound) return false;
      print_frame(frame, stream_options);
      return stream_options.frames == 0 || ++received < stream_options.frames;
    });
    if (!sound) return fail("stream", sound.within("a frame from the server: "));
    if (!ended) return fail("stream", ended);
  } else if (*record) {
    Result<client::RecordingWriter> writer = client::RecordingWriter::create(recording_file);
    if (!writer) return fail("record", writer.status());
    std::uint64_t received = 0, dropped = 0;
    Status written = Status::ok();
    const Status ended = client.stream(record_options.request(), [&](const v1::Frame& frame) {
      written = writer.value().write(frame);
      dropped += frame.dropped();
      return written && (record_options.frames == 0 || ++received < record_options.frames);
    });
    if (!written) return fail("record", written);
    if (Status finished = writer.value().finish(); !finished) return fail("record", finished);
    if (!ended) return fail("record", ended);
    std::fprintf(stderr, "tumble: recorded %llu frames to %s (%llu dropped on the way)\n",
                 static_cast<unsigned long long>(received), recording_file.c_str(),
                 static_cast<unsigned long long>(dropped));
  }
  return 0;
}
