#include "report_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <set>

namespace tumble::report {
namespace {

std::string number(double x, const char* pattern = "%.3g") {
  if (std::isnan(x)) return "–";
  char text[64];
  std::snprintf(text, sizeof text, pattern, x);
  return text;
}

std::string csv_field(const std::string& s) {
  std::string out = "\"";
  for (char c : s)
    out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// A table cell: a '|' in a failure mode ("|L| drifted") would split it.
std::string cell(const std::string& s) {
  std::string out;
  for (char c : s)
    out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
  return out;
}

std::vector<std::string> ordered(const std::vector<std::string>& items) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const std::string& s : items)
    if (seen.insert(s).second) out.push_back(s);
  return out;
}

}  // namespace

Survival survival(const std::vector<StabilityRow>& rows, const std::string& scenario,
                  const std::string& engine) {
  Survival out{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
               ""};
  for (const StabilityRow& row : rows) {
    if (row.scenario != scenario || row.engine != engine) continue;
    if (row.passed) {
      out.largest_pass = row.value;
    } else {
      out.first_failure = row.value;
      out.mode = row.failure;
      break;
    }
  }
  return out;
}

bool write_csv(const std::string& directory, const std::vector<WorkPrecisionRow>& work,
               const std::vector<StabilityRow>& stability, const std::vector<CostRow>& cost,
               std::string* error) {
  std::ofstream wp(directory + "/work_precision.csv");
  wp << "scene,engine,dt,error,wall_s_per_simulated_s,settings,note\n";
  for (const WorkPrecisionRow& r : work)
    wp << csv_field(r.scene) << ',' << csv_field(r.engine) << ',' << number(r.dt, "%.17g") << ','
       << (std::isnan(r.error) ? std::string("nan") : number(r.error, "%.6e")) << ','
       << number(r.wall_per_second, "%.6e") << ',' << csv_field(r.settings) << ','
       << csv_field(r.note) << '\n';
  std::ofstream st(directory + "/stability.csv");
  st << "scenario,engine,value,passed,failure,wall_s,settings\n";
  for (const StabilityRow& r : stability)
    st << csv_field(r.scenario) << ',' << csv_field(r.engine) << ',' << number(r.value, "%.17g")
       << ',' << (r.passed ? 1 : 0) << ',' << csv_field(r.failure) << ','
       << number(r.wall_seconds, "%.4f") << ',' << csv_field(r.settings) << '\n';
  std::ofstream co(directory + "/joint_cost.csv");
  co << "scene,engine,ms_per_step,worst_gap_m,mean_gap_m,ratio_to_bullet_float,settings,note\n";
  for (const CostRow& r : cost)
    co << csv_field(r.scene) << ',' << csv_field(r.engine) << ',' << number(r.ms_per_step, "%.6e")
       << ',' << number(r.worst_gap, "%.6e") << ',' << number(r.mean_gap, "%.6e") << ','
       << number(r.ratio_to_reference, "%.4f") << ',' << csv_field(r.settings) << ','
       << csv_field(r.note) << '\n';
  if (!wp || !st || !co) {
    *error = "cannot write the CSV files in " + directory;
    return false;
  }
  return true;
}

namespace {

void write_error_tables(std::ostream& out, const std::vector<ReferenceInfo>& scenes,
                        const std::vector<WorkPrecisionRow>& work) {
  for (const ReferenceInfo& scene : scenes) {
    std::vector<double> dts;
    std::vector<std::string> engines;
    for (const WorkPrecisionRow& r : work) {
      if (r.scene != scene.name) continue;
      if (std::find(dts.begin(), dts.end(), r.dt) == dts.end()) dts.push_back(r.dt);
      engines.push_back(r.engine);
    }
    engines = ordered(engines);
    out << "\n### " << scene.name << "\n\n"
        << scene.what << ". Reference: " << scene.reference << ". Error unit: " << scene.unit
        << ".\n\n![" << scene.name << "](wp_" << scene.name << ".png)\n\n| engine |";
    for (double dt : dts)
      out << " dt 1/" << std::lround(1 / dt) << " |";
    out << "\n|---|";
    for (std::size_t i = 0; i < dts.size(); ++i)
      out << "---|";
    out << '\n';
    std::map<std::string, std::string> notes;
    for (const std::string& engine : engines) {
      out << "| " << engine << " |";
      for (double dt : dts)
        for (const WorkPrecisionRow& r : work)
          if (r.scene == scene.name && r.engine == engine && r.dt == dt) {
            out << ' ' << number(r.error) << " / " << number(1e3 * r.wall_per_second) << " |";
            if (!r.note.empty()) notes[engine] = r.note;
          }
      out << '\n';
    }
    for (const auto& [engine, note] : notes)
      out << "\n- " << engine << ": " << note;
    if (!notes.empty()) out << '\n';
  }
}

void write_stability_tables(std::ostream& out, const std::vector<ScenarioInfo>& scenarios,
                            const std::vector<StabilityRow>& stability) {
  for (const ScenarioInfo& scenario : scenarios) {
    out << "\n### " << scenario.name << "\n\nAxis: " << scenario.axis << " (";
    for (std::size_t i = 0; i < scenario.values.size(); ++i)
      out << (i ? ", " : "") << number(scenario.values[i], "%g");
    out << "). Pass: " << scenario.criterion << ".\n\n| engine | survives | first failure |\n"
        << "|---|---|---|\n";
    std::vector<std::string> engines;
    for (const StabilityRow& r : stability)
      if (r.scenario == scenario.name) engines.push_back(r.engine);
    for (const std::string& engine : ordered(engines)) {
      const Survival s = survival(stability, scenario.name, engine);
      out << "| " << engine << " | " << number(s.largest_pass, "%g") << " | "
          << (s.mode.empty() ? std::string("none (passed every value)")
                             : number(s.first_failure, "%g") + ": " + cell(s.mode))
          << " |\n";
    }
  }
}

template <class Info>
std::vector<Info> kept(std::vector<Info> all, bool joints) {
  std::erase_if(all, [joints](const Info& info) { return info.joints != joints; });
  return all;
}

}  // namespace

