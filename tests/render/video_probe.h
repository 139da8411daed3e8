// What ffprobe finds in a video file: the first video stream's codec, pixel
// format, size and decoded frame count, and the container's duration; and
// one frame decoded by ffmpeg. The one helper for every test that checks a
// video (tests/render/video_test.cpp, tests/app/run_test.cpp); header-only,
// so tests built without the renderer can use it too.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace throng::testing {

struct VideoProbe {
  std::string codec;    // e.g. "h264"; empty when ffprobe found no video stream
  std::string pix_fmt;  // e.g. "yuv420p"
  int width = 0;
  int height = 0;
  long frames = -1;        // frames decoded (nb_read_frames); -1 when unknown
  double duration = -1.0;  // seconds, the container's; -1 when unknown
  std::string text;        // what ffprobe printed, for failure messages
};

inline std::ostream& operator<<(std::ostream& os, const VideoProbe& p) { return os << "ffprobe said:\n" << p.text; }

// Runs `ffprobe -count_frames` (it decodes every frame) on `path`.
inline VideoProbe probe_video(const std::string& path) {
  const std::string cmd =
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,pix_fmt,width,height,nb_read_frames:format=duration -of json '" +
      path + "' 2>&1";
  VideoProbe p;
  {
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
    char buf[256];
    while (pipe && fgets(buf, sizeof buf, pipe.get()) != nullptr) p.text += buf;
  }
  // The JSON starts at a line "{"; error lines may come before it.
  const std::size_t start = p.text.rfind('{', 0) == 0 ? 0 : p.text.find("\n{");
  if (start == std::string::npos) return p;
  const nlohmann::json j = nlohmann::json::parse(p.text.substr(start), nullptr, false);
  if (j.is_discarded()) return p;
  // ffprobe writes some numbers as strings ("nb_read_frames": "25").
  const auto number = [](const nlohmann::json& v, double otherwise) {
    if (v.is_number()) return v.get<double>();
    if (v.is_string()) {
      try {
        return std::stod(v.get<std::string>());
      } catch (const std::exception&) {
      }
    }
    return otherwise;
  };
  if (j.contains("streams") && j["streams"].is_array() && !j["streams"].empty()) {
    const nlohmann::json& s = j["streams"][0];
    p.codec = s.value("codec_name", "");
    p.pix_fmt = s.value("pix_fmt", "");
    p.width = static_cast<int>(number(s.value("width", nlohmann::json()), 0.0));
    p.height = static_cast<int>(number(s.value("height", nlohmann::json()), 0.0));
    p.frames = static_cast<long>(number(s.value("nb_read_frames", nlohmann::json()), -1.0));
  }
  if (j.contains("format")) p.duration = number(j["format"].value("duration", nlohmann::json()), -1.0);
  return p;
}

// Frame `index` (0 = the first) of the first video stream, decoded to RGB:
// 3 bytes a pixel, rows top to bottom; empty when there is no such frame.
inline std::vector<std::uint8_t> decode_frame_rgb(const std::string& path, long index) {
  const std::string cmd = "ffmpeg -v error -i '" + path + "' -vf 'select=eq(n\\," + std::to_string(index) +
                          ")' -frames:v 1 -f rawvideo -pix_fmt rgb24 - 2>/dev/null";
  std::vector<std::uint8_t> rgb;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::array<std::uint8_t, 65536> buf;
  std::size_t n;
  while (pipe && (n = fread(buf.data(), 1, buf.size(), pipe.get())) > 0)
    rgb.insert(rgb.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  return rgb;
}

// Distinct colours in RGB pixels: a drawn scene has hundreds, a cleared or black picture a handful.
inline std::size_t distinct_colours_rgb(const std::vector<std::uint8_t>& rgb) {
  std::set<std::uint32_t> colours;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
    colours.insert(static_cast<std::uint32_t>(rgb[i]) << 16 | static_cast<std::uint32_t>(rgb[i + 1]) << 8 | rgb[i + 2]);
  return colours.size();
}

}  // namespace throng::testing
