// Hostile inputs for the fuzzing suites: numbers at and beyond every limit, NaN and infinities,
// and byte-level mutations of files. Seeded, so a failure replays exactly.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "physics/limits.h"
#include "test_support.h"

namespace tumble::testing {

class Hostile {
 public:
  explicit Hostile(std::uint64_t seed) : rng_(seed) {}
  Random& rng() { return rng_; }
  bool chance(double p) { return rng_.uniform() < p; }
  int integer(int lo, int hi) { return rng_.integer(lo, hi); }

  // Mostly an ordinary value in [lo, hi]; otherwise one of the values that break programs.
  double number(double lo, double hi) {
    if (chance(0.6)) return rng_.uniform(lo, hi);
    return special();
  }
  double special() {
    const WorldLimits limits;
    const double inf = std::numeric_limits<double>::infinity();
    const double values[] = {0.0,
                             -0.0,
                             std::numeric_limits<double>::quiet_NaN(),
                             inf,
                             -inf,
                             1e308,
                             -1e308,
                             std::numeric_limits<double>::denorm_min(),
                             1e-300,
                             -1,
                             0x1p53,
                             limits.max_coordinate,
                             std::nextafter(limits.max_coordinate, inf),
                             -std::nextafter(limits.max_coordinate, inf),
                             limits.min_size,
                             std::nextafter(limits.min_size, 0.0),
                             limits.max_size,
                             std::nextafter(limits.max_size, inf),
                             limits.max_mass,
                             limits.min_mass,
                             limits.max_linear_speed,
                             std::nextafter(limits.max_linear_speed, inf),
                             limits.max_angular_speed,
                             std::nextafter(limits.max_angular_speed, inf),
                             1e18};
    return values[rng_.integer(0, static_cast<int>(std::size(values)) - 1)];
  }
  Vec3 vector(double lo, double hi) { return Vec3(number(lo, hi), number(lo, hi), number(lo, hi)); }

  // A copy of `bytes` damaged the ways files are: bits flipped, cut short, a piece repeated or
  // dropped, garbage appended.
  std::string mutate(const std::string& bytes) {
    std::string out = bytes;
    const int edits = integer(1, 4);
    for (int e = 0; e < edits && !out.empty(); ++e) {
      const std::size_t at = static_cast<std::size_t>(rng_.uniform() * out.size());
      switch (integer(0, 5)) {
        case 0:
          out[at] = static_cast<char>(out[at] ^ (1 << integer(0, 7)));
          break;
        case 1:
          out.resize(at);
          break;
        case 2: {
          const std::size_t length = std::min<std::size_t>(integer(1, 64), out.size() - at);
          out.insert(at, out.substr(at, length));
          break;
        }
        case 3:
          out.erase(at, std::min<std::size_t>(integer(1, 16), out.size() - at));
          break;
        case 4:
          out[at] = static_cast<char>(integer(0, 255));
          break;
        default:
          for (int k = integer(1, 16); k > 0; --k)
            out.push_back(static_cast<char>(integer(0, 255)));
      }
    }
    return out;
  }

 private:
  Random rng_;
};

// Counts for the closing note; printed by each suite.
struct FuzzTally {
  std::uint64_t tried = 0, accepted = 0, refused = 0;
  std::uint64_t half_applied = 0;  // refused, yet the world changed
  std::uint64_t poisoned = 0;      // the world held a value it should have refused
};

}  // namespace tumble::testing
