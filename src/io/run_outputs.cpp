#include "io/run_outputs.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/output_file.h"

namespace throng::io {

TrajectoryWriter::TrajectoryWriter(std::string path, std::int64_t every) : path_(std::move(path)), every_(every) {
  if (every_ < 1) throw Error(fmt::format("the trajectory stride must be >= 1 frame (got {})", every_), at_field("--every"));
  file_ = std::fopen(path_.c_str(), "wb");
  if (file_ == nullptr) throw Error(std::string("cannot open for writing: ") + std::strerror(errno), Location{path_, 0, 0, {}});
  std::fprintf(file_, "%s\n", kHeader);
  std::fflush(file_);
}

TrajectoryWriter::~TrajectoryWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void TrajectoryWriter::after_step(const sim::Simulation& sim, const sim::FrameInfo& frame) {
  if (file_ == nullptr || (frame.frame % every_ != 0 && !frame.last) || frame.frame == last_written_) return;
  const sim::CrowdState& c = sim.crowd();
  const std::vector<glm::vec2> p = c.position.to_vector(), v = c.velocity.to_vector();
  const std::vector<float> heading = c.heading.to_vector();
  const std::vector<std::uint8_t> flags = c.flags.to_vector();
  buffer_.clear();
  auto out = std::back_inserter(buffer_);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if ((flags[i] & sim::kAgentActive) == 0) continue;
    fmt::format_to(out, "{},{:.3f},{},{:.4f},{:.4f},{:.4f},{:.4f}\n", frame.frame, frame.time, i, p[i].x, p[i].y, heading[i],
                   std::hypot(v[i].x, v[i].y));
    ++rows_;
  }
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size() || std::fflush(file_) != 0)
    throw Error(std::string("write failed: ") + std::strerror(errno), Location{path_, 0, 0, {}});
  ++frames_;
  last_written_ = frame.frame;
}

void TrajectoryWriter::close() {
  if (file_ == nullptr) return;
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw Error(std::string("closing failed: ") + std::strerror(errno), Location{path_, 0, 0, {}});
}

void TrajectoryWriter::finish(const sim::Simulation&, nlohmann::json& stats) {
  close();
  stats["trajectories"] = {{"path", path_}, {"every_frames", every_}, {"frames", frames_}, {"rows", rows_}, {"columns", kHeader}};
}

void write_json_file(const std::string& path, const nlohmann::json& j) {
  OutputFile file(path);
  {
    std::ofstream out(file.writing_path(), std::ios::binary | std::ios::trunc);
    if (!out) throw Error("cannot open for writing", Location{path, 0, 0, {}});
    out << j.dump(2) << '\n';
    out.flush();
    if (!out) throw Error(std::string("write failed: ") + std::strerror(errno), Location{path, 0, 0, {}});
  }
  file.commit();
}

}  // namespace throng::io
