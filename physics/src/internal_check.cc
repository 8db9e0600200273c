#include <cstdio>
#include <cstdlib>

#include "physics/status.h"

namespace tumble {

void internal_check_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "tumble: internal check failed: %s (%s:%d)\n", condition, file, line);
  std::abort();
}

}  // namespace tumble
