// tumble: the command-line client. Spawns and removes bodies, steers the run, and streams
// frames to stdout as JSON lines or CSV for other tools.
//   tumble --server 127.0.0.1:50051 spawn box --size 1,1,1 --mass 2 --pos 0,0,5
//   tumble stream --format jsonl --frames 100
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "client.h"

using namespace tumble;

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

void print_json_frame(const v1::Frame& frame) {
  nlohmann::json line = {
      {"step", frame.step()}, {"time", frame.time()}, {"dropped", frame.dropped()}};
  nlohmann::json bodies = nlohmann::json::array();
  for (int i = 0; i < frame.ids_size(); ++i) {
    nlohmann::json body = {
        {"id", frame.ids(i)},
        {"p", {frame.positions(3 * i), frame.positions(3 * i + 1), frame.positions(3 * i + 2)}},
        {"q",
         {frame.orientations(4 * i), frame.orientations(4 * i + 1), frame.orientations(4 * i + 2),
          frame.orientations(4 * i + 3)}}};
    if (frame.linear_velocities_size() == 3 * frame.ids_size()) {
      body["v"] = {frame.linear_velocities(3 * i), frame.linear_velocities(3 * i + 1),
                   frame.linear_velocities(3 * i + 2)};
      body["w"] = {frame.angular_velocities(3 * i), frame.angular_velocities(3 * i + 1),
                   frame.angular_velocities(3 * i + 2)};
    }
    bodies.push_back(std::move(body));
  }
  line["bodies"] = std::move(bodies);
  std::printf("%s\n", line.dump().c_str());
}

