// MP4 video through ffmpeg: raw RGBA frames piped to `ffmpeg` (H.264,
// yuv420p, playable everywhere). ffmpeg is a Debian package that
// scripts/setup.sh installs; a missing ffmpeg is a clear Error.
#pragma once

#include <cstdint>
#include <string>

#include "core/config.h"
#include "core/output_file.h"
#include "render/image.h"

namespace throng::render {

struct VideoSpec {
  std::string path;           // .mp4
  std::int32_t width = 960;   // even (yuv420p)
  std::int32_t height = 540;  // even
  double fps = 30.0;
  std::int32_t crf = 23;          // H.264 quality: 0 (lossless) .. 51 (worst)
  std::string ffmpeg = "ffmpeg";  // executable name or path
  void validate() const;          // Error naming the field ("video.width")
};

// True when `ffmpeg -version` runs.
bool ffmpeg_available(const std::string& executable = "ffmpeg");

class VideoWriter {
 public:
  // Starts ffmpeg writing spec.path + ".partial" (core/output_file.h).
  // Throws Error when it cannot start.
  explicit VideoWriter(const VideoSpec& spec);
  // Without finish() (an error elsewhere ended the run): lets ffmpeg close
  // the file and keeps it as spec.path + ".partial", with a warning.
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Appends one frame (spec.width x spec.height, top row first). Throws
  // Error when the size differs or ffmpeg has stopped (with its message).
  void write(const Image& frame);
  // Closes the stream, waits for ffmpeg and renames the video into place;
  // throws Error with ffmpeg's message when it failed. Idempotent.
  void finish();
  Index frames_written() const { return frames_; }
  const VideoSpec& spec() const { return spec_; }

 private:
  [[noreturn]] void fail(const std::string& what);
  int close_stream();  // closes the pipe, waits for ffmpeg: its exit status (0 when already closed)
  VideoSpec spec_;
  OutputFile file_;
  int pid_ = -1;
  int pipe_ = -1;
  std::string log_path_;
  Index frames_ = 0;
  bool failed_ = false;  // ffmpeg stopped early: the video stays partial
};

}  // namespace throng::render
