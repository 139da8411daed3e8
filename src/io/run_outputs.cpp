#include "io/run_outputs.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/output_file.h"
#include "core/spelling.h"
#include "io/sqlite_trajectories.h"

namespace throng::io {

TrajectoryFormat parse_trajectory_format(const std::string& text, const std::string& field) {
  if (text == "csv") return TrajectoryFormat::Csv;
  if (text == "pedpy") return TrajectoryFormat::Pedpy;
  if (text == "sqlite") return TrajectoryFormat::Sqlite;
  const std::string near = closest_name(text, std::vector<std::string>{"csv", "pedpy", "sqlite"});
  throw Error(fmt::format("unknown trajectory format '{}': expected csv, pedpy or sqlite{}", text,
                          near.empty() ? "" : " (did you mean '" + near + "'?)"),
              at_field(field));
}

const char* to_string(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::Csv: return "csv";
    case TrajectoryFormat::Pedpy: return "pedpy";
    case TrajectoryFormat::Sqlite: return "sqlite";
  }
  return "csv";
}

std::string trajectory_file_name(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::Csv: return "trajectories.csv";
    case TrajectoryFormat::Pedpy: return "trajectories.txt";
    case TrajectoryFormat::Sqlite: return "trajectories.sqlite";
  }
  return "trajectories.csv";
}

double trajectory_frame_rate(double dt, std::int64_t every) {
  const double fps = 1.0 / (dt * static_cast<double>(every));
  return std::stod(fmt::format("{:.6g}", fps));
}

namespace {

// A text file written a frame at a time: each frame is formatted into a
// buffer, then written and flushed whole, so the file always ends on a
// complete frame.
class TextSink : public TrajectorySink {
 public:
  explicit TextSink(std::string path) : path_(std::move(path)) {
    file_ = std::fopen(path_.c_str(), "wb");
    if (file_ == nullptr)
      throw Error(std::string("cannot open for writing: ") + std::strerror(errno), Location{path_, 0, 0, {}});
  }
  ~TextSink() override {
    if (file_ != nullptr) std::fclose(file_);
  }
  TextSink(const TextSink&) = delete;
  TextSink& operator=(const TextSink&) = delete;

  void close() override {
    if (file_ == nullptr) return;
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (rc != 0) throw Error(std::string("closing failed: ") + std::strerror(errno), Location{path_, 0, 0, {}});
  }

 protected:
  void put(const std::string& text) {
    if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fflush(file_) != 0)
      throw Error(std::string("write failed: ") + std::strerror(errno), Location{path_, 0, 0, {}});
  }
  std::string buffer_;

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

class CsvSink final : public TextSink {
 public:
  explicit CsvSink(std::string path) : TextSink(std::move(path)) { put(std::string(TrajectoryWriter::kHeader) + "\n"); }
  void write(const TrajectoryFrame& f) override {
    buffer_.clear();
    auto out = std::back_inserter(buffer_);
    for (const TrajectoryRow& r : f.rows)
      fmt::format_to(out, "{},{:.3f},{},{:.4f},{:.4f},{:.4f},{:.4f}\n", f.step, f.time, r.agent, r.x, r.y, r.heading,
                     r.speed);
    put(buffer_);
  }
  bool uniform_frames() const override { return false; }
  std::string columns() const override { return TrajectoryWriter::kHeader; }
};

// PedPy's text trajectory format (pedpy.io.load_trajectory_from_txt), the
// plain format JuPedSim wrote: '#' comment lines first, one of them holding
// "framerate" and a number, one naming the unit ("x/m"), then whitespace-
// separated rows `id frame x y z`. PedPy reads the first four columns; ids
// start at 1 as in JuPedSim's files. The comments avoid the phrases PedPy
// takes for units ("in cm", "x/cm").
class PedpySink final : public TextSink {
 public:
  PedpySink(std::string path, double fps) : TextSink(std::move(path)), fps_(fps) {
    put(
        fmt::format("#description: trajectories written by throng run\n"
                    "#framerate: {}\n"
                    "#geometry: geometry.wkt\n"
                    "#ID: the agent ID, from 1 (agent index + 1)\n"
                    "#FR: the frame, from 0 (step / every; time = FR / fps)\n"
                    "#X,Y,Z: the agent coordinates in metres (Z = 0)\n"
                    "#id\tframe\tx/m\ty/m\tz/m\n",
                    fps_));
  }
  void write(const TrajectoryFrame& f) override {
    buffer_.clear();
    auto out = std::back_inserter(buffer_);
    for (const TrajectoryRow& r : f.rows)
      fmt::format_to(out, "{}\t{}\t{:.4f}\t{:.4f}\t0\n", r.agent + 1, f.index, r.x, r.y);
    put(buffer_);
  }
  bool uniform_frames() const override { return true; }
  std::string columns() const override { return "id frame x y z"; }
  void describe(nlohmann::json& section) const override { section["framerate"] = fps_; }

