// libFuzzer target for the animation streams YAML reader: any bytes either
// build a crowd or throw throng::Error naming a line; a crowd that builds
// must then animate a few agents per rig for a few frames with finite palettes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "io/streams_yaml.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  io::StreamsYamlOptions options;
  options.allow_files = false;
  options.limits.max_items = 16;
  options.limits.max_pose_bytes = 1u << 20;
  options.limits.max_controller_depth = 6;
  std::unique_ptr<anim::StreamCrowd> crowd;
  try {
    crowd = io::parse_stream_crowd(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml", options);
  } catch (const Error& e) {
    if (e.location().line <= 0 && e.location().file.empty()) std::abort();  // every error says where
    return 0;
  }
  for (std::int32_t r = 0; r < crowd->rig_count(); ++r) {
    const Index first = crowd->add_agents(r, 4);
    for (std::int32_t s = 0; s < crowd->streams().size(); ++s)
      if (crowd->streams()[s].rig() == r)
        for (std::int32_t c = 0; c < crowd->rig(r).clusters.count(); ++c) crowd->assign(first + c % 4, 1, c, s, 0);
  }
  std::vector<anim::Mat3x4> palettes(static_cast<std::size_t>(crowd->palette_size()));
  for (int f = 0; f < 3; ++f) {
    crowd->step();
    crowd->resolve({}, {}, palettes);
  }
  for (const anim::Mat3x4& m : palettes)
    if (!std::isfinite(m.r0.w) || !std::isfinite(m.r1.w) || !std::isfinite(m.r2.w)) std::abort();
  return 0;
}
