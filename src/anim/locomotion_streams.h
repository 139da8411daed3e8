// Locomotion through animation streams: the crowd simulation's agents
// animated by a few shared streams instead of per-agent synthesis, except
// near the camera.
//
// One stream per speed bucket: the locomotion blend space's segments cut
// into buckets of the blend weight w exactly as the motion cache cuts them
// (cache_key / cache_bucket: segment * bucket_count + bucket), each played
// by a Blend1DController at its bucket's centre speed, with a history of
// one whole cycle (ceil(frames per cycle) + 1 slots). An agent reads the
// stream of its speed's bucket at the offset that shows its own gait phase;
// while it stays in the bucket it keeps its offset, so it plays at the
// stream's cadence. Agents close to the camera (any body part at LOD level
// 0: its bounding sphere covers at least `exact_coverage` square pixels)
// get exact per-agent synthesis instead (anim::PoseJob at their own speed
// and phase), written into the same palette layout.
//
//   auto space = std::make_shared<const motion::BlendSpace1D>(motion::make_default_blend_space());
//   LocomotionStreams loco(space, agents, {.frame_rate = 30});
//   each frame:
//     loco.drive_from_map(sim_positions, sim_velocities, sim_headings);   // device spans, map coordinates
//     const LocomotionStreamsStats& stats = loco.animate(&camera);        // one animation frame
//     renderer: loco.palette_refs(), positions(), yaws() (render::poses_of)
//
// Per frame, all on the device but a few host decisions about streams:
// anim.from_map, anim.loco_streams_keys (exact near the camera or which bucket),
// a histogram of buckets in use (streams start, history filled, when first
// needed and stop when unused), the streams' step, anim.loco_streams_select
// (each agent's phase and desired stream and offset), anim.stream_retarget
// (transitions), for the exact agents a compaction, anim.pose and
// anim.joint_palette, then anim.loco_streams_refs: per agent a PaletteRef
// (anim/palette_ref.h) to its stream's slot or its own palette. No palette
// is written per streamed agent: the renderer composes the visible ones
// (render::poses_of), and palettes() composes all of them on request.
//
// The error this sharing costs (sharing_error) and the foot skating of
// agents (track, foot_skating) are measured by the same object;
// docs/streams.md has the figures.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "anim/blend_controller.h"
#include "anim/crowd_animator.h"
#include "anim/lod.h"
#include "anim/palette_ref.h"
#include "anim/stream_crowd.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "core/span.h"
#include "motion/foot_skating.h"
#include "motion/locomotion.h"

namespace throng::anim {

// World joint transforms (PoseJob's outputs, character-major) as skinning
// palettes: palettes[palette_offsets[agents[c]] + j] = [R | P] * inverse_bind[j]
// (R scaled by scales[c] when given). agents empty: c itself; palette_offsets
// empty: agent * joint_count. ("anim.joint_palette")
struct JointPaletteJob {
  std::int32_t joint_count = 0;
  Span<const glm::vec3> joint_positions;  // characters * joint_count
  Span<const glm::quat> joint_rotations;
  Span<const Mat3x4> inverse_bind;    // joint_count
  Span<const float> scales;           // characters, or empty
  Span<const Index> agents;           // characters, or empty
  Span<const Index> palette_offsets;  // per agent, or empty
  Span<Mat3x4> palettes;

