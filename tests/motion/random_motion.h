// Random skeletons and clips for tests (not a test file itself).
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <random>
#include <string>

#include "motion/clip.h"
#include "motion/rotation.h"
#include "motion/skeleton.h"

namespace throng::motion::testing {

// `joints` joints with offsets of 5 to 40 cm. Depth first (pre-order) when
// asked, as BVH files are; otherwise any parent-before-child order.
inline Skeleton random_skeleton(std::mt19937& rng, int joints, bool depth_first = true) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.05f, 0.4f);
  Skeleton s;
  for (int i = 0; i < joints; ++i) {
    std::int32_t parent = -1;
    if (i > 0) {
      if (depth_first) {  // the previous joint or one of its ancestors
        parent = i - 1;
        for (int up = static_cast<int>(rng() % 3); up > 0 && s.parents[static_cast<std::size_t>(parent)] >= 0; --up)
          parent = s.parents[static_cast<std::size_t>(parent)];
      } else {
        parent = static_cast<std::int32_t>(rng() % static_cast<unsigned>(i));
      }
    }
    const glm::vec3 dir = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 0.01f));
    std::string name = "j";  // appended: GCC 12 warns falsely (-Wrestrict) on "j" + std::string
    name.append(std::to_string(i));
    s.add_joint(name, parent, i == 0 ? glm::vec3(0.0f, 0.9f, 0.0f) : dir * len(rng));
    if (rng() % 3 == 0) {
      s.has_end_site.back() = 1;
      s.end_sites.back() = glm::vec3(0.0f, len(rng), 0.0f);
    }
  }
  return s;
}

// Random unit rotations; every 7th is exactly at gimbal lock of a random
// order; with `animate_translations`, every 4th joint slides.
inline Clip random_clip(const Skeleton& s, int frames, std::mt19937& rng, bool animate_translations) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_real_distribution<double> angle(-3.1, 3.1);
  std::uniform_real_distribution<float> pos(-5.0f, 5.0f);
  Clip c;
  c.resize(frames, s.joint_count());
  c.frame_time = 1.0f / 120.0f;
  if (animate_translations)
    c.translations.resize(static_cast<std::size_t>(frames) * static_cast<std::size_t>(s.joint_count()));
  int k = 0;
  for (int f = 0; f < frames; ++f) {
    c.root_positions[static_cast<std::size_t>(f)] = glm::vec3(pos(rng), 1.0f + 0.1f * pos(rng), pos(rng));
    for (int j = 0; j < s.joint_count(); ++j) {
      glm::quat q;
      if (++k % 7 == 0) {
        const EulerOrder o = kAllEulerOrders[rng() % 6];
        glm::dvec3 a(angle(rng), angle(rng), angle(rng));
        a[euler_axes(o)[1]] = (rng() % 2 ? 1 : -1) * 1.5707963267948966;
        q = glm::quat(euler_to_quat(o, a));
      } else {
        q = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
      }
      c.rotation(f, j) = q;
      if (animate_translations) {
        const glm::vec3 rest = s.offsets[static_cast<std::size_t>(j)];
        c.translations[static_cast<std::size_t>(f) * static_cast<std::size_t>(s.joint_count()) +
                       static_cast<std::size_t>(j)] =
            (j % 4 == 3) ? rest + 0.1f * glm::vec3(g(rng), g(rng), g(rng)) : rest;
      }
    }
  }
  return c;
}

}  // namespace throng::motion::testing
