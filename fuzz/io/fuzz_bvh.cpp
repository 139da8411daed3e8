// libFuzzer target for the BVH reader: any bytes either parse or throw
// throng::Error; whatever parses must also write and parse back unchanged in
// shape (joints, frames, channels per frame), and its FK must be finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/error.h"
#include "io/bvh_reader.h"
#include "io/bvh_writer.h"
#include "motion/fk.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  io::BvhReadOptions options;
  // Small limits keep each run fast; the checks are the same code as in production.
  options.limits.max_joints = 256;
  options.limits.max_frames = 20000;
  options.limits.max_poses = 1 << 20;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  io::BvhFile file;
  try {
    file = io::parse_bvh(text, "fuzz.bvh", options);
  } catch (const Error& e) {
    if (e.location().line <= 0) std::abort();  // every parse error names its line
    return 0;
  }
  // Parsed: the writer must accept it and the reader must take it back.
  io::BvhWriteOptions w;
  w.unit = file.unit;
  w.frame_time = file.frame_time;
  io::BvhReadOptions again_options = options;
  again_options.unit = file.unit;
  const io::BvhFile again =
      io::parse_bvh(io::write_bvh_string(file.skeleton, file.clip, w), "again.bvh", again_options);
  if (again.skeleton.joint_count() != file.skeleton.joint_count() || again.clip.frame_count != file.clip.frame_count)
    std::abort();
  if (file.clip.frame_count > 0 && file.clip.frame_count * file.skeleton.joint_count() < 4096) {
    const motion::ModelSpaceClip ms = motion::forward_kinematics(file.skeleton, file.clip);
    for (const auto& p : ms.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  }
  return 0;
}