void print_csv_frame(const v1::Frame& frame) {
  for (int i = 0; i < frame.ids_size(); ++i)
    std::printf("%llu,%.17g,%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                static_cast<unsigned long long>(frame.step()), frame.time(),
                static_cast<unsigned long long>(frame.ids(i)), frame.positions(3 * i),
                frame.positions(3 * i + 1), frame.positions(3 * i + 2), frame.orientations(4 * i),
                frame.orientations(4 * i + 1), frame.orientations(4 * i + 2),
                frame.orientations(4 * i + 3));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tumble: talks to a tumble-server (spawn, remove, control, stream)."};
  app.require_subcommand(1);
  client::Connection connection;
  app.add_option("--server", connection.address, "the server's address")->envname("TUMBLE_SERVER");
  app.add_option("--token", connection.token, "bearer token, when the server asks for one")
      ->envname("TUMBLE_TOKEN");

  CLI::App* info = app.add_subcommand("info", "the server's version, step, time and bodies");

  CLI::App* spawn = app.add_subcommand("spawn", "add one body; prints its id");
  std::string shape;
  std::vector<double> size{1, 1, 1}, position{0, 0, 0}, velocity{0, 0, 0}, spin{0, 0, 0};
  double radius = 0.5, half_height = 0.5, mass = 0;
  bool is_static = false;
  spawn->add_option("shape", shape, "box, sphere or capsule")
      ->required()
      ->check(CLI::IsMember({"box", "sphere", "capsule"}));
  spawn->add_option("--size", size, "box: full extents x,y,z (m)")->delimiter(',')->expected(3);
  spawn->add_option("--radius", radius, "sphere, capsule: radius (m)");
  spawn->add_option("--half-height", half_height, "capsule: half the core length (m)");
  spawn->add_option("--mass", mass, "kg (default: from a density of 1000 kg/m^3)");
  spawn->add_option("--pos", position, "x,y,z (m)")->delimiter(',')->expected(3);
  spawn->add_option("--vel", velocity, "x,y,z (m/s)")->delimiter(',')->expected(3);
  spawn->add_option("--spin", spin, "angular velocity x,y,z (rad/s)")->delimiter(',')->expected(3);
  spawn->add_flag("--static", is_static, "a body that never moves");

  CLI::App* spawn_scene = app.add_subcommand("spawn-scene", "replace the world with a scene file");
  std::string scene_file;
  spawn_scene->add_option("file", scene_file, "a scene (JSON, docs/SCENES.md)")
      ->required()
      ->check(CLI::ExistingFile);

  CLI::App* remove = app.add_subcommand("remove", "remove bodies by id");
  std::vector<std::uint64_t> ids;
  remove->add_option("ids", ids, "body ids")->required();

  CLI::App* play = app.add_subcommand("play", "run continuously");
  CLI::App* pause = app.add_subcommand("pause", "stop after the current step");
  CLI::App* reset = app.add_subcommand("reset", "back to the scene as loaded");
  CLI::App* step = app.add_subcommand("step", "run N steps, then pause");
  std::uint32_t steps = 1;
  step->add_option("n", steps, "steps")->check(CLI::PositiveNumber);

  CLI::App* stream = app.add_subcommand("stream", "frames to stdout, one per line");
  std::string format = "jsonl";
  std::uint64_t frames = 0;
  double rate = 0;
  bool velocities = false;
  stream->add_option("--format", format, "jsonl or csv")->check(CLI::IsMember({"jsonl", "csv"}));
  stream->add_option("--frames", frames, "stop after this many frames (0: until interrupted)");
  stream->add_option("--rate", rate, "at most this many frames per second (0: every step)");
  stream->add_flag("--velocities", velocities, "include velocities (jsonl)");
  CLI11_PARSE(app, argc, argv);

  client::Client client(connection);
  if (*info) {
    Result<v1::GetInfoResponse> got = client.info();
    if (!got) return fail("info", got.status());
    const v1::GetInfoResponse& i = got.value();
    std::printf("%s\n", nlohmann::json{{"version", i.version()},
                                       {"step", i.step()},
                                       {"time", i.time()},
                                       {"bodies", i.body_count()},
                                       {"running", i.running()},
                                       {"subscribers", i.subscribers()}}
                            .dump()
                            .c_str());
  } else if (*spawn) {
    v1::BodySpec spec;
    if (shape == "box")
      set_vec(size, spec.mutable_shape()->mutable_box()->mutable_size());
    else if (shape == "sphere")
      spec.mutable_shape()->mutable_sphere()->set_radius(radius);
    else {
      spec.mutable_shape()->mutable_capsule()->set_radius(radius);
      spec.mutable_shape()->mutable_capsule()->set_half_height(half_height);
    }
    if (mass > 0) spec.set_mass(mass);
    if (is_static) spec.set_type(v1::BODY_TYPE_STATIC);
    set_vec(position, spec.mutable_position());
    set_vec(velocity, spec.mutable_linear_velocity());
    set_vec(spin, spec.mutable_angular_velocity());
    Result<std::vector<std::uint64_t>> made = client.spawn({spec});
    if (!made) return fail("spawn", made.status());
    std::printf("%llu\n", static_cast<unsigned long long>(made.value()[0]));
  } else if (*spawn_scene) {
    std::ifstream file(scene_file);
    std::stringstream text;
    text << file.rdbuf();
    v1::LoadSceneRequest request;
    request.set_scene_json(text.str());
    Result<v1::LoadSceneResponse> loaded = client.load_scene(request);
    if (!loaded) return fail(scene_file, loaded.status());
    std::printf("%s: %d bodies\n", loaded.value().name().c_str(), loaded.value().ids_size());
  } else if (*remove) {
    if (Status s = client.remove(ids); !s) return fail("remove", s);
  } else if (*play || *pause || *reset || *step) {
    v1::ControlRequest request;
    if (*play) request.set_play(true);
    if (*pause) request.set_pause(true);
    if (*reset) request.set_reset(true);
    if (*step) request.set_step(steps);
    Result<v1::ControlResponse> done = client.control(request);
    if (!done) return fail("control", done.status());
    std::printf("%s\n",
                nlohmann::json{{"running", done.value().running()}, {"step", done.value().step()}}
                    .dump()
                    .c_str());
  } else if (*stream) {
    v1::StreamFramesRequest request;
    request.set_max_rate(rate);
    request.set_velocities(velocities);
    if (format == "csv") std::printf("step,time,id,x,y,z,qw,qx,qy,qz\n");
    std::uint64_t received = 0;
    const Status ended = client.stream(request, [&](const v1::Frame& frame) {
      if (format == "csv")
        print_csv_frame(frame);
      else
        print_json_frame(frame);
      std::fflush(stdout);
      return frames == 0 || ++received < frames;
    });
    if (!ended) return fail("stream", ended);
  }
  return 0;
}