  Index character_count() const { return joint_count > 0 ? joint_positions.size() / joint_count : 0; }
  void validate() const;
  void run() const;
};

// Per agent: exact synthesis (near the camera) or the speed bucket whose
// stream it reads ("anim.loco_streams_keys"). Near means some body part's
// sphere covers at least exact_coverage square pixels, as LodJob measures
// it (level 0 under that threshold). A sphere round the whole body is
// tried first: a part inside it covers no more than it does, so an agent
// far from the camera costs one projection instead of five.
struct StreamBucketJob {
  motion::BlendSpaceView blend;  // quantised to the buckets (BlendSpaceView::quantum)
  float bucket_width = 0.05f;
  std::int32_t bucket_count = 20;
  Span<const float> speeds;  // per agent, m/s
  // The exact decision; near_camera false: nobody is exact.
  bool near_camera = false;
  CameraView camera;
  float exact_coverage = 1000.0f;
  glm::vec4 part_spheres[kBodyPartCount]{};  // BodyParts::rest_spheres (a plain array: it travels into kernels)
  glm::vec4 body_sphere{0.0f};               // holds every part sphere; centre on the +Y axis
  Span<const glm::vec3> positions;           // per agent, world (near_camera only)
  Span<const float> yaws;
  Span<std::uint8_t> exact;        // out: 1 = synthesised
  Span<std::int32_t> exact_flags;  // out: the same as 0/1 integers (to scan)
  Span<std::int32_t> keys;         // out: cache_key of the bucket, -1 for exact agents

  Index agent_count() const { return speeds.size(); }
  void validate() const;
  void run() const;
};

// The sphere round a character's part spheres, centred above its ground
// point (so that it does not turn with the character).
glm::vec4 body_sphere(const glm::vec4 (&parts)[kBodyPartCount]);

// Per agent: the gait phase it shows this frame and the stream and offset
// it should read ("anim.loco_streams_select"). An exact agent advances at
// its own cadence and wants no stream. A streamed agent still on its
// bucket's stream keeps its offset (it plays at the stream's cadence);
// one joining a stream advances at the bucket's cadence and takes the slot
// nearest its phase. Either way its phase becomes that slot's phase:
// head phase - offset / frames per cycle. The stream of key k is stream k.
struct StreamSelectJob {
  motion::BlendSpaceView blend;      // exact agents' cadence
  motion::BlendSpaceView quantised;  // streamed agents' cadence
  float dt = 1.0f / 30.0f;
  Span<const float> speeds;
  Span<const std::uint8_t> exact;
  Span<const std::int32_t> keys;
  Span<const float> key_phases;  // per key: phase of its stream's newest slot
  Span<const float> key_frames;  // per key: frames per cycle
  Span<const SourceView> streams;
  Span<const ClusterRef> clusters;  // the crowd's: which stream each agent reads now (cluster 0 for all)
  std::int32_t cluster_stride = 1;
  Span<float> phases;          // in/out
  Span<std::int32_t> sources;  // out
  Span<std::int32_t> offsets;  // out

  Index agent_count() const { return speeds.size(); }
  void validate() const;
  void run() const;
};

// The exact agents' inputs gathered densely: agent a with exact[a] goes to
// slot ranks[a] (an exclusive scan of the flags). ("anim.loco_streams_gather")
struct ExactGatherJob {
  Span<const std::uint8_t> exact;
  Span<const std::int32_t> ranks;
  Span<const glm::vec3> positions;
  Span<const float> yaws, phases, speeds;
  Index count = 0;  // exact agents: the ranks run from 0 to count - 1
  Span<glm::vec3> out_positions;
  Span<float> out_yaws, out_phases, out_speeds;
  void validate() const;  // Error naming the field
  void run() const;
};

// Per agent, the palette reference the renderer composes (anim/palette_ref.h;
// "anim.loco_streams_refs"): a streamed agent's slot of its stream and,
// while a transition runs, the slot it leaves with the transition's alpha;
// an exact agent's own world palette at exact_palettes[rank * joint_count].
// Every cluster of a locomotion agent reads the same slot, so cluster 0
// stands for all.
struct StreamRefsJob {
  Span<const SourceView> streams;
  Span<const ClusterRef> clusters;
  std::int32_t cluster_stride = 1;
  std::int32_t frame = 0;  // the crowd's last stepped frame (transition alphas)
  std::int32_t joint_count = 0;
  Span<const std::uint8_t> exact;
  Span<const std::int32_t> exact_ranks;  // exclusive scan of the exact flags
  Span<const Mat3x4> exact_palettes;     // world space, the exact agents densely
  Span<PaletteRef> refs;                 // out, per agent

