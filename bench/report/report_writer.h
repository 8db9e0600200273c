// Writes the report: CSV of every measurement (for the plots and other tools) and REPORT.md with
// the tables.
#pragma once

#include <string>
#include <vector>

#include "stability.h"
#include "work_precision.h"

namespace tumble::report {

struct ReportHeader {
  std::string command, date, machine, commit;
  bool quick = false;
  std::vector<std::string> engines;  // "label: settings"
};

// False with *error set when a file cannot be written.
bool write_csv(const std::string& directory, const std::vector<WorkPrecisionRow>& work,
               const std::vector<StabilityRow>& stability, const std::vector<CostRow>& cost,
               std::string* error);
bool write_markdown(const std::string& path, const ReportHeader& header,
                    const std::vector<WorkPrecisionRow>& work,
                    const std::vector<StabilityRow>& stability, const std::vector<CostRow>& cost,
                    std::string* error);

// What each engine survives in a scenario: the largest passing value before the first failure
// (NaN when the first value already fails), and the first failure's value and mode (empty when
// it never failed).
struct Survival {
  double largest_pass;
  double first_failure;
  std::string mode;
};
Survival survival(const std::vector<StabilityRow>& rows, const std::string& scenario,
                  const std::string& engine);

}  // namespace tumble::report
