// Animated crowds as glTF 2.0 binary files (.glb), for DCC tools (Blender,
// Maya, Houdini, Unreal): one skinned mesh (the rig's mannequin) shared by
// every agent, a joint hierarchy and a skin per agent, and one animation
// that keys every agent's joints at a fixed frame rate. Y up, metres: what
// glTF asks and what throng's world already is (core/ground.h).
//
// Layout, which CrowdGlb reads back:
//   - nodes: agent a owns nodes a * (J + 1) + j for its joints j (skeleton
//     order, children as in the skeleton), then a * (J + 1) + J, the node of
//     mesh 0 with skin a. The scene lists every agent's root joint and mesh
//     node.
//   - the root joint: translation and rotation keyed (world), scale the
//     agent's; every other joint: translation its skeleton offset, rotation
//     keyed (relative to its parent), so a DCC tool sees a plain armature.
//   - every skin reads the same inverse bind matrices: the inverse of each
//     joint's rest transform (a translation; the rest pose has no rotation).
//   - animation 0 ("crowd"): one input accessor (the key times) for all
//     channels; LINEAR interpolation.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "anim/rig.h"
#include "core/span.h"

namespace throng::io {

// Frames of a crowd's world joint frames, stored as glTF will key them.
class CrowdTake {
 public:
  // scales: one per agent (the characters' sizes; the root node's scale).
  CrowdTake(anim::Rig rig, std::vector<float> scales, double fps);

  // Appends one frame: world joint positions and rotations [a * J + j], as
  // the locomotion stage writes them (anim::CrowdAnimator).
  void add_frame(Span<const glm::vec3> joint_positions, Span<const glm::quat> joint_rotations);

  const anim::Rig& rig() const { return rig_; }
  Index agents() const { return static_cast<Index>(scales_.size()); }
  std::int32_t joints() const { return rig_.joint_count(); }
  std::int32_t frames() const { return frames_; }
  double fps() const { return fps_; }
  float scale(Index a) const { return scales_[static_cast<std::size_t>(a)]; }
  const glm::vec3& root_position(std::int32_t frame, Index a) const;
  // The root's world rotation, else the joint's rotation relative to its parent.
  const glm::quat& rotation(std::int32_t frame, Index a, std::int32_t joint) const;

  // Bytes of the .glb for this many agents and frames of a rig (within a
  // few kB): what `export-crowd` checks against its size limit up front.
  static double estimate_bytes(const anim::Rig& rig, Index agents, std::int64_t frames);

 private:
  anim::Rig rig_;
  std::vector<float> scales_;
  double fps_ = 24.0;
  std::int32_t frames_ = 0;
  std::vector<glm::vec3> root_positions_;  // [frame * agents + a]
  std::vector<glm::quat> rotations_;       // [(frame * agents + a) * J + j]
};

// Writes the take as a .glb (OutputFile: under .partial until complete).
// Throws Error naming the file on a write failure.
void write_crowd_glb(const std::string& path, const CrowdTake& take);

// A .glb laid out as above, parsed (tinygltf) and evaluated by forward
// kinematics over its nodes: what a DCC tool would show at each key.
class CrowdGlb {
 public:
  // Throws Error naming the file when it does not parse as glTF or is not
  // laid out as write_crowd_glb lays it out. Embedded images are skipped.
  explicit CrowdGlb(const std::string& path);
  // The same from bytes in memory; `name` names them in errors.
  static CrowdGlb parse(std::span<const unsigned char> bytes, const std::string& name);

  Index agents() const { return agents_; }
  std::int32_t joints() const { return joints_; }
  std::int32_t frames() const { return frames_; }
  double fps() const { return fps_; }
  // World frames of agent a's joints at key `frame` (its times are frame / fps).
  void joint_frames(Index a, std::int32_t frame, std::vector<glm::vec3>& positions, std::vector<glm::quat>& rotations,
                    std::vector<float>& scales) const;
  const std::vector<anim::Mat3x4>& inverse_bind() const { return inverse_bind_; }
  const anim::SkinnedMesh& mesh() const { return mesh_; }

 private:
  CrowdGlb() = default;
  void load(std::span<const unsigned char> bytes, const std::string& path);
  struct Node {
    std::int32_t parent = -1;  // within the agent's joints
    glm::vec3 translation{0.0f};
    glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
    float scale = 1.0f;
    std::int32_t translation_keys = -1, rotation_keys = -1;  // into translation_keys_, rotation_keys_; -1: not keyed
  };
  Index agents_ = 0;
  std::int32_t joints_ = 0, frames_ = 0;
  double fps_ = 0.0;
  std::vector<Node> nodes_;                               // [a * J + j]
  std::vector<std::vector<glm::vec3>> translation_keys_;  // per keyed channel, per frame
  std::vector<std::vector<glm::vec4>> rotation_keys_;     // per keyed channel, per frame: x, y, z, w
  std::vector<anim::Mat3x4> inverse_bind_;
  anim::SkinnedMesh mesh_;
};

}  // namespace throng::io
