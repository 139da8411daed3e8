#include "anim/stream_crowd.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/array_kernels.h"
#include "core/random.h"

namespace throng::anim {

namespace {

template <class T>
Buffer<T> appended(const Buffer<T>& old, Index extra, const T& value, Memory memory) {
  std::vector<T> v = old.to_vector();
  v.insert(v.end(), static_cast<std::size_t>(extra), value);
  return Buffer<T>(std::span<const T>(v), memory);
}

template <class T>
Buffer<T> to_buffer(const std::vector<T>& v, Memory memory) {
  return Buffer<T>(std::span<const T>(v), memory);
}

template <class T>
std::size_t bytes_of(const Buffer<T>& b) {
  return static_cast<std::size_t>(b.size()) * sizeof(T);
}

}  // namespace

// Every rig's tables concatenated, in the crowd's memory.
struct StreamCrowd::RigTables {
  Buffer<RigView> rigs;
  Buffer<std::int32_t> parents;
  Buffer<glm::vec3> offsets;
  Buffer<std::uint8_t> joint_cluster;
  Buffer<Mat3x4> inverse_bind;
  Buffer<glm::quat> hook_rotations;
  Buffer<glm::vec3> hook_translations;
  Buffer<std::int32_t> hook_joints;
  Buffer<std::uint8_t> joint_segment;
  Buffer<Mat3x4> segment_hooks;
  Buffer<glm::vec3> bind_positions;