 private:
  double fps_;
};

std::unique_ptr<TrajectorySink> make_sink(const TrajectoryOutput& o) {
  const double fps = trajectory_frame_rate(o.dt, o.every);
  switch (o.format) {
    case TrajectoryFormat::Pedpy: return std::make_unique<PedpySink>(o.path, fps);
    case TrajectoryFormat::Sqlite: return std::make_unique<SqliteTrajectorySink>(o.path, fps, o.geometry_wkt);
    case TrajectoryFormat::Csv: break;
  }
  return std::make_unique<CsvSink>(o.path);
}

}  // namespace

TrajectoryWriter::TrajectoryWriter(TrajectoryOutput output)
    : output_(std::move(output)), file_(output_.path, OutputFile::OnFailure::KeepPartial) {
  if (output_.every < 1)
    throw Error(fmt::format("the trajectory stride must be >= 1 frame (got {})", output_.every), at_field("--every"));
  if (!(output_.dt > 0)) throw Error(fmt::format("the time step must be > 0 s (got {})", output_.dt), at_field("dt"));
  TrajectoryOutput writing = output_;
  writing.path = file_.writing_path();
  sink_ = make_sink(writing);
}

TrajectoryWriter::~TrajectoryWriter() = default;

bool TrajectoryWriter::due(const sim::FrameInfo& frame) const {
  if (sink_ == nullptr || frame.frame == last_written_) return false;
  return frame.frame % output_.every == 0 || (frame.last && !sink_->uniform_frames());
}

void TrajectoryWriter::after_step(const sim::Simulation& sim, const sim::FrameInfo& frame) {
  if (!due(frame)) return;
  const sim::CrowdState& c = sim.crowd();
  const std::vector<glm::vec2> p = c.position.to_vector(), v = c.velocity.to_vector();
  const std::vector<float> heading = c.heading.to_vector();
  const std::vector<std::uint8_t> flags = c.flags.to_vector();
  buffer_.clear();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if ((flags[i] & sim::kAgentActive) == 0) continue;
    buffer_.push_back({static_cast<std::int64_t>(i), p[i].x, p[i].y, heading[i], std::hypot(v[i].x, v[i].y)});
  }
  sink_->write({frame.frame, frame.frame / output_.every, frame.time, buffer_});
  rows_ += static_cast<std::int64_t>(buffer_.size());
  ++frames_;
  last_written_ = frame.frame;
}

void TrajectoryWriter::finish(const sim::Simulation&, nlohmann::json& stats) {
  if (sink_ == nullptr) return;
  sink_->close();
  file_.commit();
  nlohmann::json section = {{"format", to_string(output_.format)},
                            {"path", output_.path},
                            {"every_frames", output_.every},
                            {"frames", frames_},
                            {"rows", rows_},
                            {"columns", sink_->columns()}};
  sink_->describe(section);
  stats["trajectories"] = std::move(section);
}

void write_text_file(const std::string& path, const std::string& text) {
  OutputFile file(path);
  {
    std::ofstream out(file.writing_path(), std::ios::binary | std::ios::trunc);
    if (!out) throw Error("cannot open for writing", Location{path, 0, 0, {}});
    out << text;
    out.flush();
    if (!out) throw Error(std::string("write failed: ") + std::strerror(errno), Location{path, 0, 0, {}});
  }
  file.commit();
}

void write_json_file(const std::string& path, const nlohmann::json& j) { write_text_file(path, j.dump(2) + "\n"); }

}  // namespace throng::io
