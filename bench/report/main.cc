// tumble-report: error against run time and stability on stiff and extreme cases, for every
// Tumble solver and every peer engine built in, measured in one run. Writes REPORT.md and CSV
// files into --out; scripts/report-plots draws the PNG plots from the CSV.
//
//   tumble-report [--quick] [--out DIR] [--only work|stability|joints] [--time-limit SECONDS]
//                 [--commit ID] [--sweeps] [--engines SUBSTRING,...]
//
// --sweeps adds the soft solver's other splits of substeps and sweeps; --engines keeps the
// engines whose label contains one of the substrings (case-sensitive).
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    if (comma > start) parts.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return parts;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tumble::report;
  bool quick = false, sweeps = false;
  std::vector<std::string> engine_filter;
  std::string out = "docs/report", only, commit = "unrecorded";
  double time_limit = 60;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--sweeps") {
      sweeps = true;
    } else if ((arg == "--out" || arg == "--only" || arg == "--time-limit" || arg == "--commit" ||
                arg == "--engines") &&
               i + 1 < argc) {
      const std::string value = argv[++i];
      if (arg == "--engines") engine_filter = split_list(value);
      if (arg == "--commit") commit = value;
      if (arg == "--out") out = value;
      if (arg == "--only") only = value;
      if (arg == "--time-limit") time_limit = std::stod(value);
    } else {
      std::fprintf(stderr,
                   "usage: tumble-report [--quick] [--out DIR] [--only work|stability|joints] "
                   "[--time-limit SECONDS] [--commit ID] [--sweeps] [--engines SUBSTRING,...]\n"
                   "(unknown or incomplete argument '%s')\n",
                   arg.c_str());
      return 2;
    }
  }
  if (!only.empty() && only != "work" && only != "stability" && only != "joints") {
    std::fprintf(stderr, "--only: expected work, stability or joints, got '%s'\n", only.c_str());
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
  if (sweeps)
    for (Engine& variant : soft_sweep_engines())
      engines.push_back(std::move(variant));
  for (Engine& peer : peer_engines())
    engines.push_back(std::move(peer));
  if (!engine_filter.empty()) {
    std::erase_if(engines, [&](const Engine& engine) {
      return std::none_of(engine_filter.begin(), engine_filter.end(), [&](const std::string& part) {
        return engine.label.find(part) != std::string::npos;
      });
    });
    if (engines.empty()) {
      std::fprintf(stderr, "--engines: no engine's label contains any of the given substrings\n");
      return 2;
    }
  }

  ReportHeader header;
  header.quick = quick;
  header.command = quick ? "make report QUICK=1" : "make report";
  if (sweeps || !engine_filter.empty()) {
    header.command = "build/bench/tumble-report";
    for (int i = 1; i < argc; ++i)
      header.command += std::string(" ") + argv[i];
  }
  header.date = today();
  header.machine = machine();
  header.commit = commit;
  const tumble::SceneDef probe = tumble::standard_scene("tower:2").value();
  const tumble::SceneDef jointed = tumble::standard_scene("pendulum").value();
  for (const Engine& engine : engines) {
    std::string why_not;
    const auto sim = engine.make(engine.joints_only ? jointed : probe, {}, &why_not);
    header.engines.push_back(engine.label + ": " + (sim ? sim->settings() : why_not));
  }

  std::vector<WorkPrecisionRow> work;
  std::vector<StabilityRow> stability;
  std::vector<CostRow> cost;
  const bool joints = only == "joints";
  if (only.empty() || only == "work" || joints) {
    Progress progress{.phase = "error against run time"};
    work = measure_work_precision(engines, {quick, time_limit, progress, joints});
  }
  if (only.empty() || only == "stability" || joints) {
    Progress progress{.phase = "stability"};
    stability = measure_stability(engines, {quick, time_limit, progress, joints});
    Progress cost_progress{.phase = "joints' cost"};
    cost = measure_joint_cost(engines, {quick, time_limit, cost_progress, joints});
  }
  std::string error;
  if (!write_csv(out, work, stability, cost, &error) ||
      !write_markdown(out + "/REPORT.md", header, work, stability, cost, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  std::fprintf(stderr, "wrote %s/REPORT.md, work_precision.csv, stability.csv, joint_cost.csv\n",
               out.c_str());
  return 0;
}
