// The list of suites `throng bench` runs. A new family adds its line here.
#include "bench/registry.h"

namespace throng::bench {

void register_all(const Options& options) {
  static bool done = false;  // Google Benchmark keeps registrations for the process
  if (done) return;
  done = true;
  register_core(options);
}

}  // namespace throng::bench
