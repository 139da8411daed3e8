// libFuzzer target for the motion state machine reader: any bytes either
// read or throw throng::Error naming a file position; a machine that reads
// is built on the default skeleton (clips synthesised, segments cut), and
// must then have at least one state and finite segment lengths.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/error.h"
#include "io/state_machine_yaml.h"
#include "motion/default_set.h"
#include "path/state_machine.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const path::StateMachineSpec spec = io::parse_state_machine(text, "fuzz.yaml");
    const path::MotionGraph m = path::MotionGraph::build(spec, motion::default_skeleton());
    if (m.states().empty() || !std::isfinite(m.segment_length())) std::abort();
  } catch (const Error& e) {
    if (e.location().line <= 0 && e.location().file.empty() && e.location().field.empty())
      std::abort();  // every error says where
  }
  return 0;
}