  RigTablesView view() const {
    return {rigs.span(),          parents.span(),        offsets.span(),           joint_cluster.span(),
            inverse_bind.span(),  hook_rotations.span(), hook_translations.span(), hook_joints.span(),
            joint_segment.span(), segment_hooks.span(),  bind_positions.span()};
  }
};

void StreamCrowdConfig::validate() const {
  if (!(frame_rate >= 1.0f && frame_rate <= 1000.0f))
    throw Error("must be in [1, 1000] frames per second", at_field("frame_rate"));
}

StreamCrowd::StreamCrowd(StreamCrowdConfig config, Memory memory) : config_(config), memory_(memory) {
  config_.validate();
  streams_ = std::make_unique<StreamPool>(config_.frame_rate, memory_);
  uniques_ = std::make_unique<UniquePool>(config_.frame_rate, memory_);
  tables_ = std::make_unique<RigTables>();
  event_filter_.fill(~EventMask{0});
}

StreamCrowd::~StreamCrowd() = default;

std::int32_t StreamCrowd::add_rig(Rig rig) {
  if (agent_count_ > 0) throw Error("rigs must be added before agents", at_field("rigs." + rig.name));
  if (rig.name.empty()) throw Error("a rig needs a name", at_field("rigs"));
  if (find_rig(rig.name) >= 0) throw Error("rig name used twice", at_field("rigs." + rig.name));
  if (rig.joint_count() <= 0 || rig.joint_count() > kMaxRigJoints || rig.clusters.count() <= 0 ||
      rig.inverse_bind.size() != static_cast<std::size_t>(rig.joint_count()))
    throw Error("not a complete rig (use make_rig)", at_field("rigs." + rig.name));
  rigs_.push_back(std::move(rig));
  cluster_stride_ = std::max(cluster_stride_, rigs_.back().clusters.count());
  rebuild_rig_tables();
  return rig_count() - 1;
}

std::int32_t StreamCrowd::find_rig(const std::string& name) const {
  for (std::size_t i = 0; i < rigs_.size(); ++i)
    if (rigs_[i].name == name) return static_cast<std::int32_t>(i);
  return -1;
}

void StreamCrowd::rebuild_rig_tables() {
  std::vector<RigView> views;
  std::vector<std::int32_t> parents, hook_joints;
  std::vector<glm::vec3> offsets, hook_t;
  std::vector<std::uint8_t> joint_cluster;
  std::vector<Mat3x4> inverse_bind;
  std::vector<glm::quat> hook_q;
  std::vector<std::uint8_t> joint_segment;
  std::vector<Mat3x4> segment_hooks;
  std::vector<glm::vec3> bind_positions;
  for (const Rig& r : rigs_) {
    RigView v;
    v.joint_base = static_cast<Index>(parents.size());
    v.joint_count = r.joint_count();
    v.cluster_base = static_cast<std::int32_t>(hook_q.size());
    v.cluster_count = r.clusters.count();
    v.segment_base = static_cast<std::int32_t>(segment_hooks.size());
    v.segment_count = static_cast<std::int32_t>(r.clusters.segment_roots.size());
    v.rest_root = r.rest_pose().root;
    views.push_back(v);
    parents.insert(parents.end(), r.skeleton.parents.begin(), r.skeleton.parents.end());
    offsets.insert(offsets.end(), r.skeleton.offsets.begin(), r.skeleton.offsets.end());
    joint_cluster.insert(joint_cluster.end(), r.clusters.cluster_of_joint.begin(), r.clusters.cluster_of_joint.end());
    inverse_bind.insert(inverse_bind.end(), r.inverse_bind.begin(), r.inverse_bind.end());
    joint_segment.insert(joint_segment.end(), r.clusters.segment_of_joint.begin(), r.clusters.segment_of_joint.end());
    bind_positions.insert(bind_positions.end(), r.bind_positions.begin(), r.bind_positions.end());
    for (const std::int32_t root : r.clusters.segment_roots) {
      // B_p * hook * B_p^-1 with p the root's parent: the hook moved into model space.
      const std::int32_t p = r.skeleton.parents[static_cast<std::size_t>(root)];
      const ClusterDef& d = r.clusters.clusters[r.clusters.cluster_of_joint[static_cast<std::size_t>(root)]];
      const bool identity = d.hook_rotation == glm::quat(1, 0, 0, 0) && d.hook_translation == glm::vec3(0.0f);
      if (p < 0 || identity) {
        segment_hooks.emplace_back();
      } else {
        const auto pu = static_cast<std::size_t>(p);
        segment_hooks.push_back(inverse_rigid(r.inverse_bind[pu]) * mat3x4_from(d.hook_rotation, d.hook_translation) *
                                r.inverse_bind[pu]);
      }
    }
    for (std::int32_t c = 0; c < r.clusters.count(); ++c) {
      hook_q.push_back(r.clusters.clusters[static_cast<std::size_t>(c)].hook_rotation);
      hook_t.push_back(r.clusters.clusters[static_cast<std::size_t>(c)].hook_translation);
      hook_joints.push_back(r.clusters.hook_joint[static_cast<std::size_t>(c)]);
    }
  }
  tables_->rigs = to_buffer(views, memory_);
  tables_->parents = to_buffer(parents, memory_);
  tables_->offsets = to_buffer(offsets, memory_);
  tables_->joint_cluster = to_buffer(joint_cluster, memory_);
  tables_->inverse_bind = to_buffer(inverse_bind, memory_);
  tables_->hook_rotations = to_buffer(hook_q, memory_);
  tables_->hook_translations = to_buffer(hook_t, memory_);
  tables_->hook_joints = to_buffer(hook_joints, memory_);
  tables_->joint_segment = to_buffer(joint_segment, memory_);
  tables_->segment_hooks = to_buffer(segment_hooks, memory_);
  tables_->bind_positions = to_buffer(bind_positions, memory_);
}

// ---- agents -----------------------------------------------------------------------------

Index StreamCrowd::add_agents(std::int32_t rig, Index count) {
  if (rig < 0 || rig >= rig_count()) throw Error("no rig " + std::to_string(rig), at_field("agents.rig"));
  if (count < 0 || count > (Index{1} << 31)) throw Error("must be in [0, 2^31]", at_field("agents.count"));
  const Index first = agent_count_;
  if (count == 0) return first;
  std::vector<Index> offsets = palette_offsets_.to_vector();
  const std::int32_t J = rigs_[static_cast<std::size_t>(rig)].joint_count();
  for (Index i = 0; i < count; ++i) {
    offsets.push_back(palette_size_);
    palette_size_ += J;
  }
  host_agent_rig_.insert(host_agent_rig_.end(), static_cast<std::size_t>(count), rig);
  palette_offsets_ = to_buffer(offsets, memory_);
  agent_rig_ = appended(agent_rig_, count, rig, memory_);
  clusters_ = appended(clusters_, count * cluster_stride_, ClusterRef{}, memory_);
  agent_events_ = appended(agent_events_, count, EventMask{0}, memory_);
  agent_count_ += count;
  if (!overrides_.empty()) overrides_dirty_ = true;
  return first;
}

std::int32_t StreamCrowd::agent_rig(Index agent) const {
  if (agent < 0 || agent >= agent_count_) throw Error("no agent " + std::to_string(agent), at_field("agent"));
  return host_agent_rig_[static_cast<std::size_t>(agent)];
}

void StreamCrowd::check_agent_cluster(Index agent, std::int32_t cluster) const {
  const std::int32_t r = agent_rig(agent);
  const std::int32_t n = rigs_[static_cast<std::size_t>(r)].clusters.count();
  if (cluster < 0 || cluster >= n)
    throw Error("rig '" + rigs_[static_cast<std::size_t>(r)].name + "' has " + std::to_string(n) + " clusters, not " +
                    std::to_string(cluster + 1),
                at_field("cluster"));
}

std::int32_t StreamCrowd::random_offset(Index agent, std::int32_t cluster, std::int32_t stream,
                                        std::uint64_t salt) const {
  Rng rng(config_.seed ^ (salt * 0x9e3779b97f4a7c15ull),
          static_cast<std::uint64_t>(agent) * kMaxClusters + static_cast<std::uint64_t>(cluster));
  return static_cast<std::int32_t>(rng.below(static_cast<std::uint64_t>((*streams_)[stream].history())));
}

void StreamCrowd::apply(std::vector<ClusterCommand> commands) {
  if (commands.empty()) return;
  // One thread per agent, its commands in cluster order: the result does not
  // depend on the order of the calls or on the thread count.
  std::stable_sort(commands.begin(), commands.end(), [](const ClusterCommand& a, const ClusterCommand& b) {
    return a.agent < b.agent || (a.agent == b.agent && a.cluster < b.cluster);
  });
  std::vector<Index> groups;
  for (std::size_t k = 0; k < commands.size(); ++k)
    if (k == 0 || commands[k].agent != commands[k - 1].agent) groups.push_back(static_cast<Index>(k));
  groups.push_back(static_cast<Index>(commands.size()));
  const Buffer<ClusterCommand> cmd = to_buffer(commands, memory_);
  const Buffer<Index> grp = to_buffer(groups, memory_);
  StreamCommandJob job;
  job.commands = cmd.span();
  job.groups = grp.span();
  job.clusters = clusters_.span();
  job.cluster_stride = cluster_stride_;
  job.frame = frame_;
  job.run();
}

void StreamCrowd::assign(Index first, Index count, std::int32_t cluster, std::int32_t stream, std::int32_t offset) {
  if (first < 0 || count < 0 || first + count > agent_count_)
    throw Error("agent range out of bounds", at_field("assign"));
  if (stream < 0 || stream >= streams_->size())
    throw Error("no stream " + std::to_string(stream), at_field("assign.stream"));
  const AnimStream& s = (*streams_)[stream];
  if (offset < 0 || offset >= s.history())
    throw Error("must be in [0, " + std::to_string(s.history()) + ")", at_field("assign.offset"));
  std::vector<ClusterCommand> cmds;
  cmds.reserve(static_cast<std::size_t>(count));
  for (Index a = first; a < first + count; ++a) {
    check_agent_cluster(a, cluster);
    if (host_agent_rig_[static_cast<std::size_t>(a)] != s.rig())
      throw Error("stream '" + s.name() + "' is of another rig than agent " + std::to_string(a),
                  at_field("assign.stream"));
    cmds.push_back({a, cluster, stream, offset});
  }
  apply(std::move(cmds));
}

void StreamCrowd::assign_random(Index first, Index count, const VarietySpec& spec, std::uint64_t seed) {
  if (first < 0 || count < 0 || first + count > agent_count_)
    throw Error("agent range out of bounds", at_field("variety"));
  for (std::size_t c = 0; c < spec.streams.size(); ++c)
    for (std::size_t k = 0; k < spec.streams[c].size(); ++k) {
      const std::int32_t s = spec.streams[c][k];
      if (s < 0 || s >= streams_->size())
        throw Error("no stream " + std::to_string(s),
                    at_field("variety.streams[" + std::to_string(c) + "][" + std::to_string(k) + "]"));
    }
  std::vector<ClusterCommand> cmds;
  cmds.reserve(static_cast<std::size_t>(count * cluster_stride_));
  for (Index a = first; a < first + count; ++a) {
    const std::int32_t rig = host_agent_rig_[static_cast<std::size_t>(a)];
    const std::int32_t clusters = rigs_[static_cast<std::size_t>(rig)].clusters.count();
    Rng rng(seed, static_cast<std::uint64_t>(a));
    std::int32_t picked[kMaxClusters], offsets[kMaxClusters];
    for (std::int32_t c = 0; c < clusters && c < static_cast<std::int32_t>(spec.streams.size()); ++c) {
      const auto& candidates = spec.streams[static_cast<std::size_t>(c)];
      picked[c] = -1;
      if (candidates.empty()) continue;
      const std::int32_t s = candidates[static_cast<std::size_t>(rng.below(candidates.size()))];
      const AnimStream& stream = (*streams_)[s];
      if (stream.rig() != rig)
        throw Error("stream '" + stream.name() + "' is of another rig than agent " + std::to_string(a),
                    at_field("variety.streams[" + std::to_string(c) + "]"));
      std::int32_t offset = static_cast<std::int32_t>(rng.below(static_cast<std::uint64_t>(stream.history())));
      if (spec.same_offset_per_stream)
        for (std::int32_t d = 0; d < c; ++d)
          if (picked[d] == s) offset = offsets[d];
      picked[c] = s;
      offsets[c] = offset;
      cmds.push_back({a, c, s, offset});
    }
  }
  apply(std::move(cmds));
}

void StreamCrowd::set_culled(Index agent, std::int32_t cluster, bool culled) {
  check_agent_cluster(agent, cluster);
  const Index i = agent * cluster_stride_ + cluster;
  ClusterRef ref;
  clusters_.read(i, std::span<ClusterRef>(&ref, 1));
  ref.flags = culled ? (ref.flags | kClusterCulled) : (ref.flags & ~kClusterCulled);
  clusters_.write(i, std::span<const ClusterRef>(&ref, 1));
}

void StreamCrowd::set_event_filter(std::int32_t cluster, EventMask allowed) {
  if (cluster < 0 || cluster >= kMaxClusters) throw Error("must be in [0, 8)", at_field("event_filter.cluster"));
  event_filter_[static_cast<std::size_t>(cluster)] = allowed;
}

std::vector<ClusterRef> StreamCrowd::clusters_of(Index agent) const {
  agent_rig(agent);
  std::vector<ClusterRef> out(static_cast<std::size_t>(cluster_stride_));
  clusters_.read(agent * cluster_stride_, std::span<ClusterRef>(out));
  return out;
}

// ---- transitions ------------------------------------------------------------------------------

void StreamCrowd::queue(const ClusterCommand& c) {
  const Index key = c.agent * cluster_stride_ + c.cluster;
  auto it = pending_index_.find(key);
  if (it != pending_index_.end()) {
    pending_[it->second] = c;  // the later request wins
  } else {
    pending_index_[key] = pending_.size();
    pending_.push_back(c);
  }
}

void StreamCrowd::drop_unique_ref(Index key, std::int32_t release_frame) {
  auto it = unique_targets_.find(key);
  if (it == unique_targets_.end()) return;
  delayed_releases_.emplace_back(release_frame, it->second.instance);
  unique_targets_.erase(it);
}

void StreamCrowd::release_unique(std::int32_t instance) {
  std::int32_t& refs = unique_refcount_[static_cast<std::size_t>(instance)];
  if (--refs > 0) return;
  refs = 0;
  for (auto it = unique_by_agent_.begin(); it != unique_by_agent_.end(); ++it)
    if (it->second == instance) {
      unique_by_agent_.erase(it);
      break;
    }
  uniques_->release(instance);
}

void StreamCrowd::transition_to_streamed(Index agent, std::int32_t cluster, std::int32_t stream, float blend_seconds,
                                         std::int32_t offset) {
  check_agent_cluster(agent, cluster);
  if (stream < 0 || stream >= streams_->size())
    throw Error("no stream " + std::to_string(stream), at_field("transition.stream"));
  const AnimStream& s = (*streams_)[stream];
  if (s.rig() != agent_rig(agent))
    throw Error("stream '" + s.name() + "' is of another rig than the agent", at_field("transition.stream"));
  if (!(blend_seconds >= 0.0f && blend_seconds < 1e4f))
    throw Error("must be in [0, 1e4) seconds", at_field("transition.blend"));
  if (offset >= s.history())
    throw Error("must be below the stream's history " + std::to_string(s.history()), at_field("transition.offset"));
  const float blend_frames = blend_seconds * config_.frame_rate;
  const Index key = agent * cluster_stride_ + cluster;
  const std::int32_t t0 = frame_ + 1;
  drop_unique_ref(key, t0 + static_cast<std::int32_t>(std::ceil(blend_frames)));
  ClusterCommand c;
  c.agent = agent;
  c.cluster = cluster;
  c.source = stream;
  c.offset = offset;
  c.fallback_offset = random_offset(agent, cluster, stream, ++command_serial_);
  c.blend_frames = blend_frames;
  c.transition = 1;
  queue(c);
}

void StreamCrowd::transition_to_unique(Index agent, std::int32_t cluster, std::int32_t animation, float blend_seconds,
                                       std::int32_t then_stream, float then_blend) {
  check_agent_cluster(agent, cluster);
  if (animation < 0 || animation >= uniques_->animation_count())
    throw Error("no unique animation " + std::to_string(animation), at_field("transition.animation"));
  if (uniques_->animation(animation).rig != agent_rig(agent))
    throw Error("unique animation '" + uniques_->animation(animation).name + "' is of another rig than the agent",
                at_field("transition.animation"));
  if (!(blend_seconds >= 0.0f && blend_seconds < 1e4f))
    throw Error("must be in [0, 1e4) seconds", at_field("transition.blend"));
  if (then_stream >= streams_->size() || (then_stream >= 0 && (*streams_)[then_stream].rig() != agent_rig(agent)))
    throw Error("no stream of the agent's rig with this index", at_field("transition.then_stream"));
  if (!(then_blend >= 0.0f && then_blend < 1e4f))
    throw Error("must be in [0, 1e4) seconds", at_field("transition.then_blend"));
  const float blend_frames = blend_seconds * config_.frame_rate;
  const Index key = agent * cluster_stride_ + cluster;
  const std::int32_t t0 = frame_ + 1;

  std::int32_t instance = -1;
  auto found = unique_by_agent_.find({agent, animation});
  if (found != unique_by_agent_.end()) {
    instance = found->second;
  } else {
    instance = uniques_->acquire(animation);
    unique_by_agent_[{agent, animation}] = instance;
    if (unique_refcount_.size() < static_cast<std::size_t>(uniques_->instance_count()))
      unique_refcount_.resize(static_cast<std::size_t>(uniques_->instance_count()), 0);
  }
  ++unique_refcount_[static_cast<std::size_t>(instance)];
  drop_unique_ref(key, t0 + static_cast<std::int32_t>(std::ceil(blend_frames)));
  unique_targets_[key] = {instance, animation, then_stream, then_blend};

  ClusterCommand c;
  c.agent = agent;
  c.cluster = cluster;
  c.source = unique_source(instance);
  c.offset = 0;
  c.blend_frames = blend_frames;
  c.transition = 1;
  queue(c);
}

// ---- overrides ----------------------------------------------------------------------------------

void StreamCrowd::set_override(Index agent, const BoneOverride& o) {
  const std::int32_t r = agent_rig(agent);
  const std::int32_t J = rigs_[static_cast<std::size_t>(r)].joint_count();
  if (o.joint < 0 || o.joint >= J) throw Error("must be a joint of the agent's rig", at_field("override.joint"));
  if (!(o.weight >= 0.0f && o.weight <= 1.0f)) throw Error("must be in [0, 1]", at_field("override.weight"));
  if (!(o.max_angle >= 0.0f && o.max_angle <= 3.1416f))
    throw Error("must be in [0, pi]", at_field("override.max_angle"));
  const glm::quat& q = o.rotation;
  if (!(std::abs(glm::length(q) - 1.0f) < 1e-3f))
    throw Error("must be a unit quaternion", at_field("override.rotation"));
  if (!std::isfinite(o.target.x) || !std::isfinite(o.target.y) || !std::isfinite(o.target.z))
    throw Error("must be finite", at_field("override.target"));
  if (!(glm::length(o.aim_axis) > 1e-6f) || !std::isfinite(glm::length(o.aim_axis)))
    throw Error("must be a non-zero finite vector", at_field("override.aim_axis"));
  auto& list = overrides_[agent];
  auto it = std::find_if(list.begin(), list.end(), [&](const BoneOverride& x) { return x.joint == o.joint; });
  if (it != list.end()) {
    *it = o;
  } else {
    list.push_back(o);
    std::sort(list.begin(), list.end(), [](const BoneOverride& a, const BoneOverride& b) { return a.joint < b.joint; });
  }
  overrides_dirty_ = true;
}

void StreamCrowd::clear_override(Index agent, std::int32_t joint) {
  auto it = overrides_.find(agent);
  if (it == overrides_.end()) return;
  auto& list = it->second;
  list.erase(std::remove_if(list.begin(), list.end(), [&](const BoneOverride& x) { return x.joint == joint; }),
             list.end());
  if (list.empty()) overrides_.erase(it);
  overrides_dirty_ = true;
}

void StreamCrowd::clear_overrides(Index agent) {
  if (overrides_.erase(agent) > 0) overrides_dirty_ = true;
}

void StreamCrowd::rebuild_overrides() const {
  if (!overrides_dirty_) return;
  overrides_dirty_ = false;
  if (overrides_.empty()) {
    override_begin_ = Buffer<std::int32_t>();
    override_list_ = Buffer<BoneOverride>();
    return;
  }
  std::vector<std::int32_t> begin(static_cast<std::size_t>(agent_count_ + 1), 0);
  std::vector<BoneOverride> list;
  auto it = overrides_.begin();
  for (Index a = 0; a < agent_count_; ++a) {
    begin[static_cast<std::size_t>(a)] = static_cast<std::int32_t>(list.size());
    if (it != overrides_.end() && it->first == a) {
      list.insert(list.end(), it->second.begin(), it->second.end());
      ++it;
    }
  }
  begin[static_cast<std::size_t>(agent_count_)] = static_cast<std::int32_t>(list.size());
  override_begin_ = to_buffer(begin, memory_);
  override_list_ = to_buffer(list, memory_);
}

// ---- per frame ----------------------------------------------------------------------------------

void StreamCrowd::step() {
  ++frame_;
  // Unique instances whose last reader finished blending them out.
  std::vector<std::pair<std::int32_t, std::int32_t>> still;
  for (const auto& [f, instance] : delayed_releases_) {
    if (f <= frame_)
      release_unique(instance);
    else
      still.emplace_back(f, instance);
  }
  delayed_releases_ = std::move(still);

  std::vector<ClusterCommand> commands = std::move(pending_);
  pending_.clear();
  pending_index_.clear();
  apply(std::move(commands));

  streams_->step(frame_);
  uniques_->step(frame_);

  const StreamEventsJob events{.streams = streams_->views(),
                               .uniques = uniques_->views(),
                               .rigs = tables_->rigs.span(),
                               .agent_rigs = agent_rig_.span(),
                               .clusters = clusters_.span(),
                               .cluster_stride = cluster_stride_,
                               .cluster_event_filter = event_filter_,
                               .out_events = agent_events_.span()};
  if (config_.events) events.run();

  // Unique animations that should hand back to a stream, arriving as they end.
  std::vector<std::pair<Index, UniqueRef>> returning;
  for (auto& [key, ref] : unique_targets_) {
    if (ref.then_stream < 0) continue;
    const Controller* c = uniques_->controller(ref.instance);
    if (c == nullptr) continue;
    const double left = c->duration() > 0.0 ? c->duration() - c->time() : 0.0;
    if (c->finished() || (c->duration() > 0.0 && left <= ref.then_blend + 0.5 / config_.frame_rate))
      returning.emplace_back(key, ref);
  }
  std::sort(returning.begin(), returning.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [key, ref] : returning)
    transition_to_streamed(key / cluster_stride_, static_cast<std::int32_t>(key % cluster_stride_), ref.then_stream,
                           ref.then_blend);
}

Index StreamCrowd::retarget(Span<const std::int32_t> sources, Span<const std::int32_t> offsets, float blend_seconds,
                            std::uint32_t cluster_mask) {
  if (!(blend_seconds >= 0.0f && blend_seconds < 1e4f))
    throw Error("must be in [0, 1e4) seconds", at_field("retarget.blend"));
  if (retarget_changed_.size() != agent_count_) retarget_changed_ = Buffer<std::uint8_t>(agent_count_, memory_);
  const StreamRetargetJob job{.sources = sources,
                              .offsets = offsets,
                              .streams = streams_->views(),
                              .rigs = tables_->rigs.span(),
                              .agent_rigs = agent_rig_.span(),
                              .clusters = clusters_.span(),
                              .cluster_stride = cluster_stride_,
                              .cluster_mask = cluster_mask,
                              .frame = frame_,
                              .blend_frames = blend_seconds * config_.frame_rate,
                              .changed = retarget_changed_.span()};
  job.run();
  return count_nonzero(retarget_changed_.span());
}

void StreamCrowd::resolve(Span<const glm::vec3> positions, Span<const float> yaws, Span<Mat3x4> palettes,
                          Span<std::int32_t> read_offsets, Span<const std::uint8_t> skip) const {
  if (palettes.size() != palette_size_)
    throw Error(
        "has " + std::to_string(palettes.size()) + " matrices, the crowd needs " + std::to_string(palette_size_),
        at_field("resolve.palettes"));
  rebuild_overrides();
  StreamResolveJob job;
  job.tables = tables_->view();
  job.streams = streams_->views();
  job.uniques = uniques_->views();
  job.agent_rigs = agent_rig_.span();
  job.palette_offsets = palette_offsets_.span();
  job.clusters = clusters_.span();
  job.cluster_stride = cluster_stride_;
  job.override_begin = override_begin_.span();
  job.overrides = override_list_.span();
  job.positions = positions;
  job.yaws = yaws;
  job.frame = frame_;
  job.palettes = palettes;
  job.read_offsets = read_offsets;
  job.skip = skip;
  job.run();
}

StreamMemory StreamCrowd::memory() const {
  StreamMemory m;
  m.stream_poses = streams_->pose_bytes();
  m.unique_poses = uniques_->pose_bytes();
  m.agent_state = bytes_of(agent_rig_) + bytes_of(palette_offsets_) + bytes_of(clusters_) + bytes_of(agent_events_) +
                  bytes_of(override_begin_) + bytes_of(override_list_);
  m.palettes = static_cast<std::size_t>(palette_size_) * sizeof(Mat3x4);
  return m;
}

}  // namespace throng::anim
