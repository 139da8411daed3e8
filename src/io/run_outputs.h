// What `throng run` writes: trajectories as a frame stage (CSV, PedPy text
// or JuPedSim SQLite), and JSON and text files written whole (to a temporary
// name, then renamed) so a reader never sees half a file, even when the run
// is interrupted.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <cmath>
#include <string>
#include <vector>

#include "core/output_file.h"
#include "io/trajectory_format.h"
#include "sim/frame_loop.h"

namespace throng::io {

// One active agent in a written frame (map coordinates: metres, x east,
// y north; heading in radians counter-clockwise from +x; speed in m/s).
struct TrajectoryRow {
  std::int64_t agent = 0;  // the agent's index in the crowd, from 0
  float x = 0, y = 0, heading = 0, speed = 0;
};

// A written frame: simulation step `step` at `time` seconds; `index` is
// step / every, the frame number of the formats with a frame rate.
struct TrajectoryFrame {
  std::int64_t step = 0, index = 0;
  double time = 0;
  std::span<const TrajectoryRow> rows;
};

// One file format. write() stores a frame completely (flushed, or
// committed) before it returns, so an interrupted run leaves whole frames.
class TrajectorySink {
 public:
  virtual ~TrajectorySink() = default;
  virtual void write(const TrajectoryFrame& frame) = 0;
  virtual void close() = 0;
  // Frames whose step is not a multiple of `every` (the run's last step)
  // are written only by formats without a fixed frame rate.
  virtual bool uniform_frames() const = 0;
  // For stats.json: what a row holds, and further keys (frame rate).
  virtual std::string columns() const = 0;
  virtual void describe(nlohmann::json& section) const { (void)section; }
};

struct TrajectoryOutput {
  TrajectoryFormat format = TrajectoryFormat::Csv;
  std::string path;          // the file to write
  std::int64_t every = 1;    // write every `every`-th step
  double dt = 0.1;           // s per step: the frame rate is 1 / (dt * every)
  std::string geometry_wkt;  // the walkable area (sqlite stores it)
};

// Frames per second of the written frames, 1 / (dt * every), rounded to 6
// significant digits: dt is a float, and 1 / (0.1f * 10) should read 1.
double trajectory_frame_rate(double dt, std::int64_t every);

// The frame stage `emit.trajectories`. Frame 0 is the initial state; every
// `every`-th step is written, and with CSV also the last one. The file is
// written as PATH.partial and renamed to PATH by finish() (core/output_file.h);
// a run that ends in an error keeps PATH.partial, with a warning.
//
// csv: DIR/trajectories.csv, one row per active agent per written frame,
//   frame,time,agent,x,y,heading,speed
// where frame is the simulation step and agent the index from 0.
// pedpy: DIR/trajectories.txt (see PedpySink in run_outputs.cpp).
// sqlite: DIR/trajectories.sqlite (see io/sqlite_trajectories.h).
class TrajectoryWriter : public sim::FrameStage {
 public:
  static constexpr const char* kHeader = "frame,time,agent,x,y,heading,speed";

  explicit TrajectoryWriter(TrajectoryOutput output);
  ~TrajectoryWriter() override;
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  std::string name() const override { return "emit.trajectories"; }
  void after_step(const sim::Simulation& sim, const sim::FrameInfo& frame) override;
  // Closes the file; adds the "trajectories" section (format, path, every,
  // frames, rows, columns; the frame rate for pedpy and sqlite).
  void finish(const sim::Simulation& sim, nlohmann::json& stats) override;

  std::int64_t rows() const { return rows_; }
  std::int64_t frames() const { return frames_; }

 private:
  bool due(const sim::FrameInfo& frame) const;
  TrajectoryOutput output_;
  OutputFile file_;  // declared before sink_: the sink closes the file before an abandoned one is kept
  std::unique_ptr<TrajectorySink> sink_;
  std::int64_t rows_ = 0, frames_ = 0, last_written_ = -1;
  std::vector<TrajectoryRow> buffer_;
};

// Writes `text` to `path` via a temporary file and a rename.
void write_text_file(const std::string& path, const std::string& text);
// Writes `j` to `path` (pretty-printed) the same way.
void write_json_file(const std::string& path, const nlohmann::json& j);

// A coordinate in metres rounded to the millimetre, for files: printed as
// typed (0.1, not the float's 0.100000001...), and never "-0".
inline double round_to_mm(float v) { return std::round(static_cast<double>(v) * 1000.0) / 1000.0 + 0.0; }

}  // namespace throng::io
