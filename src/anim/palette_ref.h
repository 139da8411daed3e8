// A character's skinning palette by reference to shared poses, so that a
// crowd animated by streams needs no palette of its own per agent: the
// renderer (and whoever else wants palettes) composes each joint's matrix
// when it packs the character.
//
// A streamed character points at its stream's history slot, whose
// model-space palette (model_j * inverse_bind_j) the stream wrote once for
// everyone reading it, and is placed by its root transform (yaw about +Y,
// then its ground point: core/ground.h). While it changes stream it also
// points at the slot it leaves and cross-fades the two matrices (a linear
// blend of the skinned vertices, which for the small steps between
// neighbouring speed buckets looks as the SLERP of StreamResolveJob's
// blended path does). A character posed by exact synthesis points at a
// palette of its own, already in world space.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "anim/pose.h"
#include "core/config.h"
#include "core/span.h"

namespace throng::anim {

struct PaletteRef {
  const Mat3x4* pose = nullptr;  // joint_count matrices: model space, or world space when `world`
  const Mat3x4* from = nullptr;  // the pose blended out (model space), or null
  float alpha = 1.0f;            // weight of `pose` against `from`
  std::uint32_t world = 0;       // 1: `pose` is in world space already (no root transform)
};

// The root transform of a character standing at `position` facing `yaw`.
THRONG_HOST_DEVICE inline Mat3x4 root_transform(const glm::vec3& position, float yaw) {
  return mat3x4_from(glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f)), position);
}

// Joint j's palette entry. A null pose is the rest pose at the root.
THRONG_HOST_DEVICE inline Mat3x4 compose_palette(const PaletteRef& r, const Mat3x4& root, std::int32_t j) {
  if (r.pose == nullptr) return root;
  if (r.world != 0u) return r.pose[j];
  Mat3x4 m = r.pose[j];
  if (r.from != nullptr && r.alpha < 1.0f) {
    const Mat3x4& f = r.from[j];
    m.r0 = f.r0 + r.alpha * (m.r0 - f.r0);
    m.r1 = f.r1 + r.alpha * (m.r1 - f.r1);
    m.r2 = f.r2 + r.alpha * (m.r2 - f.r2);
  }
  return root * m;
}

// Whole palettes from references ("anim.compose_palettes"): character
// agents[k] (k itself when agents is empty) into palettes[k * joint_count + j].
struct PaletteComposeJob {
  std::int32_t joint_count = 0;
  Span<const PaletteRef> refs;      // per agent
  Span<const glm::vec3> positions;  // per agent, world
  Span<const float> yaws;           // per agent
  Span<const Index> agents;         // the agents to compose, or empty: all
  Span<Mat3x4> palettes;            // (agents or refs).size() * joint_count

  Index count() const { return agents.empty() ? refs.size() : agents.size(); }
  void validate() const;  // Error naming the field
  void run() const;
};

}  // namespace throng::anim