  Index agent_count() const { return refs.size(); }
  void validate() const;
  void run() const;
};

struct LocomotionStreamsConfig {
  float frame_rate = 30.0f;     // animation frames per second: one animate() call is one frame
  float bucket_width = 0.05f;   // of w per segment (MotionCacheConfig::bucket_width's rule)
  float blend_seconds = 0.25f;  // cross-fade when an agent's bucket changes
  bool exact_near_camera = true;
  // Square pixels: an agent whose largest body-part sphere covers at least
  // this much (LOD level 0 under the default thresholds, docs/lod.md) is
  // synthesised exactly.
  float exact_coverage = 1000.0f;
  float stop_after_seconds = 2.0f;  // a stream no agent targets for this long stops
  std::uint64_t seed = 1;           // initial gait phases
  bool footstep_events = false;     // footsteps delivered to agents (crowd().agent_events(): a pass over the crowd)
  void validate() const;            // Error naming "locomotion_streams.<field>"
};

struct LocomotionStreamsStats {
  Index agents = 0;
  Index streamed = 0;        // posed from a stream
  Index exact = 0;           // synthesised per agent
  Index retargeted = 0;      // agents that changed stream this frame (a transition started)
  std::int32_t streams = 0;  // defined: one per speed bucket
  std::int32_t streams_running = 0;
  std::int32_t streams_in_use = 0;    // targeted by at least one agent this frame
  std::int32_t streams_started = 0;   // this frame (history filled at once)
  std::size_t pose_bytes = 0;         // every stream's history (StreamMemory::stream_poses)
  std::size_t exact_bytes = 0;        // the exact path's per-agent joint buffers this frame
  std::size_t agent_state_bytes = 0;  // cluster refs, rigs, events, palette offsets, phases, speeds, flags
  std::size_t palette_bytes = 0;      // the exact agents' own palettes
  std::size_t ref_bytes = 0;          // the agents' palette references
};

// Joint position error of streamed agents against exact synthesis (the same
// agents synthesised at their own speed, at the phase they show), in cm.
struct SharingError {
  Index agents = 0;                 // streamed agents compared
  double max_cm = 0.0;              // over agents and joints
  double mean_cm = 0.0;             // of every agent's largest joint error
  double p95_cm = 0.0;              // of every agent's largest joint error
  std::vector<float> agent_max_cm;  // per compared agent (agent order)
  // The agents cross-fading between two streams (a bucket change under
  // way) show a blend of both; the others, steady, only their bucket's.
  Index fading = 0;
  double steady_max_cm = 0.0;
  double steady_p95_cm = 0.0;
};

class LocomotionStreams {
 public:
  LocomotionStreams(std::shared_ptr<const motion::BlendSpace1D> space, Index agents,
                    LocomotionStreamsConfig config = {});

  Index agent_count() const { return count_; }
  std::int32_t joint_count() const { return joints_; }
  const LocomotionStreamsConfig& config() const { return config_; }
  const motion::BlendSpace1D& blend_space() const { return *space_; }
  const Rig& rig() const { return crowd_.rig(0); }
  // Read only: every cluster of an agent follows its speed's stream (the
  // palette references read cluster 0 for all).
  const StreamCrowd& crowd() const { return crowd_; }
  std::int32_t bucket_count() const { return buckets_; }
  // The stream of a speed bucket (cache_key order) and the speed it plays.
  std::int32_t stream_of_key(std::int32_t key) const { return key; }
  float key_speed(std::int32_t key) const { return key_speed_[static_cast<std::size_t>(key)]; }

  // ---- inputs (world: Y up, yaw about +Y, core/ground.h)
  // The simulation's own spans (map coordinates, headings CCW from +x).
  void drive_from_map(Span<const glm::vec2> positions, Span<const glm::vec2> velocities, Span<const float> headings);
  // Host arrays, agent_count() each.
  void set_agents(std::span<const glm::vec3> positions, std::span<const float> yaws, std::span<const float> speeds);
  void set_phases(std::span<const float> phases);  // gait phases in [0, 1) (random from the seed by default)

