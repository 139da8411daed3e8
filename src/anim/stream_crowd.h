// A crowd animated by streams: rigs, the StreamPool and UniquePool, and per
// agent its part clusters, each pointing at (source, offset into its
// history), transitions between sources, bone overrides and events.
//
//   StreamCrowd crowd({.frame_rate = 30});
//   const int human = crowd.add_rig(make_rig("humanoid", motion::default_skeleton()));
//   const int walk = crowd.streams().add(crowd.rig(human), human, {.name = "walk"}, std::make_unique<ClipPlayer>(clip));
//   const Index first = crowd.add_agents(human, 10000);
//   crowd.assign_random(first, 10000, {{walk}, {walk}, {walk}}, seed);
//   each frame:  crowd.step();  crowd.resolve(positions, yaws, palettes);
//
// step() advances every running stream and unique instance by one animation
// frame, applies the transitions requested since the last step and
// delivers events; resolve() writes every agent's skinning palette (one
// kernel over agents). Per-agent state lives in Buffers in the crowd's
// memory; the layout is in docs/streams.md.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include "anim/controller.h"
#include "anim/pose.h"
#include "anim/rig.h"
#include "anim/stream_pool.h"
#include "anim/stream_resolve.h"
#include "core/buffer.h"
#include "core/config.h"
#include "core/span.h"

namespace throng::anim {

// Which streams each cluster may pick from.
struct VarietySpec {
  std::vector<std::vector<std::int32_t>> streams;  // [cluster]: candidate streams (same rig)
  // Clusters that picked the same stream read it at the same offset, so a
  // walk's arms stay in phase with its legs.
  bool same_offset_per_stream = true;
};

struct StreamCrowdConfig {
  float frame_rate = 30.0f;  // animation frames per second (animFrameRate)
  std::uint64_t seed = 1;    // offsets chosen by transitions
  bool events = true;        // step() delivers the sources' events to agents (a pass over the crowd)
  void validate() const;
};

struct StreamMemory {
  std::size_t stream_poses = 0;  // StreamPool: sum over streams of M * (J * 16 + 12)
  std::size_t unique_poses = 0;  // UniquePool slots
  std::size_t agent_state = 0;   // cluster refs, rigs, palette offsets, events, overrides
  std::size_t palettes = 0;      // 48 bytes per agent joint, when the caller allocates them
  std::size_t total() const { return stream_poses + unique_poses + agent_state + palettes; }
};

class StreamCrowd {
 public:
  explicit StreamCrowd(StreamCrowdConfig config = {}, Memory memory = current_memory());
  ~StreamCrowd();

  const StreamCrowdConfig& config() const { return config_; }
  std::int32_t frame() const { return frame_; }  // the last frame stepped (-1 before the first step)
  double time() const { return (frame_ + 1) / static_cast<double>(config_.frame_rate); }

  // ---- setup
  std::int32_t add_rig(Rig rig);  // Error for a name used twice; no rigs after agents
  std::int32_t rig_count() const { return static_cast<std::int32_t>(rigs_.size()); }
  const Rig& rig(std::int32_t i) const { return rigs_[static_cast<std::size_t>(i)]; }
  std::int32_t find_rig(const std::string& name) const;
  std::int32_t cluster_stride() const { return cluster_stride_; }  // ClusterRef entries per agent
  EventNames& event_names() { return events_; }
  const EventNames& event_names() const { return events_; }
  StreamPool& streams() { return *streams_; }
  const StreamPool& streams() const { return *streams_; }
  UniquePool& uniques() { return *uniques_; }
  const UniquePool& uniques() const { return *uniques_; }

  // ---- agents
  // Appends `count` agents of a rig (clusters on the rest pose); returns the first index.
  Index add_agents(std::int32_t rig, Index count);
  Index agent_count() const { return agent_count_; }
  std::int32_t agent_rig(Index agent) const;
  // Points a cluster of agents [first, first + count) at a stream and
  // offset, at once (no transition).
  void assign(Index first, Index count, std::int32_t cluster, std::int32_t stream, std::int32_t offset);
  // Random stream per cluster from spec.streams[cluster] and random offset in
  // [0, M), from the seed: agent a's choice depends only on (seed, a).
  void assign_random(Index first, Index count, const VarietySpec& spec, std::uint64_t seed);
  void set_culled(Index agent, std::int32_t cluster, bool culled);
  // Which events a cluster index delivers (all by default); e.g. footsteps
  // only from the cluster that holds the legs.
  void set_event_filter(std::int32_t cluster, EventMask allowed);
  // A host copy of one agent's clusters (for tests and tools).
  std::vector<ClusterRef> clusters_of(Index agent) const;

