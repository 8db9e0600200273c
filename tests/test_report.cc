// The quick report (make report QUICK=1), run in-process: its numbers must be sane. Errors fall as
// dt falls where the scheme converges, every peer built in appears with numbers, every scenario
// has a verdict for every engine, and the Markdown has every section.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "report_writer.h"

namespace tumble::report {
namespace {

struct QuickReport {
  std::vector<Engine> engines;
  std::vector<WorkPrecisionRow> work;
  std::vector<StabilityRow> stability;
  std::vector<CostRow> cost;
};

const QuickReport& quick_report() {
  static const QuickReport report = [] {
    QuickReport r;
    r.engines = tumble_engines(true);
    for (Engine& peer : peer_engines())
      r.engines.push_back(std::move(peer));
    r.work = measure_work_precision(r.engines, {true, 20, {}});
    r.stability = measure_stability(r.engines, {true, 20, {}});
    r.cost = measure_joint_cost(r.engines, {true, 20, {}});
    return r;
  }();
  return report;
}

double error_at(const std::vector<WorkPrecisionRow>& rows, const std::string& scene,
                const std::string& engine, double dt) {
  for (const WorkPrecisionRow& r : rows)
    if (r.scene == scene && r.engine == engine && r.dt == dt) return r.error;
  return std::nan("");
}

// The slide across a floor of triangles, as a mesh and as a heightfield, stops within 1e-6 m of
// where the slide on the plane does (the goal of docs/COLLISION.md's meshes), for each of our
// configurations and steps: the inner edges never catch the box. (Exactly, but for the exact
// solver at 60 Hz, whose pivoting turns the two grounds' rounding into 8e-9 m.)
TEST(Report, TheSlideOnAMeshOrHeightfieldStopsWhereTheSlideOnThePlaneDoes) {
  const QuickReport& r = quick_report();
  int compared = 0;
  for (const char* floor : {"slide-on-mesh", "slide-on-heightfield"}) {
    for (const Engine& engine : r.engines) {
      if (!engine.ours) continue;
      for (int rate : swept_rates(true)) {
        const double plane = error_at(r.work, "slide", engine.label, 1.0 / rate);
        const double triangles = error_at(r.work, floor, engine.label, 1.0 / rate);
        SCOPED_TRACE(std::string(floor) + ", " + engine.label + " at " + std::to_string(rate) +
                     " Hz");
        ASSERT_TRUE(std::isfinite(plane) && std::isfinite(triangles));
        const double stop = 25.0 / (2 * 0.5 * 9.81);  // m: both errors are relative to it
        EXPECT_LT(std::abs(triangles - plane) * stop, 1e-6);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 0);
}

// First-order schemes: an eighth of the step must cut the error by at least 4 on scenes with a
// closed form where the motion is smooth (free flight, rolling, sliding, the time of a flip).
TEST(Report, ErrorsFallAsTheStepFallsWhereTheSchemeConverges) {
  const QuickReport& r = quick_report();
  const std::vector<int> rates = swept_rates(true);
  for (const char* scene : {"projectile", "roll", "roll-dumbbell", "slide", "flip"}) {
    for (const Engine& engine : r.engines) {
      if (!engine.ours) continue;
      const double coarse = error_at(r.work, scene, engine.label, 1.0 / rates.front());
      const double fine = error_at(r.work, scene, engine.label, 1.0 / rates.back());
      SCOPED_TRACE(std::string(scene) + ", " + engine.label);
      ASSERT_TRUE(std::isfinite(coarse) && std::isfinite(fine));
      EXPECT_LT(fine, coarse / 4);
    }
  }
}

// A free body's energy and world angular momentum are invariants our integrator keeps exactly:
// round-off at every step size.
TEST(Report, OursKeepTheSpinInvariantsAtEveryStep) {
  const QuickReport& r = quick_report();
  for (const WorkPrecisionRow& row : r.work) {
    if (row.scene == "spin" && row.engine.rfind("Tumble", 0) == 0) {
      EXPECT_LT(row.error, 1e-9) << row.engine << ", dt " << row.dt;
    }
  }
}

TEST(Report, EveryPeerBuiltInAppearsWithNumbers) {
  const QuickReport& r = quick_report();
  for (const std::string& peer : built_peers()) {
    int measured = 0;
    for (const WorkPrecisionRow& row : r.work)
      measured += row.engine == peer && std::isfinite(row.error) ? 1 : 0;
    EXPECT_GT(measured, 0) << peer;
  }
#ifdef TUMBLE_HAVE_PEERS
  EXPECT_EQ(built_peers().size(), 6u);  // the packages are there: every peer must be built in
#endif
}

TEST(Report, EveryScenarioHasAVerdictForEveryEngine) {
  const QuickReport& r = quick_report();
  for (const ScenarioInfo& scenario : stability_scenarios(true)) {
    for (const Engine& engine : r.engines) {
      if (engine.joints_only && !scenario.joints) continue;
      bool verdict = false;
      for (const StabilityRow& row : r.stability)
        verdict |= row.scenario == scenario.name && row.engine == engine.label &&
                   (row.passed || !row.failure.empty());
      EXPECT_TRUE(verdict) << scenario.name << ", " << engine.label;
    }
  }
}

// The defects this report found stay fixed in it: our solvers keep a fast spinner's energy and
// push overlapping boxes apart without throwing them.
TEST(Report, OursPassTheSpinAndOverlapScenarios) {
  const QuickReport& r = quick_report();
  for (const Engine& engine : r.engines) {
    if (!engine.ours) continue;
    for (const char* scenario : {"spin rate", "initial overlap"})
      EXPECT_TRUE(survival(r.stability, scenario, engine.label).mode.empty())
          << scenario << ", " << engine.label << ": "
          << survival(r.stability, scenario, engine.label).mode;
  }
}

// The joints' section: the direct solve keeps a falling chain together to round-off at every step
// size and a small swing's period to 1e-4 (MuJoCo's at dt 1/60 measured 1.1e-4, ours 7.6e-6); the
// peers' adapters map motors with the right sign (a sign error reads as a wheel turning
// backwards), and every engine that runs the jointed scenes has a step time.
TEST(Report, JointsHoldInTheDirectSolveAndThePeersAreMappedTheRightWay) {
  const QuickReport& r = quick_report();
  for (const char* engine : {"Tumble exact", "Tumble auto"})
    for (int rate : swept_rates(true)) {
      SCOPED_TRACE(std::string(engine) + ", dt 1/" + std::to_string(rate));
      EXPECT_LT(error_at(r.work, "chain-gap", engine, 1.0 / rate), 1e-6);
      EXPECT_LT(error_at(r.work, "pendulum-10", engine, 1.0 / rate), 1e-4);
    }
  for (const std::string& peer : built_peers()) {
    if (peer == "MuJoCo") continue;  // its adapter refuses motors
    EXPECT_TRUE(survival(r.stability, "motor speed", peer).mode.empty())
        << peer << ": " << survival(r.stability, "motor speed", peer).mode;
  }
  // (Bullet's multibodies hold trees from the world alone: not the ragdolls.)
  for (const CostRow& row : r.cost) {
    if (row.engine.rfind("Tumble", 0) == 0 || row.engine == "Bullet float" ||
        row.engine == "Bullet double" ||
        (row.engine == "Bullet multibody" && row.scene == "chain:100")) {
      EXPECT_GT(row.ms_per_step, 0) << row.scene << ", " << row.engine << ": " << row.note;
    }
  }
  // Beside the cost, the joints' gaps: the direct solve holds the chain and the ragdolls to a
  // micrometre; Gauss-Seidel sweeps (ours, Bullet's) let the chain of 100 open by far more.
  const auto cost_of = [&](const std::string& scene, const std::string& engine) {
    for (const CostRow& row : r.cost)
      if (row.scene == scene && row.engine == engine) return row;
    ADD_FAILURE() << "no cost row for " << scene << ", " << engine;
    return CostRow{};
  };
  for (const char* scene : {"chain:100", "ragdolls:8"}) {
    const CostRow direct = cost_of(scene, "Tumble auto");
    EXPECT_GE(direct.worst_gap, direct.mean_gap) << scene;
    EXPECT_LT(direct.worst_gap, 1e-6) << scene;
  }
  EXPECT_GT(cost_of("chain:100", "Tumble pgs-10").worst_gap, 1e-3);
}

TEST(Report, MarkdownAndCsvHaveEverySection) {
  const QuickReport& r = quick_report();
  const std::string dir = testing::TempDir() + "/tumble_report_test";
  std::filesystem::create_directories(dir);
  std::string error;
  ReportHeader header;
  header.quick = true;
  ASSERT_TRUE(write_csv(dir, r.work, r.stability, r.cost, &error)) << error;
  ASSERT_TRUE(write_markdown(dir + "/REPORT.md", header, r.work, r.stability, r.cost, &error))
      << error;
  std::stringstream text;
  text << std::ifstream(dir + "/REPORT.md").rdbuf();
  for (const ReferenceInfo& scene : reference_scenes(true))
    EXPECT_NE(text.str().find("### " + scene.name + "\n"), std::string::npos) << scene.name;
  for (const ScenarioInfo& scenario : stability_scenarios(true))
    EXPECT_NE(text.str().find("### " + scenario.name + "\n"), std::string::npos) << scenario.name;
  EXPECT_NE(text.str().find("## Joints\n"), std::string::npos);
  EXPECT_NE(text.str().find("| ragdolls:8 | Tumble auto |"), std::string::npos);
  std::ifstream csv(dir + "/work_precision.csv");
  std::string line;
  std::size_t lines = 0;
  while (std::getline(csv, line))
    ++lines;
  EXPECT_EQ(lines, r.work.size() + 1);
}

}  // namespace
}  // namespace tumble::report
