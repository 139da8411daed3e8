// The file formats `throng run` writes trajectories in, named the same way
// in a scenario's `outputs.trajectories.format` and by `--trajectory-format`.
#pragma once

#include <string>

namespace throng::io {

enum class TrajectoryFormat {
  Csv,     // DIR/trajectories.csv: frame,time,agent,x,y,heading,speed
  Pedpy,   // DIR/trajectories.txt: PedPy's (and JuPedSim's) text format
  Sqlite,  // DIR/trajectories.sqlite: JuPedSim's SQLite schema, version 2
};

// "csv", "pedpy" or "sqlite"; anything else is an Error naming `field` and
// the accepted names. The one rule for the YAML key and the CLI flag.
TrajectoryFormat parse_trajectory_format(const std::string& text, const std::string& field);
const char* to_string(TrajectoryFormat format);
// The file under the output folder: trajectories.csv, .txt or .sqlite.
std::string trajectory_file_name(TrajectoryFormat format);

}  // namespace throng::io
