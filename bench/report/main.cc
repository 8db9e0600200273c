// tumble-report: error against run time and stability on stiff and extreme cases, for every
// Tumble solver and every peer engine built in, measured in one run. Writes REPORT.md and CSV
// files into --out; scripts/report-plots draws the PNG plots from the CSV.
//
//   tumble-report [--quick] [--out DIR] [--only work|stability] [--time-limit SECONDS]
//                 [--commit ID]
#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>

#include "report_writer.h"
#include "scenes/standard.h"

namespace {

struct Progress {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::string phase;
  void operator()(const std::string& what, std::size_t done, std::size_t total) const {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double left = done > 0 ? elapsed / done * (total - done) : 0;
    std::fprintf(stderr, "[%zu/%zu, %.0f s, ~%.0f s left in %s] %s\n", done, total, elapsed, left,
                 phase.c_str(), what.c_str());
  }
};

// "2 cores, <model name>" from /proc/cpuinfo, so that the figures say what they were measured on.
std::string machine() {
  std::string model;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; model.empty() && std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos)
      model = line.substr(line.find(':') + 2);
  return std::to_string(omp_get_num_procs()) + " cores" + (model.empty() ? "" : ", " + model);
}

std::string today() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d", std::gmtime(&now));
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tumble::report;
  bool quick = false;
  std::string out = "docs/report", only, commit = "unrecorded";
  double time_limit = 60;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      quick = true;
    } else if ((arg == "--out" || arg == "--only" || arg == "--time-limit" || arg == "--commit") &&
               i + 1 < argc) {
      const std::string value = argv[++i];
      if (arg == "--commit") commit = value;
      if (arg == "--out") out = value;
      if (arg == "--only") only = value;
      if (arg == "--time-limit") time_limit = std::stod(value);
    } else {
      std::fprintf(stderr,
                   "usage: tumble-report [--quick] [--out DIR] [--only work|stability] "
                   "[--time-limit SECONDS] [--commit ID]\n(unknown or incomplete argument '%s')\n",
                   arg.c_str());
      return 2;
    }
  }
  if (!only.empty() && only != "work" && only != "stability") {
    std::fprintf(stderr, "--only: expected work or stability, got '%s'\n", only.c_str());
    return 2;
  }
  if (quick) time_limit = std::min(time_limit, 20.0);
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "--out: cannot create %s: %s\n", out.c_str(), ec.message().c_str());
    return 1;
  }

  std::vector<Engine> engines = tumble_engines(quick);
  for (Engine& peer : peer_engines())
    engines.push_back(std::move(peer));

  ReportHeader header;
  header.quick = quick;
  header.command = quick ? "make report QUICK=1" : "make report";
  header.date = today();
  header.machine = machine();
  header.commit = commit;
  const tumble::SceneDef probe = tumble::standard_scene("tower:2").value();
  for (const Engine& engine : engines) {
    std::string why_not;
    const auto sim = engine.make(probe, {}, &why_not);
    header.engines.push_back(engine.label + ": " + (sim ? sim->settings() : why_not));
  }

  std::vector<WorkPrecisionRow> work;
  std::vector<StabilityRow> stability;
  if (only.empty() || only == "work") {
    Progress progress{.phase = "error against run time"};
    work = measure_work_precision(engines, {quick, time_limit, progress});
  }
  if (only.empty() || only == "stability") {
    Progress progress{.phase = "stability"};
    stability = measure_stability(engines, {quick, time_limit, progress});
  }
  std::string error;
  if (!write_csv(out, work, stability, &error) ||
      !write_markdown(out + "/REPORT.md", header, work, stability, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  std::fprintf(stderr, "wrote %s/REPORT.md, work_precision.csv, stability.csv\n", out.c_str());
  return 0;
}
