#include "path/state_machine.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <map>
#include <numbers>

#include "core/ground.h"
#include "motion/cycle.h"
#include "motion/fk.h"
#include "motion/phase.h"
#include "sim/geometry.h"

namespace throng::path {

namespace {

// Sampled frame position of clip time t (seconds, t0 = time of frame 0).
struct FramePos {
  std::int32_t f0, f1;
  float w;
};
FramePos frame_pos(const motion::Clip& clip, double t0, double fps, double t) {
  const double x = std::clamp((t - t0) * fps, 0.0, static_cast<double>(clip.frame_count - 1));
  const auto f0 = static_cast<std::int32_t>(std::floor(x));
  const std::int32_t f1 = std::min(f0 + 1, clip.frame_count - 1);
  return {f0, f1, static_cast<float>(x - f0)};
}

}  // namespace

glm::vec2 MachineClip::raw_root(double t) const {
  const FramePos p = frame_pos(clip, time_of_first_frame, fps, t);
  const glm::vec3 r = glm::mix(clip.root_positions[static_cast<std::size_t>(p.f0)],
                               clip.root_positions[static_cast<std::size_t>(p.f1)], p.w);
  return ground_from_world(r);
}

glm::vec2 MachineClip::smoothed_root(double t) const {
  // A box filter over exactly one period (P samples one frame apart) removes
  // every periodic part of the root motion: bob, sway, surge.
  const std::int32_t P = std::max(1, period_frames);
  glm::dvec2 acc(0.0);
  for (std::int32_t i = 0; i < P; ++i) acc += glm::dvec2(raw_root(t + (i - 0.5 * (P - 1)) / fps));
  return glm::vec2(acc / static_cast<double>(P));
}

std::int32_t MotionGraph::state_index(const std::string& name) const {
  for (std::size_t i = 0; i < states_.size(); ++i)
    if (states_[i].name == name) return static_cast<std::int32_t>(i);
  return -1;
}

void MotionGraph::pose(std::int32_t seg, double t, std::vector<glm::quat>& rotations, glm::vec3& root) const {
  const MotionSegment& s = segments_[static_cast<std::size_t>(seg)];
  const MachineClip& c = clips_[static_cast<std::size_t>(s.clip)];
  const FramePos p = frame_pos(c.clip, c.time_of_first_frame, c.fps, s.start_time + t);
  const std::int32_t J = c.clip.joint_count;
  rotations.resize(static_cast<std::size_t>(J));
  const motion::SlerpAt between(p.w);
  for (std::int32_t j = 0; j < J; ++j)
    rotations[static_cast<std::size_t>(j)] = between(c.clip.rotation(p.f0, j), c.clip.rotation(p.f1, j));
  root = glm::mix(c.clip.root_positions[static_cast<std::size_t>(p.f0)],
                  c.clip.root_positions[static_cast<std::size_t>(p.f1)], p.w);
}

namespace {

[[noreturn]] void fail(const std::string& what, const Location& where) { throw Error(what, where); }

// Name -> index of the spec's groups, states and clips.
struct Names {
  std::map<std::string, std::int32_t> group_of, state_of, clip_of;
};

// Checks the spec's scalar fields and its sizes (segment and clip counts);
// throws Error naming the field.
void check_limits(const StateMachineSpec& spec) {
  if (!(spec.fps >= 1 && spec.fps <= 1000)) fail("fps must be in [1, 1000]", at_field("fps"));
  if (!(spec.spacing >= 1e-3f && spec.spacing <= 1.0f)) fail("spacing must be in [0.001, 1] m", at_field("spacing"));
  if (spec.points_per_segment < 2 || spec.points_per_segment > 4096)
    fail("points_per_segment must be in [2, 4096]", at_field("points_per_segment"));
  if (spec.transition_frames < 0 || spec.transition_frames > 240)
    fail("transition_frames must be in [0, 240]", at_field("transition_frames"));
  if (!(spec.pose_weight >= 0 && std::isfinite(spec.pose_weight)))
    fail("pose_weight must be >= 0", at_field("pose_weight"));
  if (spec.states.empty()) fail("a machine needs at least one state", at_field("states"));
  std::size_t segment_total = 0;
  for (const StateSpec& s : spec.states) segment_total += s.segments.size();
  // The transition table has segments^2 entries.
  if (segment_total > 4096) fail("a machine may have at most 4096 segments", at_field("states"));
  if (spec.clips.size() > 1024) fail("a machine may have at most 1024 clips", at_field("clips"));
}

// Groups in spec order with their parents resolved (acyclic); fills
// names.group_of.
std::vector<MachineGroup> name_groups(const StateMachineSpec& spec, Names& names) {
  std::vector<MachineGroup> groups;
  for (const StateGroupSpec& g : spec.groups) {
    if (g.name.empty()) fail("a group needs a name", g.where);
    if (names.group_of.count(g.name)) fail("group '" + g.name + "' is defined twice", g.where);
    names.group_of[g.name] = static_cast<std::int32_t>(groups.size());
    groups.push_back({g.name, -1});
  }
  for (std::size_t i = 0; i < spec.groups.size(); ++i) {
    const StateGroupSpec& g = spec.groups[i];
    if (g.parent.empty()) continue;
    auto it = names.group_of.find(g.parent);
    if (it == names.group_of.end()) fail("unknown parent group '" + g.parent + "'", g.where);
    groups[i].parent = it->second;
    // No cycles: walk up at most group-count steps.
    std::int32_t up = it->second;
    for (std::size_t steps = 0; up >= 0; ++steps, up = groups[static_cast<std::size_t>(up)].parent)
      if (steps > spec.groups.size() || up == static_cast<std::int32_t>(i))
        fail("group '" + g.name + "' is its own ancestor", g.where);
  }
  return groups;
}

// Fills names.clip_of: each clip's index in spec.clips.
void name_clips(const StateMachineSpec& spec, Names& names) {
  for (std::size_t i = 0; i < spec.clips.size(); ++i) {
    const ClipSpec& c = spec.clips[i];
    if (c.name.empty()) fail("a clip needs a name", c.where);
    if (names.clip_of.count(c.name)) fail("clip '" + c.name + "' is defined twice", c.where);
    names.clip_of[c.name] = static_cast<std::int32_t>(i);
  }
}

// States in spec order (no segments yet), checking their segments; fills
// names.state_of. Returns how far into each clip the segments reach
// (seconds; d = segment arc length, m), to size the clip's samples.
std::vector<double> name_states(const StateMachineSpec& spec, double d, Names& names,
                                std::vector<MachineState>& states) {
  const double fps = spec.fps;
  std::vector<double> clip_end(spec.clips.size(), 0.0);
  for (const StateSpec& s : spec.states) {
    if (s.name.empty()) fail("a state needs a name", s.where);
    if (names.state_of.count(s.name) || names.group_of.count(s.name))
      fail("state '" + s.name + "' is defined twice (or is also a group)", s.where);
    names.state_of[s.name] = static_cast<std::int32_t>(states.size());
    MachineState st;
    st.name = s.name;
    st.locomotion = s.locomotion;
    if (!s.group.empty()) {
      auto it = names.group_of.find(s.group);
      if (it == names.group_of.end()) fail("unknown group '" + s.group + "'", s.where);
      st.group = it->second;
    }
    if (s.segments.empty()) fail("state '" + s.name + "' has no segments", s.where);
    for (const SegmentSpec& seg : s.segments) {
      auto it = names.clip_of.find(seg.clip);
      if (it == names.clip_of.end()) fail("unknown clip '" + seg.clip + "'", seg.where);
      if (!(seg.start_frame >= 0 && seg.start_frame <= 36000)) fail("start frame must be in [0, 36000]", seg.where);
      if (!(seg.frames >= 0 && seg.frames <= 36000)) fail("frames must be in [0, 36000]", seg.where);
      const motion::LocomotionSpec& ls = spec.clips[static_cast<std::size_t>(it->second)].spec;
      if (s.locomotion && !(ls.speed > 0))
        fail("a locomotion segment needs a moving clip ('" + seg.clip + "' stands)", seg.where);
      // Generous: the smoothed root may be a little slower than the clip's speed.
      const double need =
          seg.start_frame / fps + (s.locomotion ? 1.5 * d / ls.speed : seg.frames / fps + 4.0 * ls.idle_period_s);
      auto& end = clip_end[static_cast<std::size_t>(it->second)];
      end = std::max(end, need);
    }
    states.push_back(st);
  }
  return clip_end;
}

// Clip `c` generated at the spec's fps and sampled from before 0
// (transitions, smoothing) to past `clip_end` (s), the segments' reach.
MachineClip sample_clip(const ClipSpec& c, const StateMachineSpec& spec, const motion::Skeleton& skeleton,
                        double clip_end) {
  const double fps = spec.fps;
  motion::LocomotionSpec ls = c.spec;
  ls.fps = fps;
  try {
    ls.validate();
  } catch (const Error& e) {
    fail(e.message(), c.where);
  }
  MachineClip mc;
  mc.name = c.name;
  mc.fps = fps;
  mc.generator = std::make_shared<motion::LocomotionGenerator>(skeleton, ls);
  mc.period_frames = mc.generator->targets().period_frames;
  const double pad = (mc.period_frames + 2.0 * spec.transition_frames + 4.0) / fps;
  mc.time_of_first_frame = -pad;
  const auto frames = static_cast<std::int32_t>(std::ceil((clip_end + 2.0 * pad) * fps)) + 1;
  if (frames > 100'000)
    fail("clip would need more than 100,000 frames (lower the start frames or raise the speed)", c.where);
  mc.clip.resize(frames, skeleton.joint_count());
  mc.clip.frame_time = static_cast<float>(1.0 / fps);
  std::vector<glm::quat> rot(static_cast<std::size_t>(skeleton.joint_count()));
  for (std::int32_t f = 0; f < frames; ++f) {
    glm::vec3 root;
    mc.generator->pose_at(mc.time_of_first_frame + f / fps, rot, root);
    for (std::int32_t j = 0; j < skeleton.joint_count(); ++j) mc.clip.rotation(f, j) = rot[static_cast<std::size_t>(j)];
    mc.clip.root_positions[static_cast<std::size_t>(f)] = root;
  }
  return mc;
}

// A standing segment (ms.start_time set, s): its duration (s) from `frames`
// or the clip's period, and its frame where the root stands, facing its way.
void stand(MotionSegment& ms, const MachineClip& mc, const SegmentSpec& seg, double fps) {
  ms.duration = (seg.frames > 0 ? seg.frames : static_cast<double>(mc.period_frames)) / fps;
  const FramePos fp = frame_pos(mc.clip, mc.time_of_first_frame, fps, ms.start_time);
  ms.origin = mc.raw_root(ms.start_time);
  ms.heading = static_cast<float>(heading_from_yaw(static_cast<float>(motion::heading_of(mc.clip.rotation(fp.f0, 0)))));
  ms.end_point = rotate_ccw(mc.raw_root(ms.start_time + ms.duration) - ms.origin, -ms.heading);
}

// Clip times (s) at smoothed-root arc lengths j * spacing, j = 0..k, from
// `start` on: a march in quarter frames, linear inside a step. Fails past
// `limit` + 1 s (the clip's end); d = k * spacing, m, for the message.
std::vector<double> arc_times(const MachineClip& mc, const SegmentSpec& seg, const StateMachineSpec& spec, double start,
                              double limit, double d) {
  const double fps = spec.fps;
  const double dt = 0.25 / fps;
  double t = start, arc = 0;
  glm::vec2 prev = mc.smoothed_root(t);
  std::vector<double> times = {t};
  std::int32_t next = 1;
  while (next <= spec.points_per_segment) {
    const glm::vec2 p = mc.smoothed_root(t + dt);
    const double step = sim::length_of(p - prev);
    while (next <= spec.points_per_segment && arc + step >= next * static_cast<double>(spec.spacing)) {
      const double f = step > 0 ? (next * static_cast<double>(spec.spacing) - arc) / step : 0.0;
      times.push_back(t + f * dt);
      ++next;
    }
    arc += step;
    prev = p;
    t += dt;
    if (t > limit + 1.0) fail(fmt::format("segment of clip '{}' does not cover {:.3f} m", seg.clip, d), seg.where);
  }
  return times;
}

// Map heading (rad) of the smoothed root at clip time t (s): its motion over
// one frame centred on t.
float smoothed_heading(const MachineClip& mc, double fps, double t) {
  const glm::vec2 v = mc.smoothed_root(t + 0.5 / fps) - mc.smoothed_root(t - 0.5 / fps);
  return std::atan2(v.y, v.x);
}

// A locomotion segment (ms.start_time set, s) covering d metres of smoothed
// root: its k point times and trajectory in its own frame, duration (s),
// speed (m/s), end point and end heading (rad).
void walk(MotionSegment& ms, const MachineClip& mc, const SegmentSpec& seg, const StateMachineSpec& spec, double limit,
          double d) {
  const double fps = spec.fps;
  std::vector<double> times = arc_times(mc, seg, spec, ms.start_time, limit, d);
  const double t_end = times.back();
  times.pop_back();
  ms.times = times;
  ms.duration = t_end - ms.start_time;
  ms.speed = static_cast<float>(d / ms.duration);
  ms.origin = mc.smoothed_root(ms.start_time);
  ms.heading = static_cast<float>(smoothed_heading(mc, fps, ms.start_time));
  for (double tt : ms.times) ms.trajectory.push_back(rotate_ccw(mc.smoothed_root(tt) - ms.origin, -ms.heading));
  ms.end_point = rotate_ccw(mc.smoothed_root(t_end) - ms.origin, -ms.heading);
  ms.end_heading =
      static_cast<float>(std::remainder(smoothed_heading(mc, fps, t_end) - ms.heading, 2.0 * std::numbers::pi));
}

// Indices of the states `name` stands for: the state itself, or every state
// with the group among its ancestors (in state order).
std::vector<std::int32_t> states_under(const std::string& name, const Location& where, const Names& names,
                                       const std::vector<MachineState>& states,
                                       const std::vector<MachineGroup>& groups) {
  std::vector<std::int32_t> out;
  if (auto it = names.state_of.find(name); it != names.state_of.end()) return std::vector<std::int32_t>{it->second};
  auto it = names.group_of.find(name);
  if (it == names.group_of.end()) fail("unknown state or group '" + name + "'", where);
  for (std::size_t s = 0; s < states.size(); ++s)
    for (std::int32_t g = states[s].group; g >= 0; g = groups[static_cast<std::size_t>(g)].parent)
      if (g == it->second) {
        out.push_back(static_cast<std::int32_t>(s));
        break;
      }
  return out;
}

// Edges expanded to states (every state under `from` to every state under
// `to`): allowed and edge_cost, S x S row-major, cost the cheapest edge's.
void expand_edges(const StateMachineSpec& spec, const Names& names, const std::vector<MachineState>& states,
                  const std::vector<MachineGroup>& groups, std::vector<std::uint8_t>& allowed,
                  std::vector<float>& edge_cost) {
  const std::size_t S = states.size();
  allowed.assign(S * S, 0);
  edge_cost.assign(S * S, INFINITY);
  for (const EdgeSpec& e : spec.edges) {
    if (!(e.cost >= 0 && std::isfinite(e.cost))) fail("edge cost must be >= 0", e.where);
    for (std::int32_t a : states_under(e.from, e.where, names, states, groups))
      for (std::int32_t b : states_under(e.to, e.where, names, states, groups)) {
        const std::size_t i = static_cast<std::size_t>(a) * S + static_cast<std::size_t>(b);
        allowed[i] = 1;
        edge_cost[i] = std::min(edge_cost[i], e.cost);
      }
  }
}

// Joint positions (m) of segment `seg` at t seconds after its start,
// relative to the root and turned into its heading frame (heading = twist
// of the root rotation about +Y).
std::vector<glm::vec3> heading_frame_pose(const MotionGraph& m, const motion::Skeleton& skeleton, std::int32_t seg,
                                          double t) {
  const std::int32_t J = skeleton.joint_count();
  std::vector<glm::quat> rot;
  glm::vec3 root;
  m.pose(seg, t, rot, root);
  std::vector<glm::vec3> pos(static_cast<std::size_t>(J));
  std::vector<glm::quat> wrot(static_cast<std::size_t>(J));
  motion::fk_pose(J, skeleton.parents.data(), skeleton.offsets.data(), rot.data(), nullptr, root, pos.data(),
                  wrot.data());
  const glm::quat unyaw = glm::angleAxis(static_cast<float>(-motion::heading_of(rot[0])), glm::vec3(0, 1, 0));
  for (glm::vec3& p : pos) p = unyaw * (p - root);
  return pos;
}

// Transition costs, M x M row-major over m's segments: INFINITY where the
// states may not follow, else edge cost + pose_weight * k * mean joint
// mismatch (m) between a's last pose and b's first.
std::vector<float> transition_costs(const MotionGraph& m, const StateMachineSpec& spec,
                                    const motion::Skeleton& skeleton) {
  const std::int32_t J = skeleton.joint_count();
  const std::vector<MotionSegment>& segments = m.segments();
  const std::size_t M = segments.size();
  std::vector<std::vector<glm::vec3>> first(M), last(M);
  for (std::size_t i = 0; i < M; ++i) {
    first[i] = heading_frame_pose(m, skeleton, static_cast<std::int32_t>(i), 0.0);
    last[i] = heading_frame_pose(m, skeleton, static_cast<std::int32_t>(i), segments[i].duration);
  }
  std::vector<float> transition(M * M, INFINITY);
  for (std::size_t a = 0; a < M; ++a)
    for (std::size_t b = 0; b < M; ++b) {
      const std::int32_t sa = segments[a].state, sb = segments[b].state;
      if (!m.allowed(sa, sb)) continue;
      double mismatch = 0;
      for (std::int32_t j = 0; j < J; ++j)
        mismatch += glm::length(last[a][static_cast<std::size_t>(j)] - first[b][static_cast<std::size_t>(j)]);
      mismatch /= std::max(1, J);
      transition[a * M + b] =
          m.edge_cost(sa, sb) + static_cast<float>(spec.pose_weight * spec.points_per_segment * mismatch);
    }
  return transition;
}

}  // namespace

// Stages: limits, names (groups, clips, states), clips sampled, segments
// (standing or locomotion), edges, start and end states, transition costs.
MotionGraph MotionGraph::build(const StateMachineSpec& spec, const motion::Skeleton& skeleton) {
  check_limits(spec);
  MotionGraph m;
  m.spec_ = spec;
  m.skeleton_ = skeleton;
  const double fps = spec.fps;
  const double d = static_cast<double>(spec.spacing) * spec.points_per_segment;

  Names names;
  m.groups_ = name_groups(spec, names);
  name_clips(spec, names);
  const std::vector<double> clip_end = name_states(spec, d, names, m.states_);
  for (std::size_t i = 0; i < spec.clips.size(); ++i)
    m.clips_.push_back(sample_clip(spec.clips[i], spec, skeleton, clip_end[i]));

  for (std::size_t si = 0; si < spec.states.size(); ++si) {
    const StateSpec& s = spec.states[si];
    for (std::size_t k = 0; k < s.segments.size(); ++k) {
      const SegmentSpec& seg = s.segments[k];
      MotionSegment ms;
      ms.name = fmt::format("{}/{}", s.name, k);
      ms.state = static_cast<std::int32_t>(si);
      ms.clip = names.clip_of.at(seg.clip);
      const MachineClip& mc = m.clips_[static_cast<std::size_t>(ms.clip)];
      ms.start_time = seg.start_frame / fps;
      if (!s.locomotion) {
        stand(ms, mc, seg, fps);
      } else {
        walk(ms, mc, seg, spec, clip_end[static_cast<std::size_t>(ms.clip)], d);
        m.locomotion_.push_back(static_cast<std::int32_t>(m.segments_.size()));
      }
      m.states_[si].segments.push_back(static_cast<std::int32_t>(m.segments_.size()));
      m.segments_.push_back(std::move(ms));
    }
  }

  expand_edges(spec, names, m.states_, m.groups_, m.allowed_, m.edge_cost_);
  if (!spec.start_state.empty() && (m.start_state_ = m.state_index(spec.start_state)) < 0)
    fail("unknown start state '" + spec.start_state + "'", at_field("start_state"));
  if (!spec.end_state.empty() && (m.end_state_ = m.state_index(spec.end_state)) < 0)
    fail("unknown end state '" + spec.end_state + "'", at_field("end_state"));
  if (m.locomotion_.empty()) fail("a machine needs at least one locomotion state", at_field("states"));
  m.transition_ = transition_costs(m, spec, skeleton);
  return m;
}

}  // namespace throng::path
