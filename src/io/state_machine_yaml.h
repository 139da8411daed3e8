// Motion state machines from YAML (format: docs/path.md), with
// file:line:column in every error. The default machine ships as
// data/motion/default_machine.yaml and is compiled into the library.
#pragma once

#include <string>
#include <string_view>

#include "path/state_machine.h"

namespace throng::io {

// Parses a machine; `name` is the file name used in error locations.
path::StateMachineSpec parse_state_machine(std::string_view text, const std::string& name);
path::StateMachineSpec read_state_machine(const std::string& file);

// The text of data/motion/default_machine.yaml as built into the library.
std::string_view default_state_machine_yaml();
path::StateMachineSpec default_state_machine_spec();

}  // namespace throng::io
