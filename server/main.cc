// tumble-server: owns a world, steps it, and serves the tumble.v1 World API over gRPC.
// Flags may also come from the environment (TUMBLE_LISTEN, TUMBLE_SCENE, ...).
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <pthread.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bind_failure.h"
#include "frame_recorder.h"
#include "log.h"
#include "reflection_v1.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#include "service.h"
#ifdef TUMBLE_WITH_DDS
#include "dds_publisher.h"
#endif
#include "tumble/command_line.h"
#include "tumble/passive_wait.h"

namespace {

tumble::Result<std::string> read_pem(const std::string& path, const char* flag) {
  std::ifstream file(path);
  if (!file) return tumble::Status::error(std::string(flag) + ": cannot read " + path);
  std::stringstream text;
  text << file.rdbuf();
  return std::move(text).str();
}

// Applies "NAME=VALUE" options over the scene's limits.
tumble::Status override_limits(const std::vector<std::string>& options,
                               tumble::WorldLimits* limits) {
  for (const std::string& option : options) {
    const std::size_t equals = option.find('=');
    const std::string name = option.substr(0, equals);
    const auto fields = tumble::limit_fields();
    const auto field = std::find_if(fields.begin(), fields.end(),
                                    [&](const tumble::LimitField& f) { return f.name == name; });
    if (equals == std::string::npos || field == fields.end())
      return tumble::Status::error(option +
                                   ": expected NAME=VALUE with NAME one of max_coordinate, "
                                   "min_size, max_size, min_mass, max_mass, "
                                   "max_linear_speed, max_angular_speed, max_time_step");
    char* end = nullptr;
    const std::string text = option.substr(equals + 1);
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0')
      return tumble::Status::error(option + ": the value is not a number");
    limits->*field->value = value;
  }
  return tumble::validate(*limits);
}

}  // namespace

