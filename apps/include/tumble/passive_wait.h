// Our programs' OpenMP threads sleep when they wait, unless the user's OMP_WAIT_POLICY says
// otherwise. Measured on a 2-core machine with one other busy process (docs/PERFORMANCE.md,
// "Threads on a busy machine"): libgomp's default, spinning, took 1.1-2.4 ms a step on a pile of
// 200 with 2 threads against 0.8-1.0 ms waiting passively (1 thread: 0.7-0.9 ms); on a quiet
// machine passive waiting costs about a tenth on a pile of 2000.
//
// libgomp reads the variable once, in its initialiser, before main runs; there is no call to
// change the policy afterwards, and a variable set before main is overwritten by libc's own
// initialisation. So the program sets it and executes itself again, once, at the top of main.
#pragma once

#include <unistd.h>

#include <cstdlib>

namespace tumble::cli {

// Call first in main. Returns only if the policy is already set, or the program cannot execute
// itself again (no /proc): it then goes on with libgomp's default.
inline void wait_passively_by_default(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  setenv("OMP_WAIT_POLICY", "passive", /*overwrite=*/1);
  execv("/proc/self/exe", argv);
}

}  // namespace tumble::cli