  // ---- transitions, applied at the next step(): the cluster's current
  // target becomes the transition source and is blended out over
  // blend_seconds while the new target is blended in (SLERP per joint).
  // offset < 0: the offset of another cluster of the agent reading the same
  // stream, else a random one from the crowd's seed.
  void transition_to_streamed(Index agent, std::int32_t cluster, std::int32_t stream, float blend_seconds,
                              std::int32_t offset = -1);
  // A fresh instance of a unique animation (shared by the agent's clusters
  // that go to the same animation). When the animation has a duration and
  // then_stream >= 0, the cluster goes back to then_stream so as to arrive
  // when the animation ends, blending over then_blend seconds.
  void transition_to_unique(Index agent, std::int32_t cluster, std::int32_t animation, float blend_seconds,
                            std::int32_t then_stream = -1, float then_blend = 0.25f);
  std::int32_t pending_transitions() const { return static_cast<std::int32_t>(pending_.size()); }

  // ---- bone overrides (take effect at the next resolve)
  void set_override(Index agent, const BoneOverride& o);  // replaces an override of the same joint
  void clear_override(Index agent, std::int32_t joint);
  void clear_overrides(Index agent);

  // ---- per frame
  void step();
  // Writes every agent's palette: palettes[palette_offset(a) + j] =
  // world(a) * model_j * inverse_bind_j. positions/yaws (world, Y up, yaw
  // about +Y: core/ground.h) may be empty (model space). read_offsets, if
  // not empty (agents * cluster_stride), receives the history offset each
  // cluster actually read (-1 for none).
  // skip, if not empty (per agent): agents != 0 are posed by someone else
  // (exact synthesis) and their palettes are left as they are.
  void resolve(Span<const glm::vec3> positions, Span<const float> yaws, Span<Mat3x4> palettes,
               Span<std::int32_t> read_offsets = {}, Span<const std::uint8_t> skip = {}) const;
  // A desired stream and offset per agent for the clusters in cluster_mask,
  // applied now in one kernel (StreamRetargetJob: a new stream is blended
  // in over blend_seconds, the same stream takes the new offset at once,
  // kNoSource sets the rest pose, clusters on unique instances are left
  // alone). Call after step() and before resolve(). Spans in the crowd's
  // memory. Returns how many agents changed the source of some cluster.
  Index retarget(Span<const std::int32_t> sources, Span<const std::int32_t> offsets, float blend_seconds,
                 std::uint32_t cluster_mask = ~0u);

  // ---- data for the renderer and the simulation (in the crowd's memory)
  Index palette_size() const { return palette_size_; }                           // matrices for all agents
  Span<const Index> palette_offsets() const { return palette_offsets_.span(); }  // per agent
  Span<const std::int32_t> agent_rigs() const { return agent_rig_.span(); }
  Span<const ClusterRef> cluster_refs() const { return clusters_.span(); }     // agents * cluster_stride
  Span<const EventMask> agent_events() const { return agent_events_.span(); }  // per agent, the last step's events
  StreamMemory memory() const;

 private:
  struct UniqueRef {
    std::int32_t instance = -1;
    std::int32_t animation = -1;
    std::int32_t then_stream = -1;
    float then_blend = 0.0f;
  };
  struct RigTables;
  void rebuild_rig_tables();
  void rebuild_overrides() const;
  void queue(const ClusterCommand& c);
  void apply(std::vector<ClusterCommand> commands);
  void drop_unique_ref(Index key, std::int32_t release_frame);
  void release_unique(std::int32_t instance);
  std::int32_t random_offset(Index agent, std::int32_t cluster, std::int32_t stream, std::uint64_t salt) const;
  void check_agent_cluster(Index agent, std::int32_t cluster) const;

  StreamCrowdConfig config_;
  Memory memory_;
  std::vector<Rig> rigs_;
  EventNames events_;
  std::unique_ptr<StreamPool> streams_;
  std::unique_ptr<UniquePool> uniques_;
  std::unique_ptr<RigTables> tables_;
  std::int32_t cluster_stride_ = 1;
  std::int32_t frame_ = -1;

  Index agent_count_ = 0;
  Index palette_size_ = 0;
  std::vector<std::int32_t> host_agent_rig_;
  Buffer<std::int32_t> agent_rig_;
  Buffer<Index> palette_offsets_;
  Buffer<ClusterRef> clusters_;
  Buffer<EventMask> agent_events_;
  Buffer<std::uint8_t> retarget_changed_;

  std::vector<ClusterCommand> pending_;
  std::unordered_map<Index, std::size_t> pending_index_;  // agent * stride + cluster -> pending_
  std::uint64_t command_serial_ = 0;
  std::array<EventMask, kMaxClusters> event_filter_;
  // Unique instances: who targets them, references held, delayed releases.
  std::unordered_map<Index, UniqueRef> unique_targets_;                     // agent * stride + cluster
  std::map<std::pair<Index, std::int32_t>, std::int32_t> unique_by_agent_;  // (agent, animation) -> instance
  std::vector<std::int32_t> unique_refcount_;
  std::vector<std::pair<std::int32_t, std::int32_t>> delayed_releases_;  // (frame, instance)

  std::map<Index, std::vector<BoneOverride>> overrides_;
  mutable bool overrides_dirty_ = false;
  mutable Buffer<std::int32_t> override_begin_;  // agents + 1 (empty when no overrides)
  mutable Buffer<BoneOverride> override_list_;
};

}  // namespace throng::anim
