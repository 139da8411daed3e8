// libFuzzer target for the glTF crowd reader (io/crowd_gltf.h): any bytes
// either read as a crowd or throw throng::Error naming them; whatever reads
// must evaluate every agent's joints at every key to finite positions.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "core/error.h"
#include "io/crowd_gltf.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  try {
    const io::CrowdGlb glb = io::CrowdGlb::parse(std::span<const unsigned char>(data, size), "fuzz.glb");
    std::vector<glm::vec3> p;
    std::vector<glm::quat> q;
    std::vector<float> s;
    const std::int32_t frames = glb.frames() > 0 ? glb.frames() : 1;
    if (static_cast<std::int64_t>(glb.agents()) * frames * glb.joints() > (1 << 20)) return 0;
    for (Index a = 0; a < glb.agents(); ++a)
      for (std::int32_t f = 0; f < frames; ++f) glb.joint_frames(a, f, p, q, s);
  } catch (const Error& e) {
    if (e.location().file != "fuzz.glb") std::abort();  // every error names the input
  }
  return 0;
}
