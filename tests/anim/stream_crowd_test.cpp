// A crowd animated by streams, against independent references: palettes by
// double-precision matrix forward kinematics from the streams' histories,
// transitions by the sine SLERP, events shifted by each agent's offset.
#include "anim/stream_crowd.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "core/error.h"
#include "anim/skin.h"
#include "core/exec.h"
#include "stream_reference.h"

namespace throng::anim {
namespace {

using namespace testing;
namespace dj = motion::default_joint;
constexpr float kFps = 30.0f;
constexpr float kDt = 1.0f / kFps;

StreamSpec spec_of(const std::string& name, std::int32_t history, float time_to_dilate = -1.0f) {
  StreamSpec s;
  s.name = name;
  s.history = history;
  s.time_to_dilate = time_to_dilate > 0.0f ? time_to_dilate : static_cast<float>(history) / kFps;
  return s;
}

struct World {
  std::vector<glm::vec3> positions;
  std::vector<float> yaws;
  explicit World(Index n) {
    for (Index a = 0; a < n; ++a) {
      positions.emplace_back(0.7f * static_cast<float>(a % 13), 0.0f, -1.1f * static_cast<float>(a / 13));
      yaws.push_back(0.37f * static_cast<float>(a));
    }
  }
};

// The local rotations and root one agent should show, read from the
// streams' host copies: each joint from its cluster's (stream, offset), the
// cluster blended from its transition source by the sine SLERP.
struct AgentPose {
  std::vector<glm::dquat> local;
  glm::dvec3 root;
};

Pose source_pose(const StreamCrowd& crowd, const Rig& rig, std::int32_t source, std::int32_t offset) {
  if (is_unique_source(source)) {
    const SourceView v = crowd.uniques().views()[unique_instance(source)];
    Pose p(v.joints);
    std::copy(v.rotations, v.rotations + v.joints, p.local.begin());
    p.root = v.roots[0];
    return p;
  }
  if (source < 0) return rig.rest_pose();
  const AnimStream& s = crowd.streams()[source];
  return s.pose_at(std::min(offset, s.max_offset()));
}

AgentPose expected_pose(const StreamCrowd& crowd, Index agent) {
  const Rig& rig = crowd.rig(crowd.agent_rig(agent));
  const auto refs = crowd.clusters_of(agent);
  const auto J = static_cast<std::size_t>(rig.joint_count());
  AgentPose out;
  out.local.resize(J);
  for (std::size_t j = 0; j < J; ++j) {
    const auto c = rig.clusters.cluster_of_joint[j];
    const ClusterRef& ref = refs[c];
    const Pose to = source_pose(crowd, rig, ref.source, ref.offset);
    glm::dquat q(to.local[j]);
    glm::dvec3 root(to.root);
    const double alpha = ref.blend_frames > 0.0f
                             ? std::clamp((crowd.frame() - ref.t0) / static_cast<double>(ref.blend_frames), 0.0, 1.0)
                             : 1.0;
    if (alpha < 1.0) {
      const Pose from = source_pose(crowd, rig, ref.from_source, ref.from_offset);
      q = sine_slerp(glm::dquat(from.local[j]), q, alpha);
      root = glm::mix(glm::dvec3(from.root), root, alpha);
    }
    out.local[j] = q;
    if (j == 0) out.root = root;
  }
  return out;
}

double max_palette_error(const StreamCrowd& crowd, const std::vector<Mat3x4>& palettes, const World& w, Index agent) {
  const Rig& rig = crowd.rig(crowd.agent_rig(agent));
  const AgentPose p = expected_pose(crowd, agent);
  const auto ref = reference_palette(rig, p.local, p.root, glm::dvec3(w.positions[static_cast<std::size_t>(agent)]),
                                     w.yaws[static_cast<std::size_t>(agent)]);
  const Index base = crowd.palette_offsets()[agent];
  double e = 0.0;
  for (std::size_t j = 0; j < ref.size(); ++j)
    e = std::max(e, palette_error(palettes[static_cast<std::size_t>(base) + j], ref[j]));
  return e;
}

// Two rigs (22 and 28 joints), two streams each.
struct MixedCrowd {
  StreamCrowd crowd{StreamCrowdConfig{kFps, 7}};
  std::int32_t human = 0, fingered = 0;
  std::int32_t walk = 0, wave = 0, f_walk = 0, f_idle = 0;
  MixedCrowd() {
    human = crowd.add_rig(humanoid_rig());
    fingered = crowd.add_rig(make_rig("fingered", fingered_skeleton()));
    const int Jh = crowd.rig(human).joint_count(), Jf = crowd.rig(fingered).joint_count();
    auto& pool = crowd.streams();
    walk = pool.add(crowd.rig(human), human, spec_of("walk", 64), std::make_unique<ClipPlayer>(default_clip("walk")));
    wave =
        pool.add(crowd.rig(human), human, spec_of("wave", 32), std::make_unique<ClipPlayer>(wiggle_clip(Jh, 45, kDt)));
    f_walk = pool.add(crowd.rig(fingered), fingered, spec_of("f_walk", 64),
                      std::make_unique<ClipPlayer>(wiggle_clip(Jf, 50, kDt)));
    f_idle = pool.add(crowd.rig(fingered), fingered, spec_of("f_idle", 16),
                      std::make_unique<ClipPlayer>(wiggle_clip(Jf, 70, kDt, "idle"), 0.5f));
    crowd.add_agents(human, 60);
    crowd.add_agents(fingered, 40);
    crowd.assign_random(0, 60, {{{walk}, {walk, wave}, {walk, wave}}, true}, 11);
    crowd.assign_random(60, 40, {{{f_walk, f_idle}, {f_walk, f_idle}, {f_idle}}, true}, 12);
  }
};

TEST(StreamCrowd, MixedSkeletonsAnimateAndPoseMemoryIsTheSumOfStreams) {
  MixedCrowd m;
  StreamCrowd& crowd = m.crowd;
  const World w(crowd.agent_count());
  std::size_t want = 0;
  for (std::int32_t s = 0; s < crowd.streams().size(); ++s) {
    const AnimStream& st = crowd.streams()[s];
    want += static_cast<std::size_t>(st.history()) *
            (static_cast<std::size_t>(crowd.rig(st.rig()).joint_count()) * 64u + 12u);
  }
  EXPECT_EQ(crowd.memory().stream_poses, want);
  EXPECT_EQ(want, 64u * (22 * 64 + 12) + 32u * (22 * 64 + 12) + 64u * (28 * 64 + 12) + 16u * (28 * 64 + 12));
  EXPECT_EQ(crowd.palette_size(), 60 * 22 + 40 * 28);  // palettes are not padded either
  EXPECT_EQ(crowd.memory().palettes, static_cast<std::size_t>(crowd.palette_size()) * 48u);

  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  std::vector<Mat3x4> previous;
  for (int f = 0; f < 90; ++f) {
    crowd.step();
    crowd.resolve(w.positions, w.yaws, palettes);
    if (f % 15 == 14) {
      for (Index a = 0; a < crowd.agent_count(); a += 7) {
        ASSERT_LT(max_palette_error(crowd, palettes, w, a), 2e-4) << "agent " << a << " frame " << f;
      }
    }
    if (f > 64) {
      EXPECT_NE(previous.back().r0, palettes.back().r0);  // it moves (once dilation no longer holds it back)
    }
    previous = palettes;
  }
  // Variety: agents read different offsets; clusters on one stream share one.
  std::set<std::int32_t> offsets;
  for (Index a = 0; a < 60; ++a) {
    const auto refs = crowd.clusters_of(a);
    offsets.insert(refs[0].offset);
    for (int c = 1; c < 3; ++c) {
      if (refs[static_cast<std::size_t>(c)].source == refs[0].source) {
        EXPECT_EQ(refs[static_cast<std::size_t>(c)].offset, refs[0].offset);
      }
    }
  }
  EXPECT_GT(offsets.size(), 20u);
}

TEST(StreamCrowd, AgentsNeverReadAHistorySlotThatWasNotWritten) {
  StreamCrowd crowd({kFps, 3});
  const int h = crowd.add_rig(humanoid_rig());
  const int J = crowd.rig(h).joint_count();
  const auto a = crowd.streams().add(crowd.rig(h), h, spec_of("a", 64, 3.0f),
                                     std::make_unique<ClipPlayer>(wiggle_clip(J, 40, kDt)));
  StreamSpec later = spec_of("b", 48, 2.0f);
  later.running = false;
  const auto b = crowd.streams().add(crowd.rig(h), h, later, std::make_unique<ClipPlayer>(wiggle_clip(J, 30, kDt)));
  crowd.add_agents(h, 500);
  crowd.assign_random(0, 250, {{{a}, {a, b}, {a, b}}, false}, 5);
  crowd.assign_random(250, 250, {{{b}, {b}, {b}}, false}, 6);
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  std::vector<std::int32_t> read(static_cast<std::size_t>(crowd.agent_count() * crowd.cluster_stride()));
  std::int32_t largest = 0;
  for (int f = 0; f < 200; ++f) {
    if (f == 40) crowd.streams().start(b);  // b runs from frame 40 on
    if (f == 120) crowd.streams().stop(a);
    if (f == 150) crowd.streams().start(a);  // restarted: its history counts as empty again
    crowd.step();
    crowd.resolve({}, {}, palettes, read);
    for (Index ag = 0; ag < crowd.agent_count(); ++ag)
      for (int c = 0; c < 3; ++c) {
        const ClusterRef ref = crowd.cluster_refs()[ag * crowd.cluster_stride() + c];
        const AnimStream& s = crowd.streams()[ref.source];
        const std::int32_t o = read[static_cast<std::size_t>(ag * crowd.cluster_stride() + c)];
        if (s.newest_frame() < 0) continue;  // never started: the rest pose it was filled with
        ASSERT_GE(o, 0);
        ASSERT_LT(o, s.written()) << "agent " << ag << " cluster " << c << " frame " << f;
        ASSERT_LE(o, ref.offset);
        largest = std::max(largest, o);
      }
  }
  EXPECT_EQ(largest, 63);  // the offsets did spread over the whole history
}

TEST(StreamCrowd, TransitionAlphaAndBlendedPoseMatchTheReference) {
  MixedCrowd m;
  StreamCrowd& crowd = m.crowd;
  const World w(crowd.agent_count());
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  for (int f = 0; f < 70; ++f) crowd.step();
  const Index agent = 3;
  crowd.assign(agent, 1, 0, m.walk, 10);
  crowd.assign(agent, 1, 1, m.walk, 10);
  crowd.assign(agent, 1, 2, m.walk, 10);
  crowd.transition_to_streamed(agent, 1, m.wave, 0.5f, 4);  // upper body waves, blended over 15 frames
  crowd.transition_to_streamed(agent, 2, m.wave, 0.5f);     // head: matches the upper body's offset
  EXPECT_EQ(crowd.pending_transitions(), 2);
  crowd.step();
  const std::int32_t t0 = crowd.frame();
  auto refs = crowd.clusters_of(agent);
  EXPECT_EQ(refs[1].source, m.wave);
  EXPECT_EQ(refs[1].from_source, m.walk);
  EXPECT_EQ(refs[1].from_offset, 10);
  EXPECT_EQ(refs[1].t0, t0);
  EXPECT_FLOAT_EQ(refs[1].blend_frames, 15.0f);
  EXPECT_EQ(refs[2].offset, 4);
  EXPECT_EQ(refs[0].source, m.walk);
  EXPECT_EQ(refs[0].blend_frames, 0.0f);
  for (int k = 0; k < 20; ++k) {
    if (k > 0) crowd.step();
    EXPECT_NEAR(transition_alpha(refs[1], crowd.frame()), std::clamp(k / 15.0, 0.0, 1.0), 1e-6);
    crowd.resolve(w.positions, w.yaws, palettes);
    ASSERT_LT(max_palette_error(crowd, palettes, w, agent), 2e-4) << k;
  }
  // Half way the upper arm is neither the walk's nor the wave's.
  crowd.transition_to_streamed(agent, 1, m.walk, 1.0f, 10);
  for (int k = 0; k < 16; ++k) crowd.step();
  crowd.resolve(w.positions, w.yaws, palettes);
  ASSERT_LT(max_palette_error(crowd, palettes, w, agent), 2e-4);
  // Errors: another rig's stream, a bad cluster, a bad blend time.
  EXPECT_THROW(crowd.transition_to_streamed(agent, 1, m.f_walk, 0.2f), Error);
  EXPECT_THROW(crowd.transition_to_streamed(agent, 5, m.walk, 0.2f), Error);
  EXPECT_THROW(crowd.transition_to_streamed(agent, 1, m.walk, -1.0f), Error);
  std::vector<Mat3x4> wrong(3);
  EXPECT_THROW(crowd.resolve({}, {}, wrong), Error);
}

TEST(StreamCrowd, EventsReachEachAgentDelayedByItsOffset) {
  StreamCrowd crowd({kFps, 1});
  const int h = crowd.add_rig(humanoid_rig());
  const int J = crowd.rig(h).joint_count();
  EventNames& names = crowd.event_names();
  const auto left = names.intern("footstep_left"), right = names.intern("footstep_right"),
             wave_start = names.intern("wave_start");
  AnimClip walk = wiggle_clip(J, 30, kDt, "walk");  // 1 s loop
  walk.events = {{0.25f, left}, {0.75f, right}};
  AnimClip wave = wiggle_clip(J, 21, kDt, "wave");
  wave.loop = false;
  auto sm = std::make_unique<StateMachine>();
  const auto idle = sm->add_state("idle", std::make_unique<ClipPlayer>(wiggle_clip(J, 40, kDt, "idle")));
  const auto walking = sm->add_state("walk", std::make_unique<ClipPlayer>(walk));
  const auto waving = sm->add_state("wave", std::make_unique<ClipPlayer>(wave), wave_start);
  sm->add_transition(idle, walking, {{"speed", Compare::Greater, 0.5f}}, 0.09f);
  sm->add_transition(walking, idle, {{"speed", Compare::LessEqual, 0.5f}}, 0.09f);
  sm->add_transition(StateMachine::kAnyState, waving, {{"waiting", Compare::Equal, 1.0f}}, 0.09f);
  sm->add_transition(waving, idle, {{"state_finished", Compare::Equal, 1.0f}}, 0.09f);
  const auto stream = crowd.streams().add(crowd.rig(h), h, spec_of("crowd_sm", 32), std::move(sm));
  crowd.add_agents(h, 3);
  crowd.assign(0, 3, 0, stream, 0);
  crowd.assign(0, 3, 1, stream, 0);
  crowd.assign(0, 3, 2, stream, 0);
  crowd.assign(1, 1, 0, stream, 5);                         // agent 1's legs lag 5 frames
  crowd.assign(2, 1, 0, stream, 12);                        // agent 2's legs 12
  crowd.set_event_filter(0, (1u << left) | (1u << right));  // footsteps from the legs,
  crowd.set_event_filter(1, 1u << wave_start);              // waves from the upper body,
  crowd.set_event_filter(2, 0u);                            // nothing from the head
  std::vector<std::vector<std::pair<int, EventMask>>> got(3);
  std::vector<std::pair<int, EventMask>> at_stream;
  for (int f = 0; f < 150; ++f) {
    ParameterSet& p = crowd.streams()[stream].parameters();
    p.set("speed", f >= 10 && f < 100 ? 1.2f : 0.0f);
    p.set("waiting", f == 110 ? 1.0f : 0.0f);
    crowd.step();
    const EventMask s = crowd.streams()[stream].events_at(0);
    if (s) at_stream.emplace_back(f, s);
    for (Index a = 0; a < 3; ++a)
      if (crowd.agent_events()[a]) got[static_cast<std::size_t>(a)].emplace_back(f, crowd.agent_events()[a]);
  }
  // The stream: steps while walking, one wave_start.
  ASSERT_GE(at_stream.size(), 5u);
  EXPECT_EQ(
      std::count_if(at_stream.begin(), at_stream.end(), [&](const auto& e) { return (e.second >> wave_start) & 1u; }),
      1);
  // Agent 0 (offset 0) gets exactly the stream's events on the same frames.
  EXPECT_EQ(got[0], at_stream);
  // Agents 1 and 2 get footsteps (from their legs) 5 and 12 frames later and
  // the wave (from their upper body, offset 0) on time, once.
  for (int a = 1; a < 3; ++a) {
    const int lag = a == 1 ? 5 : 12;
    std::vector<std::pair<int, EventMask>> want;
    for (const auto& [f, ev] : at_stream) {
      const EventMask steps = ev & ((1u << left) | (1u << right));
      const EventMask waves = ev & (1u << wave_start);
      if (steps && f + lag < 150) want.emplace_back(f + lag, steps);
      if (waves) want.emplace_back(f, waves);
    }
    std::sort(want.begin(), want.end());
    // Merge events that land on the same frame.
    std::vector<std::pair<int, EventMask>> merged;
    for (const auto& e : want) {
      if (!merged.empty() && merged.back().first == e.first)
        merged.back().second |= e.second;
      else
        merged.push_back(e);
    }
    EXPECT_EQ(got[static_cast<std::size_t>(a)], merged) << "agent " << a;
  }
}

TEST(StreamCrowd, BoneOverridesReplaceRotationsAndAimLookAt) {
  MixedCrowd m;
  StreamCrowd& crowd = m.crowd;
  const World w(crowd.agent_count());
  std::vector<Mat3x4> plain(static_cast<std::size_t>(crowd.palette_size())), over(plain.size());
  for (int f = 0; f < 30; ++f) crowd.step();
  crowd.resolve(w.positions, w.yaws, plain);
  const Index a = 5, b = 6;
  BoneOverride rot;
  rot.joint = dj::LeftForeArm;
  rot.rotation = glm::angleAxis(1.2f, glm::vec3(0, 0, 1));
  crowd.set_override(a, rot);
  const glm::vec3 target = w.positions[static_cast<std::size_t>(b)] + glm::vec3(2.0f, 1.6f, 1.0f);
  BoneOverride look;
  look.joint = dj::Head;
  look.kind = OverrideKind::LookAt;
  look.target = target;
  look.max_angle = 3.0f;
  crowd.set_override(b, look);
  crowd.resolve(w.positions, w.yaws, over);

  // Agent a: the reference with the forearm's local rotation replaced.
  const Rig& rig = crowd.rig(0);
  AgentPose p = expected_pose(crowd, a);
  p.local[dj::LeftForeArm] = glm::dquat(rot.rotation);
  const auto ref = reference_palette(rig, p.local, p.root, glm::dvec3(w.positions[static_cast<std::size_t>(a)]),
                                     w.yaws[static_cast<std::size_t>(a)]);
  const Index base_a = crowd.palette_offsets()[a];
  for (std::size_t j = 0; j < ref.size(); ++j)
    EXPECT_LT(palette_error(over[static_cast<std::size_t>(base_a) + j], ref[j]), 2e-4) << j;
  EXPECT_GT(palette_error(plain[static_cast<std::size_t>(base_a) + dj::LeftHand], ref[dj::LeftHand]),
            1e-2);  // it did change

  // Agent b: the head's forward axis points at the target; its parents did not move.
  const Index base_b = crowd.palette_offsets()[b];
  const Mat3x4& head = over[static_cast<std::size_t>(base_b) + dj::Head];
  const glm::vec3 head_pos = transform_point(head, rig.bind_positions[dj::Head]);
  const glm::vec3 forward = glm::normalize(transform_vector(head, glm::vec3(0, 0, 1)));
  EXPECT_GT(glm::dot(forward, glm::normalize(target - head_pos)), 0.99999f);
  // (The agent with an override is posed by full forward kinematics, the
  // others by slot palettes: equal up to rounding.)
  for (int j = 0; j < dj::Head; ++j) {
    const Mat3x4& o = over[static_cast<std::size_t>(base_b + j)];
    const Mat3x4& p0 = plain[static_cast<std::size_t>(base_b + j)];
    EXPECT_LT(glm::length(o.r0 - p0.r0) + glm::length(o.r1 - p0.r1) + glm::length(o.r2 - p0.r2), 1e-4f) << j;
  }
  // Clamped: at most max_angle of turn.
  look.max_angle = 0.1f;
  crowd.set_override(b, look);
  crowd.resolve(w.positions, w.yaws, over);
  const glm::vec3 f0 =
      glm::normalize(transform_vector(plain[static_cast<std::size_t>(base_b) + dj::Head], glm::vec3(0, 0, 1)));
  const glm::vec3 f1 =
      glm::normalize(transform_vector(over[static_cast<std::size_t>(base_b) + dj::Head], glm::vec3(0, 0, 1)));
  EXPECT_NEAR(std::acos(std::min(1.0f, glm::dot(f0, f1))), 0.1f, 2e-3f);
  // Cleared: back to the history.
  crowd.clear_overrides(a);
  crowd.clear_override(b, dj::Head);
  crowd.resolve(w.positions, w.yaws, over);
  EXPECT_EQ(over[static_cast<std::size_t>(base_b) + dj::Head].r0,
            plain[static_cast<std::size_t>(base_b) + dj::Head].r0);
  EXPECT_EQ(over[static_cast<std::size_t>(base_a) + dj::LeftHand].r1,
            plain[static_cast<std::size_t>(base_a) + dj::LeftHand].r1);
  BoneOverride bad;
  bad.joint = 40;
  EXPECT_THROW(crowd.set_override(a, bad), Error);
}

TEST(StreamCrowd, HookTransformsOnTheFastAndTheBlendingPath) {
  // Tilted heads and a shifted upper body: agents without a transition take
  // the fast path (segment transforms times slot palettes), one in
  // transition the full forward kinematics; both match the reference.
  StreamCrowd crowd({kFps, 2});
  std::vector<ClusterDef> defs = default_cluster_defs(motion::default_skeleton());
  defs[1].hook_rotation = glm::angleAxis(0.3f, glm::normalize(glm::vec3(0.2f, 1.0f, 0.1f)));
  defs[1].hook_translation = glm::vec3(0.0f, 0.05f, 0.02f);
  defs[2].hook_rotation = glm::angleAxis(-0.4f, glm::vec3(1.0f, 0.0f, 0.0f));
  const int h = crowd.add_rig(make_rig("tilted", motion::default_skeleton(), defs));
  const int J = crowd.rig(h).joint_count();
  const auto a =
      crowd.streams().add(crowd.rig(h), h, spec_of("a", 16), std::make_unique<ClipPlayer>(wiggle_clip(J, 40, kDt)));
  const auto b =
      crowd.streams().add(crowd.rig(h), h, spec_of("b", 16), std::make_unique<ClipPlayer>(default_clip("run_slow")));
  crowd.add_agents(h, 40);
  crowd.assign_random(0, 40, {{{a, b}, {a, b}, {a, b}}, false}, 4);
  const World w(crowd.agent_count());
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  for (int f = 0; f < 20; ++f) crowd.step();
  crowd.transition_to_streamed(7, 1, a, 0.5f);
  crowd.transition_to_streamed(7, 2, b, 0.5f);
  for (int f = 0; f < 5; ++f) crowd.step();
  crowd.resolve(w.positions, w.yaws, palettes);
  ASSERT_LT(transition_alpha(crowd.clusters_of(7)[1], crowd.frame()), 1.0f);
  for (Index ag = 0; ag < 40; ++ag) EXPECT_LT(max_palette_error(crowd, palettes, w, ag), 2e-4) << ag;
}

TEST(StreamCrowd, MannequinsAtRestPoseSkinToTheirBindPose) {
  // Fresh agents read no source: the rest pose. Resolved by the kernel and
  // skinned by the CPU reference, every vertex is where the mesh has it.
  StreamCrowd crowd({kFps, 1});
  crowd.add_rig(humanoid_rig());
  crowd.add_rig(make_rig("fingered", fingered_skeleton()));
  crowd.add_agents(0, 2);
  crowd.add_agents(1, 2);
  crowd.step();
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  crowd.resolve({}, {}, palettes);
  for (Index a = 0; a < 4; ++a) {
    const Rig& rig = crowd.rig(crowd.agent_rig(a));
    const auto J = static_cast<std::size_t>(rig.joint_count());
    std::vector<glm::vec3> p(rig.mesh.positions.size()), n(p.size());
    skin_reference(rig.mesh,
                   std::span<const Mat3x4>(palettes).subspan(static_cast<std::size_t>(crowd.palette_offsets()[a]), J),
                   p, n);
    for (std::size_t v = 0; v < p.size(); ++v) {
      ASSERT_LT(glm::length(p[v] - rig.mesh.positions[v]), 1e-5f) << a << " " << v;
      ASSERT_LT(glm::length(n[v] - rig.mesh.normals[v]), 1e-5f) << a << " " << v;
    }
  }
}

TEST(StreamCrowd, CulledClusterCollapsesOntoItsHook) {
  MixedCrowd m;
  StreamCrowd& crowd = m.crowd;
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  crowd.step();
  crowd.set_culled(2, 2, true);  // head
  crowd.resolve({}, {}, palettes);
  const Rig& rig = crowd.rig(0);
  const Index base = crowd.palette_offsets()[2];
  const glm::vec3 hook =
      transform_point(palettes[static_cast<std::size_t>(base) + dj::Spine2], rig.bind_positions[dj::Spine2]);
  for (int j : {static_cast<int>(dj::Neck), static_cast<int>(dj::Head)})
    for (const glm::vec3& v : {glm::vec3(0.0f), glm::vec3(1.0f, 2.0f, 3.0f)})
      EXPECT_LT(glm::length(transform_point(palettes[static_cast<std::size_t>(base + j)], v) - hook), 1e-6f);
  crowd.set_culled(2, 2, false);
  crowd.resolve({}, {}, palettes);
  EXPECT_GT(glm::length(glm::vec3(palettes[static_cast<std::size_t>(base) + dj::Head].r0)), 0.5f);
}

TEST(StreamCrowd, UniqueAnimationsPlayPerAgentAndHandBack) {
  MixedCrowd m;
  StreamCrowd& crowd = m.crowd;
  const World w(crowd.agent_count());
  const Rig& rig = crowd.rig(m.human);
  crowd.uniques().set_capacity(rig, m.human, 2);
  AnimClip bow = wiggle_clip(rig.joint_count(), 31, kDt, "bow");  // one second, one-shot
  bow.loop = false;
  const auto anim =
      crowd.uniques().add_animation({"bow", m.human, std::make_unique<ClipPlayer>(bow), RootMotion::InPlace});
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  for (int f = 0; f < 10; ++f) crowd.step();
  // Agent 1 bows with its whole body (one instance for its three clusters), then walks.
  for (int c = 0; c < 3; ++c) crowd.transition_to_unique(1, c, anim, 0.2f, m.walk, 0.3f);
  crowd.transition_to_unique(2, 1, anim, 0.2f);                       // agent 2 bows with its upper body and stays
  EXPECT_THROW(crowd.transition_to_unique(4, 1, anim, 0.2f), Error);  // capacity 2
  crowd.step();
  EXPECT_EQ(crowd.uniques().active_count(), 2);
  const auto refs = crowd.clusters_of(1);
  EXPECT_TRUE(is_unique_source(refs[0].source));
  EXPECT_EQ(refs[0].source, refs[2].source);
  EXPECT_NE(refs[0].source, crowd.clusters_of(2)[1].source);
  // The unique's pose is the bow at its own time (0 on the first frame).
  Pose bow_pose;
  for (int k = 1; k < 12; ++k) {
    crowd.step();
    crowd.resolve(w.positions, w.yaws, palettes);
    sample_clip(bow, k * static_cast<double>(kDt), bow_pose);
    const auto views = crowd.uniques().views();
    const SourceView& v = views[unique_instance(refs[1].source)];
    for (int j = 0; j < rig.joint_count(); ++j) ASSERT_EQ(v.rotations[j], bow_pose.local[static_cast<std::size_t>(j)]);
  }
  // Agent 1 goes back to the walk 0.3 s before the bow ends, then its instance is released.
  int back = -1;
  for (int k = 0; k < 40 && back < 0; ++k) {
    crowd.step();
    if (crowd.clusters_of(1)[0].source == m.walk) back = crowd.frame();
  }
  ASSERT_GE(back, 0);
  const auto t0_bow = refs[0].t0;
  EXPECT_NEAR(back - t0_bow, 30 - 9, 1);  // bow of 30 frames, back 9 frames (0.3 s) before its end
  EXPECT_EQ(crowd.clusters_of(1)[0].from_source, refs[0].source);
  crowd.resolve(w.positions, w.yaws, palettes);
  EXPECT_LT(max_palette_error(crowd, palettes, w, 1), 2e-4);
  for (int k = 0; k < 12; ++k) crowd.step();
  EXPECT_EQ(crowd.uniques().active_count(), 1);  // agent 2's remains
  EXPECT_EQ(crowd.uniques().acquire(anim) >= 0, true);
}

// The batch retarget: a desired (stream, offset) per agent in one kernel.
TEST(StreamCrowd, RetargetSetsTransitionsOffsetsAndRestLikeTheOneByOneCalls) {
  MixedCrowd m;
  StreamCrowd& crowd = m.crowd;
  const World w(crowd.agent_count());
  const Rig& rig = crowd.rig(m.human);
  crowd.uniques().set_capacity(rig, m.human, 1);
  const auto anim = crowd.uniques().add_animation(
      {"bow", m.human, std::make_unique<ClipPlayer>(wiggle_clip(rig.joint_count(), 31, kDt, "bow")),
       RootMotion::InPlace});
  for (int f = 0; f < 70; ++f) crowd.step();
  crowd.transition_to_unique(5, 2, anim, 0.0f);
  crowd.step();
  const Index n = crowd.agent_count();
  std::vector<std::int32_t> sources(static_cast<std::size_t>(n), -5),
      offsets(static_cast<std::size_t>(n), 0);  // < -1: left alone
  std::vector<std::vector<ClusterRef>> before;
  for (Index a = 0; a < n; ++a) before.push_back(crowd.clusters_of(a));
  sources[0] = m.wave;  // another stream: blended in
  offsets[0] = 7;
  sources[1] = m.walk;     // clusters already on walk take the offset, the others blend in
  offsets[1] = 1000;       // clamped to the history
  sources[2] = kNoSource;  // rest pose at once
  sources[3] = m.f_walk;   // another rig's stream: ignored
  sources[4] = 99;         // no such stream: ignored
  sources[5] = m.wave;     // cluster 2 is on a unique instance: left alone
  sources[60] = m.f_idle;
  offsets[60] = 3;
  const Buffer<std::int32_t> src(std::span<const std::int32_t>(sources), current_memory());
  const Buffer<std::int32_t> off(std::span<const std::int32_t>(offsets), current_memory());
  // Mask: clusters 0 and 1 follow (cluster 2 of every agent keeps its source).
  const Index changed = crowd.retarget(src.span(), off.span(), 0.5f, 0b011u);
  Index want_changed = 0;
  for (Index a = 0; a < n; ++a) {
    const auto after = crowd.clusters_of(a);
    const auto& old = before[static_cast<std::size_t>(a)];
    bool any = false;
    for (std::size_t c = 0; c < after.size(); ++c) {
      const std::int32_t s = sources[static_cast<std::size_t>(a)];
      const bool follows = c < 2 && (a <= 2 || a == 5 || a == 60) && !is_unique_source(old[c].source);
      if (!follows) {
        EXPECT_EQ(after[c].source, old[c].source) << a << " " << c;
        EXPECT_EQ(after[c].offset, old[c].offset) << a << " " << c;
        EXPECT_EQ(after[c].from_source, old[c].from_source) << a << " " << c;
        continue;
      }
      const std::int32_t want_offset =
          s < 0 ? 0 : std::min(offsets[static_cast<std::size_t>(a)], crowd.streams()[s].history() - 1);
      EXPECT_EQ(after[c].source, s) << a << " " << c;
      EXPECT_EQ(after[c].offset, want_offset) << a << " " << c;
      if (old[c].source == s) {
        EXPECT_EQ(after[c].from_source, old[c].from_source);  // same stream: only the offset moves
      } else if (s >= 0 && old[c].source >= 0) {
        any = true;
        EXPECT_EQ(after[c].from_source, old[c].source) << a << " " << c;
        EXPECT_EQ(after[c].from_offset, old[c].offset);
        EXPECT_EQ(after[c].t0, crowd.frame());
        EXPECT_FLOAT_EQ(after[c].blend_frames, 0.5f * kFps);
      } else {
        any = true;
        EXPECT_EQ(after[c].blend_frames, 0.0f);
      }
    }
    want_changed += any ? 1 : 0;
  }
  EXPECT_EQ(changed, want_changed);
  EXPECT_GE(changed, 3);
  // Palettes follow the references through the blends.
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
  for (int f = 0; f < 20; ++f) {
    crowd.step();
    crowd.resolve(w.positions, w.yaws, palettes);
    for (const Index a : {0, 1, 2, 60}) ASSERT_LT(max_palette_error(crowd, palettes, w, a), 2e-4) << f << " " << a;
  }
  // Skipped agents are not written.
  std::vector<std::uint8_t> skip(static_cast<std::size_t>(n), 0);
  skip[7] = 1;
  const Buffer<std::uint8_t> skip_buffer(std::span<const std::uint8_t>(skip), current_memory());
  const Mat3x4 marker = collapse_to(glm::vec3(42.0f));
  const auto base7 = static_cast<std::size_t>(crowd.palette_offsets()[7]);
  palettes[base7] = marker;
  crowd.resolve(w.positions, w.yaws, palettes, {}, skip_buffer.span());
  EXPECT_EQ(palettes[base7].r0, marker.r0);
  EXPECT_LT(max_palette_error(crowd, palettes, w, 8), 2e-4);
  EXPECT_THROW(crowd.retarget(src.span(), off.span(), -1.0f), Error);
}

TEST(StreamCrowd, IdenticalResultsOnOneTwoAndManyThreads) {
  auto run = [](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    MixedCrowd m;
    StreamCrowd& crowd = m.crowd;
    const World w(crowd.agent_count());
    BoneOverride look;
    look.joint = dj::Head;
    look.kind = OverrideKind::LookAt;
    look.target = glm::vec3(3, 1.7f, 3);
    for (Index a = 0; a < 60; a += 3) crowd.set_override(a, look);
    std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd.palette_size()));
    std::vector<EventMask> events;
    for (int f = 0; f < 40; ++f) {
      if (f == 5)
        for (Index a = 0; a < 60; a += 2) crowd.transition_to_streamed(a, 1, a % 4 == 0 ? m.walk : m.wave, 0.4f);
      crowd.step();
      const auto e = crowd.agent_events();
      events.insert(events.end(), e.begin(), e.end());
    }
    crowd.resolve(w.positions, w.yaws, palettes);
    std::vector<float> flat;
    for (const Mat3x4& x : palettes)
      for (const glm::vec4& r : {x.r0, x.r1, x.r2}) flat.insert(flat.end(), {r.x, r.y, r.z, r.w});
    return std::make_pair(flat, events);
  };
  const auto one = run(1);
  const auto two = run(2);
  const auto many = run(7);
  EXPECT_EQ(one.first, two.first);
  EXPECT_EQ(one.first, many.first);
  EXPECT_EQ(one.second, two.second);
  EXPECT_EQ(one.second, many.second);
}

}  // namespace
}  // namespace throng::anim
