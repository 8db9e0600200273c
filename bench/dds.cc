// DDS publishing on loopback: a host in this process steps 1000 drifting spheres and publishes
// them with DdsPublisher; a reader in another process (this program run with --reader) takes
// rt/tumble/poses and rt/tumble/pose_ids. Reports the step rate with DDS off and on, the pose
// samples per second the reader received, the share of published steps it lost, and the latency
// from the end of a step to the arrival of its ids (p50, p99), flat out and paced at 1 kHz.
// Usage: bench_dds [seconds per row, default 3]
#include <dds/dds.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "dds_publisher.h"
#include "drifting_spheres.h"
#include "tumble_qos.h"
#include "tumble_states.h"

namespace {

using namespace tumble;
using bench::unix_ns;

constexpr std::uint32_t kDomain = 77;
constexpr char kLoopback[] =
    "<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto"
    "</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain>"
    "</CycloneDDS>";

// The reader process: counts pose samples and id samples' latencies for `seconds`, then prints
// "poses N ids M p50_ms p99_ms".
int run_reader(double seconds) {
  const dds_entity_t participant = dds_create_participant(kDomain, nullptr, nullptr);
  dds_qos_t* qos = tumble_states_qos();
  const dds_entity_t poses_topic = dds_create_topic(
      participant, &geometry_msgs_msg_dds__PoseArray__desc, "rt/tumble/poses", qos, nullptr);
  const dds_entity_t ids_topic = dds_create_topic(participant, &tumble_msgs_msg_dds__BodyIds__desc,
                                                  "rt/tumble/pose_ids", qos, nullptr);
  const dds_entity_t poses = dds_create_reader(participant, poses_topic, qos, nullptr);
  const dds_entity_t ids = dds_create_reader(participant, ids_topic, qos, nullptr);
  dds_delete_qos(qos);
  const dds_entity_t waitset = dds_create_waitset(participant);
  for (dds_entity_t reader : {poses, ids}) {
    dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
    dds_waitset_attach(waitset, reader, reader);
  }
  std::printf("ready\n");
  std::fflush(stdout);
  std::uint64_t pose_samples = 0;
  std::vector<double> latencies_ms;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    dds_attach_t triggered[2];
    dds_waitset_wait(waitset, triggered, 2, DDS_MSECS(50));
    void* samples[8] = {};
    dds_sample_info_t infos[8];
    dds_return_t n = dds_take(poses, samples, infos, 8, 8);
    for (dds_return_t i = 0; i < n; ++i)
      pose_samples += infos[i].valid_data ? 1 : 0;
    if (n > 0) dds_return_loan(poses, samples, n);
    std::fill(std::begin(samples), std::end(samples), nullptr);
    n = dds_take(ids, samples, infos, 8, 8);
    const std::uint64_t now = unix_ns();
    for (dds_return_t i = 0; i < n; ++i)
      if (infos[i].valid_data)
        latencies_ms.push_back(
            (now - static_cast<tumble_msgs_msg_dds__BodyIds_*>(samples[i])->stepped_at_unix_ns) * 1e-6);
    if (n > 0) dds_return_loan(ids, samples, n);
  }
  std::sort(latencies_ms.begin(), latencies_ms.end());
  auto at = [&](double q) {
    return latencies_ms.empty()
               ? 0.0
               : latencies_ms[static_cast<std::size_t>(q * (latencies_ms.size() - 1))];
  };
  std::printf("poses %llu ids %zu %.3f %.3f\n", static_cast<unsigned long long>(pose_samples),
              latencies_ms.size(), at(0.5), at(0.99));
  dds_delete(participant);
  return 0;
}

struct Row {
  double step_rate = 0, published_rate = 0, received_rate = 0, lost = 0, p50 = 0, p99 = 0;
};

Row measure(bool dds, double real_time_factor, double seconds) {
  const SceneDef scene = bench::drifting_spheres(1);
  server::WorldHost host(make_world(scene).value(), scene.dt, real_time_factor);
  std::unique_ptr<server::DdsPublisher> publisher;
  FILE* reader = nullptr;
  if (dds) {
    publisher = server::DdsPublisher::start(host, {.domain = kDomain}).value();
    // The reader runs 1.5 s longer than the row: discovery comes first.
    char self[4096] = {};
    if (readlink("/proc/self/exe", self, sizeof self - 1) <= 0) std::exit(1);
    reader = popen((std::string(self) + " --reader " + std::to_string(seconds + 1.5)).c_str(), "r");
    char line[256];
    if (fgets(line, sizeof line, reader) == nullptr) std::exit(1);  // "ready"
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  }
  const std::uint64_t published_before = publisher ? publisher->published() : 0;
  const auto start = std::chrono::steady_clock::now();
  host.play();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  host.pause();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Row row;
  row.step_rate = host.status().step / wall;
  if (dds) {
    row.published_rate = (publisher->published() - published_before) / wall;
    char line[256] = {};
    unsigned long long poses = 0;
    std::size_t ids = 0;
    if (fgets(line, sizeof line, reader) != nullptr)
      std::sscanf(line, "poses %llu ids %zu %lf %lf", &poses, &ids, &row.p50, &row.p99);
    pclose(reader);
    row.received_rate = poses / wall;
    row.lost = 1 - static_cast<double>(poses) / std::max<std::uint64_t>(1, host.status().step);
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  setenv("CYCLONEDDS_URI", kLoopback, 0);
  if (argc > 2 && std::strcmp(argv[1], "--reader") == 0) return run_reader(std::atof(argv[2]));
  const double seconds = argc > 1 ? std::atof(argv[1]) : 3;
  std::printf(
      "DDS on loopback, 1000 bodies (64 kB of poses a step), one reader process, %.0f s a row\n",
      seconds);
  std::printf("%-28s %10s %12s %12s %8s %9s %9s\n", "row", "steps/s", "published/s", "received/s",
              "lost", "p50 ms", "p99 ms");
  for (double rtf : {0.0, 1.0}) {
    const Row off = measure(false, rtf, seconds);
    const Row on = measure(true, rtf, seconds);
    const char* pace = rtf == 0 ? "flat out" : "paced at 1 kHz";
    std::printf("%-28s %10.0f %12s %12s %8s %9s %9s\n", (std::string("DDS off, ") + pace).c_str(),
                off.step_rate, "-", "-", "-", "-", "-");
    std::printf("%-28s %10.0f %12.0f %12.0f %7.1f%% %9.3f %9.3f\n",
                (std::string("DDS on, ") + pace).c_str(), on.step_rate, on.published_rate,
                on.received_rate, 100 * on.lost, on.p50, on.p99);
    std::printf("%-28s %9.1f%%\n", "  step rate lost to DDS",
                100 * (1 - on.step_rate / off.step_rate));
  }
  return 0;
}