int main(int argc, char** argv) {
  tumble::cli::wait_passively_by_default(argv);  // first: it may run the program again
  using namespace tumble;
  // SIGINT and SIGTERM are blocked in every thread (threads inherit the mask) and taken by the
  // main thread with sigwait, so shutting down runs as ordinary code, not in a signal handler.
  // This comes first: creating gRPC credentials starts gRPC's own threads, and a thread started
  // before the mask would take SIGTERM's default action and kill the server mid-shutdown.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  CLI::App app{"Tumble's simulation server: steps a world and serves it over gRPC."};
  cli::keep_conventions(app, "tumble-server");
  std::string listen = "127.0.0.1:50051", scene_name, scene_file;
  int threads = 0;
  double real_time_factor = 1;
  std::size_t max_bodies = 100000;
  bool paused = false;
  std::string token, tls_cert, tls_key;
  int max_message_mb = 64;
  std::vector<std::string> limit_options;
  bool dds = false;
  std::uint32_t dds_domain = 0;
  double dds_rate = 0;
  std::string log_level = "info";
  std::string record_file;
  app.add_option("--listen", listen, "address to listen on (loopback by default)")
      ->envname("TUMBLE_LISTEN");
  app.add_option("--scene", scene_file, "a scene file (JSON, docs/SCENES.md)")
      ->envname("TUMBLE_SCENE");
  app.add_option("--standard", scene_name, "a built-in scene: default, pile:1000, pyramid:20, ...")
      ->envname("TUMBLE_STANDARD");
  app.add_option("--threads", threads, "OpenMP threads for the step (0: all)")
      ->envname("TUMBLE_THREADS")
      ->check(cli::non_negative)
      ->check(CLI::Range(0, 1024));
  app.add_option("--real-time-factor", real_time_factor,
                 "1: simulated time at wall-clock pace; 0: as fast as possible")
      ->envname("TUMBLE_REAL_TIME_FACTOR")
      ->check(cli::non_negative);
  app.add_option("--max-bodies", max_bodies, "refuse spawns beyond this many bodies")
      ->envname("TUMBLE_MAX_BODIES");
  app.add_flag("--paused", paused, "start paused (Control play starts it)");
  app.add_option("--token", token,
                 "require 'authorization: Bearer TOKEN' on every call (prefer the variable)")
      ->envname("TUMBLE_TOKEN");
  app.add_option("--tls-cert", tls_cert, "serve TLS with this certificate chain (PEM)")
      ->envname("TUMBLE_TLS_CERT");
  app.add_option("--tls-key", tls_key, "the certificate's private key (PEM)")
      ->envname("TUMBLE_TLS_KEY");
  app.add_option("--max-message-mb", max_message_mb,
                 "largest request accepted (MiB; a Restore of a big world needs room); larger "
                 "ones are refused with RESOURCE_EXHAUSTED")
      ->envname("TUMBLE_MAX_MESSAGE_MB")
      ->check(CLI::Range(1, 2047));
  app.add_option("--limit", limit_options,
                 "NAME=VALUE: a limit of the world (docs/SCENES.md), imposed on every scene and "
                 "snapshot loaded; repeatable, e.g. --limit max_size=100 --limit max_mass=1e6")
      ->envname("TUMBLE_LIMITS")
      ->delimiter(',');
  app.add_flag("--dds", dds, "publish states on DDS (topics in proto/dds/tumble_states.idl)")
      ->envname("TUMBLE_DDS");
  app.add_option("--dds-domain", dds_domain, "the DDS domain to publish on")
      ->envname("TUMBLE_DDS_DOMAIN")
      ->check(CLI::Range(0, 232));
  app.add_option("--dds-rate", dds_rate, "DDS samples per second at most (0: every step)")
      ->envname("TUMBLE_DDS_RATE")
      ->check(cli::non_negative);
  app.add_option("--record", record_file,
                 "write every frame (velocities, contacts, statistics) to this recording, none "
                 "dropped: the world waits for the disk if it must (tumble replay, tumble-viewer "
                 "--replay)")
      ->envname("TUMBLE_RECORD");
  app.add_option("--log-level", log_level,
                 "error, warn, info or debug: what the log on stderr holds (debug: every refused "
                 "request)")
      ->envname("TUMBLE_LOG_LEVEL")
      ->check(CLI::IsMember({"error", "warn", "info", "debug"}));
  if (const int exit_status = cli::parse(app, argc, argv); exit_status >= 0) return exit_status;
  server::set_log_level(*server::log_level_from_name(log_level));
  if (tls_cert.empty() != tls_key.empty()) {
    std::fprintf(stderr, "tumble-server: --tls-cert and --tls-key go together\n");
    return 2;
  }
  std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials();
  if (!tls_cert.empty()) {
    const tumble::Result<std::string> cert = read_pem(tls_cert, "--tls-cert");
    const tumble::Result<std::string> key = read_pem(tls_key, "--tls-key");
    for (const auto* pem : {&cert, &key})
      if (!*pem) {
        std::fprintf(stderr, "tumble-server: %s\n", pem->error().c_str());
        return 2;
      }
    grpc::SslServerCredentialsOptions options;
    options.pem_key_cert_pairs.push_back({key.value(), cert.value()});
    credentials = grpc::SslServerCredentials(options);
  }

  Result<SceneDef> scene = chosen_scene(scene_file, scene_name);
  if (!scene) {
    std::fprintf(stderr, "tumble-server: %s\n", scene.error().c_str());
    return 2;
  }
  scene.value().world.threads = threads;
  if (Status s = override_limits(limit_options, &scene.value().world.limits); !s) {
    std::fprintf(stderr, "tumble-server: --limit %s\n", s.message().c_str());
    return 2;
  }
  if (tumble::Status s = server::check_real_time_factor(real_time_factor); !s) {
    std::fprintf(stderr, "tumble-server: --real-time-factor: %s\n", s.message().c_str());
    return 2;
  }
  if (scene.value().dt > scene.value().world.limits.max_time_step) {
    std::fprintf(stderr, "tumble-server: the scene's dt is above limits.max_time_step\n");
    return 2;
  }
  Result<World> world = make_world(scene.value());
  if (!world) {
    std::fprintf(stderr, "tumble-server: %s\n", world.error().c_str());
    return 2;
  }

  server::WorldHost host(std::move(world).value(), scene.value().dt, real_time_factor);
  std::shared_ptr<server::FrameRecorder> recorder;
  if (!record_file.empty()) {
    auto started = server::FrameRecorder::start(record_file);
    if (!started) {
      std::fprintf(stderr, "tumble-server: --record: %s\n", started.error().c_str());
      return 2;
    }
    recorder = std::move(started).value();
    host.record_to(recorder);
  }
#ifdef TUMBLE_WITH_DDS
  std::unique_ptr<server::DdsPublisher> dds_publisher;
  if (dds) {
    auto started = server::DdsPublisher::start(host, {.domain = dds_domain, .rate = dds_rate});
    if (!started) {
      std::fprintf(stderr, "tumble-server: --dds: %s\n", started.error().c_str());
      return 1;
    }
    dds_publisher = std::move(started).value();
  }
#else
  if (dds) {
    std::fprintf(stderr,
                 "tumble-server: --dds: this build has no DDS (install Cyclone DDS: "
                 "scripts/install-deps dds, and rebuild)\n");
    return 2;
  }
#endif
  server::WorldService service(
      host,
      {.max_bodies = max_bodies,
       .token = token,
       .world = scene.value().world.limits,
       .max_message_bytes = static_cast<std::size_t>(max_message_mb) << 20},
      scene.value());
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  // Without this gRPC sets SO_REUSEPORT, and a second server on a taken port starts, says it
  // listens, and shares the port's connections with the first.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  int port = 0;
  builder.AddListeningPort(listen, credentials, &port);
  service.register_on(builder);
  server::ReflectionV1 reflection_v1({v1::World::service_full_name(), "grpc.health.v1.Health",
                                      "grpc.reflection.v1alpha.ServerReflection",
                                      "grpc.reflection.v1.ServerReflection"});
  builder.RegisterService(&reflection_v1);
  std::unique_ptr<grpc::Server> grpc_server = builder.BuildAndStart();
  if (grpc_server == nullptr || port == 0) {
    std::fprintf(stderr, "tumble-server: --listen: cannot listen on %s: %s\n", listen.c_str(),
                 server::explain_bind_failure(listen).c_str());
    return 1;
  }
  // Health by the service's name, as well as the server's (""), for probes that ask for it.
  grpc_server->GetHealthCheckService()->SetServingStatus(v1::World::service_full_name(), true);
  // With port 0 the system picks one: print the one in use, for scripts and tests to read.
  const std::string bound = listen.substr(0, listen.rfind(':')) + ":" + std::to_string(port);
  std::printf("tumble-server: scene %s, %zu bodies, listening on %s%s\n",
              scene.value().name.c_str(), host.status().bodies, bound.c_str(),
              tls_cert.empty() ? "" : " (TLS)");
  if (dds) std::printf("tumble-server: publishing on DDS domain %u\n", dds_domain);
  std::fflush(stdout);
  server::log(server::LogLevel::kInfo,
              "serving scene " + scene.value().name + " (" + std::to_string(host.status().bodies) +
                  " bodies) on " + bound +
                  (token.empty() ? ", no token required" : ", token required") +
                  (paused ? ", paused" : ""));
  if (!paused) host.play();

  int signal = 0;
  sigwait(&stop_signals, &signal);
  // Streams end first (they see the flag within 0.1 s), then pending calls finish.
  service.shut_down();
  grpc_server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  host.pause();
  if (recorder != nullptr) {
    host.wait_idle(std::chrono::seconds(10));  // the step in flight is recorded too
    host.record_to(nullptr);
    const Status written = recorder->finish();
    server::log(written ? server::LogLevel::kInfo : server::LogLevel::kError,
                "--record: " + std::to_string(recorder->frames_written()) + " frames in " +
                    record_file + (written ? "" : " (" + written.message() + ")"));
  }
  std::printf("tumble-server: stopped at step %llu\n",
              static_cast<unsigned long long>(host.status().step));
  server::log(server::LogLevel::kInfo, std::string("stopped by ") +
                                           (signal == SIGINT ? "SIGINT" : "SIGTERM") + " at step " +
                                           std::to_string(host.status().step));
  return 0;
}
