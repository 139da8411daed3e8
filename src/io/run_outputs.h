// What `throng run` writes: the trajectory CSV as a frame stage, and JSON
// files written whole (to a temporary name, then renamed) so a reader never
// sees half a file, even when the run is interrupted.
#pragma once

#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "sim/frame_loop.h"

namespace throng::io {

// DIR/trajectories.csv: one row per active agent per written frame,
//   frame,time,agent,x,y,heading,speed
// in map coordinates (metres, x east, y north; heading in radians
// counter-clockwise from +x; speed in m/s). Frame 0 is the initial state;
// every `every`-th frame and the last one are written. Each frame is flushed
// whole, so the file ends on a complete frame whenever the run stops.
class TrajectoryWriter : public sim::FrameStage {
 public:
  static constexpr const char* kHeader = "frame,time,agent,x,y,heading,speed";

  TrajectoryWriter(std::string path, std::int64_t every);
  ~TrajectoryWriter() override;
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  std::string name() const override { return "emit.trajectories"; }
  void after_step(const sim::Simulation& sim, const sim::FrameInfo& frame) override;
  // Closes the file; adds the "trajectories" section (path, every, frames, rows).
  void finish(const sim::Simulation& sim, nlohmann::json& stats) override;

  std::int64_t rows() const { return rows_; }
  std::int64_t frames() const { return frames_; }

 private:
  void close();
  std::string path_;
  std::int64_t every_;
  std::FILE* file_ = nullptr;
  std::int64_t rows_ = 0, frames_ = 0, last_written_ = -1;
  std::string buffer_;
};

// Writes `j` to `path` (pretty-printed) via a temporary file and a rename.
void write_json_file(const std::string& path, const nlohmann::json& j);

}  // namespace throng::io