  // One animation frame (1 / frame_rate). camera null: nobody is exact.
  const LocomotionStreamsStats& animate(const Camera* camera);
  const LocomotionStreamsStats& last_frame() const { return stats_; }

  // ---- outputs (current_memory())
  // Per agent, how its palette is made (valid until the next animate()).
  Span<const PaletteRef> palette_refs() const { return refs_.span(); }
  // Every agent's palette, [agent * joint_count() + j], composed from the
  // references now (a pass over the whole crowd: for tests and measurements).
  Span<const Mat3x4> palettes() const;
  Span<const std::uint8_t> exact() const { return exact_.span(); }  // per agent: 1 = synthesised
  Span<const float> phases() const { return phase_.span(); }        // the gait phase each agent shows
  Span<const float> speeds() const { return speed_.span(); }
  Span<const glm::vec3> positions() const { return position_.span(); }
  Span<const float> yaws() const { return yaw_.span(); }

  // ---- measurements
  // Streamed agents' palettes this frame against PoseJob at their own speed
  // and shown phase (exact w): every joint's world position. at_most > 0:
  // that many agents evenly spread over the crowd are compared (memory in
  // proportion to them), else all.
  SharingError sharing_error(Index at_most = 0) const;
  // Foot skating: the world joints of these agents are recorded from their
  // palettes every frame from now on; foot_skating() measures every contact.
  void track(std::vector<Index> agents);
  motion::FootSkatingReport foot_skating(const motion::ContactOptions& options = {}) const;

 private:
  // The per-frame steps (their kernels are the jobs above, in
  // locomotion_streams_kernels.cpp: nvcc takes no device lambda in a private
  // member): exact or which bucket per agent; each agent's phase and desired
  // (stream, offset); the exact path; streams started filled / stopped by
  // use; the foot-skating probe.
  std::vector<Index> classify(const Camera* camera);  // agents per bucket
  void select(float dt);
  void synthesise_exact();
  void make_refs();
  void manage_streams(const std::vector<Index>& counts);
  void record_tracks();

  std::shared_ptr<const motion::BlendSpace1D> space_;
  LocomotionStreamsConfig config_;
  Index count_ = 0;
  std::int32_t joints_ = 0;
  std::int32_t buckets_ = 1;
  std::int32_t keys_ = 0;
  motion::BlendSpaceTables tables_;
  StreamCrowd crowd_;
  std::vector<Blend1DController*> controllers_;  // per key, owned by the streams
  std::vector<float> key_speed_;
  std::vector<float> key_frames_;        // frames per cycle, per key
  std::vector<std::int32_t> last_used_;  // per key: the last frame an agent targeted it
  Buffer<float> key_phase_;              // per key: phase of the head slot
  Buffer<float> key_frames_device_;
  // Per agent.
  Buffer<glm::vec3> position_;
  Buffer<float> yaw_, speed_, phase_;
  Buffer<std::uint8_t> exact_;
  Buffer<std::int32_t> key_, source_, offset_;
  Buffer<PaletteRef> refs_;
  mutable Buffer<Mat3x4> palettes_;  // palettes(), allocated on first use
  // The exact decision.
  glm::vec4 part_spheres_[kBodyPartCount]{};
  // The exact path, sized to the exact agents of the frame.
  Buffer<Mat3x4> inverse_bind_;
  Buffer<glm::vec3> bind_positions_;
  Buffer<std::int32_t> exact_rank_;
  Buffer<glm::vec3> exact_position_, joint_position_;
  Buffer<Mat3x4> exact_palettes_;
  Buffer<float> exact_yaw_, exact_phase_, exact_speed_;
  Buffer<glm::quat> joint_rotation_;
  LocomotionStreamsStats stats_;
  // Foot-skating probe: the tracked agents and their palettes each frame.
  motion::FootSkatingRecorder skating_;
  Buffer<Index> tracked_agents_;
  Buffer<Mat3x4> tracked_palettes_;
};

}  // namespace throng::anim