bool write_markdown(const std::string& path, const ReportHeader& header,
                    const std::vector<WorkPrecisionRow>& work,
                    const std::vector<StabilityRow>& stability, const std::vector<CostRow>& cost,
                    std::string* error) {
  std::ofstream out(path);
  out << "# Tumble: error against run time, and stability on stiff and extreme cases\n\n"
      << "Generated by `" << header.command << "` on " << header.date << " (" << header.machine
      << ", commit " << header.commit << ")" << (header.quick ? ", **quick version**" : "")
      << ". Every engine ran in the same process, one after the other (but in the joints' "
         "cost table, where they take turns), on one thread unless its label says otherwise; "
         "times are wall time inside the engines' step calls only. "
         "Regenerate with `make report` (`make report QUICK=1` for the reduced version).\n\n"
      << "## Engines and settings\n\n";
  for (const std::string& e : header.engines)
    out << "- " << e << '\n';

  const char* error_cells =
      "Each cell: error / wall milliseconds per simulated second. – : no number (the note "
      "below the table says why). Plots: `wp_<scene>.png`, error against wall time on log-log "
      "axes, one line per engine and solver, points from the largest dt (left) to the "
      "smallest.\n";
  const char* stability_cells =
      "Each scenario is swept along its axis in the order given; an engine stops at its first "
      "failure. Cell: the largest value it survived (– : not even the first), then the first "
      "value it failed and how.\n";
  out << "\n## Error against run time\n\n" << error_cells;
  write_error_tables(out, kept(reference_scenes(header.quick), false), work);
  out << "\n## Stability\n\n" << stability_cells;
  write_stability_tables(out, kept(stability_scenarios(header.quick), false), stability);

  out << "\n## Joints\n\n"
         "The same measurements on jointed bodies. Every engine gets the same joint definitions "
         "in its own kind of joint: Bullet's btHingeConstraint and btPoint2PointConstraint "
         "(sequential impulses), Bullet's btMultiBody (Featherstone's generalised coordinates: "
         "trees of joints hanging from the world), ODE's hinge, ball and slider joints "
         "(dWorldQuickStep, and dWorldStep: its direct LCP solver), MuJoCo's hinge, ball and "
         "slide joints in generalised coordinates (a joint cannot come apart there: the accuracy "
         "anchor for joint gaps). What an adapter does not map (Bullet's sliders and limits, "
         "the multibodies' cones and free bodies, MuJoCo's motors and restitution) is refused "
         "and shown, never approximated. A joint's gap is read from the bodies' poses, the same "
         "way for every engine; a body's velocity that its joint cannot carry (the kicked end "
         "of a hanging chain) is given to the peers in generalised coordinates as its momentum, "
         "a force over the first step.\n\n"
         "**Error against run time.** "
      << error_cells;
  write_error_tables(out, kept(reference_scenes(header.quick), true), work);
  out << "\n**Stability.** " << stability_cells;
  write_stability_tables(out, kept(stability_scenarios(header.quick), true), stability);
  out << "\n### cost\n\n"
         "Milliseconds per step (dt 1/60, one thread unless the label says otherwise, sleeping "
         "off), beside how far the joints came apart meanwhile: the largest distance between a "
         "joint's two anchors, read from the bodies' poses the same way for every engine, the "
         "largest over the run and each step's largest averaged over the steps. The engines of "
         "a scene take turns of 20 steps, so that each meets the machine at the same speeds; a "
         "turn's first step is not timed. The time is the mean over the timed steps, and the "
         "ratio the median over the turns of the engine's turn over Bullet float's in the same "
         "turn (each turn's median step).\n\n"
         "| scene | engine | ms per step | × Bullet float | largest gap, m | mean gap, m | note "
         "|\n"
         "|---|---|---|---|---|---|---|\n";
  for (const CostRow& row : cost) {
    const bool ran = row.note.empty();
    out << "| " << row.scene << " | " << row.engine << " | "
        << (ran ? number(row.ms_per_step, "%.3g") : std::string("–")) << " | "
        << (ran && row.ratio_to_reference > 0 ? number(row.ratio_to_reference, "%.2f")
                                              : std::string("–"))
        << " | " << (ran ? number(row.worst_gap, "%.2g") : std::string("–")) << " | "
        << (ran ? number(row.mean_gap, "%.2g") : std::string("–")) << " | " << cell(row.note)
        << " |\n";
  }
  if (!out) {
    *error = "cannot write " + path;
    return false;
  }
  return true;
}

}  // namespace tumble::report
