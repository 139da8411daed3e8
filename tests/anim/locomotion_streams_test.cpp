// Locomotion through streams: streamed agents read what synthesis at their
// bucket's blend gives, agents near the camera are synthesised exactly, the
// error of sharing shrinks with the bucket width within a derived bound,
// bucket changes are transitions, streams start filled and stop unused,
// feet of streamed agents stay planted, and results do not depend on the
// thread count.
#include "anim/locomotion_streams.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <set>
#include <string>

#include "core/error.h"
#include "core/exec.h"
#include "core/random.h"

namespace throng::anim {
namespace {

constexpr float kFps = 30.0f;

std::shared_ptr<const motion::BlendSpace1D> space() { return default_blend_spaces().speeds; }

struct Crowd {
  std::vector<glm::vec3> positions;
  std::vector<float> yaws, speeds;
};

// Agents on a grid 2 m apart with random headings; speeds as given.
Crowd grid_crowd(const std::vector<float>& speeds, std::uint64_t seed) {
  Crowd c;
  const auto side = static_cast<Index>(std::ceil(std::sqrt(static_cast<double>(speeds.size()))));
  Rng rng(seed);
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    c.positions.emplace_back(2.0f * static_cast<float>(static_cast<Index>(i) % side), 0.0f,
                             2.0f * static_cast<float>(static_cast<Index>(i) / side));
    c.yaws.push_back(static_cast<float>(rng.uniform(-3.14159, 3.14159)));
    c.speeds.push_back(speeds[i]);
  }
  return c;
}

std::vector<float> speed_sweep(int count, float top) {
  std::vector<float> s;
  for (int i = 0; i < count; ++i) s.push_back(top * static_cast<float>(i) / static_cast<float>(count - 1));
  return s;
}

// World joint positions of agent a from its palette (palette * bind position).
std::vector<glm::vec3> palette_joints(const LocomotionStreams& loco, Index a) {
  const Rig& rig = loco.rig();
  const Span<const Mat3x4> palettes = loco.palettes();
  std::vector<glm::vec3> out;
  for (std::int32_t j = 0; j < loco.joint_count(); ++j)
    out.push_back(
        transform_point(palettes[a * loco.joint_count() + j], rig.bind_positions[static_cast<std::size_t>(j)]));
  return out;
}

// motion::synthesise_pose for one agent at a blend speed and phase (quantum: bucket width, 0 = exact w).
std::vector<glm::vec3> synthesised(const LocomotionStreams& loco, Index a, float quantum) {
  motion::BlendSpaceView v = loco.blend_space().view();
  if (quantum > 0.0f) {
    v.quantum = quantum;
    v.quantum_buckets = motion::weight_bucket_count(quantum);
  }
  const motion::CharacterFrame f =
      motion::character_frame(v, loco.speeds()[a], loco.phases()[a], loco.positions()[a], loco.yaws()[a], 1.0f);
  std::vector<glm::vec3> p(static_cast<std::size_t>(v.joint_count));
  std::vector<glm::quat> q(p.size());
  motion::synthesise_pose(v, f, p.data(), q.data());
  return p;
}

double largest_distance(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double worst = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) worst = std::max(worst, static_cast<double>(glm::length(a[j] - b[j])));
  return worst;
}

TEST(LocomotionStreams, StreamedAgentsShowSynthesisAtTheirBucketsBlendAndTheirPhase) {
  const Crowd c = grid_crowd(speed_sweep(97, 4.6f), 3);
  const auto n = static_cast<Index>(c.speeds.size());
  LocomotionStreams loco(space(), n);
  loco.set_agents(c.positions, c.yaws, c.speeds);
  for (int frame = 0; frame < 45; ++frame) {
    const LocomotionStreamsStats& s = loco.animate(nullptr);
    EXPECT_EQ(s.streamed, n);
    EXPECT_EQ(s.exact, 0);
    double worst = 0.0;
    for (Index a = 0; a < n; ++a)
      worst = std::max(worst, largest_distance(palette_joints(loco, a), synthesised(loco, a, 0.05f)));
    ASSERT_LT(worst, 2e-4) << frame;  // metres: float FK through the palettes
  }
  // Streams in use: one per distinct bucket of the agents' speeds.
  std::set<std::int32_t> keys;
  const motion::BlendSpaceView v = loco.blend_space().view();
  for (float s : c.speeds)
    keys.insert(cache_key(motion::blend_point(v, motion::blend_coordinate(v, s)), 0.05f, loco.bucket_count()));
  EXPECT_EQ(loco.last_frame().streams_in_use, static_cast<std::int32_t>(keys.size()));
  EXPECT_EQ(loco.last_frame().streams_running, static_cast<std::int32_t>(keys.size()));
  EXPECT_EQ(loco.last_frame().streams, loco.blend_space().segment_count() * loco.bucket_count());
  EXPECT_EQ(loco.last_frame().pose_bytes, loco.crowd().memory().stream_poses);
}

TEST(LocomotionStreams, AnAgentInABucketKeepsItsOffsetAndPlaysAtTheStreamsCadence) {
  const Crowd c = grid_crowd({1.1f, 1.1f, 1.1f, 2.0f}, 5);
  LocomotionStreams loco(space(), 4);
  loco.set_agents(c.positions, c.yaws, c.speeds);
  loco.set_phases(std::vector<float>{0.0f, 0.3f, 0.61f, 0.2f});
  loco.animate(nullptr);
  const std::vector<ClusterRef> first = loco.crowd().clusters_of(1);
  const std::int32_t key = first[0].source;
  const float frames = static_cast<float>(loco.crowd().streams()[key].history() - 1);
  for (int frame = 0; frame < 60; ++frame) {
    const float before = loco.phases()[1];
    loco.animate(nullptr);
    const std::vector<ClusterRef> now = loco.crowd().clusters_of(1);
    for (const ClusterRef& r : now) {
      EXPECT_EQ(r.source, key);
      EXPECT_EQ(r.offset, first[0].offset);
      EXPECT_GE(r.offset, 0);
      EXPECT_LT(r.offset, loco.crowd().streams()[key].history());
    }
    // One frame of the stream's cycle per frame (history = ceil(frames per cycle) + 1).
    const float advanced = motion::wrap_phase(loco.phases()[1] - before);
    EXPECT_GT(advanced, 1.0f / (frames + 1.0f) - 1e-5f);
    EXPECT_LE(advanced, 1.0f / (frames - 1.0f) + 1e-5f);
  }
  // Agents 0..2 share the stream at different offsets.
  EXPECT_EQ(loco.crowd().clusters_of(0)[0].source, key);
  EXPECT_NE(loco.crowd().clusters_of(0)[0].offset, loco.crowd().clusters_of(2)[0].offset);
}

TEST(LocomotionStreams, ChangingBucketIsATransitionFromTheOldStream) {
  Crowd c = grid_crowd({1.1f, 1.6f}, 7);
  LocomotionStreamsConfig config;
  config.blend_seconds = 0.2f;
  LocomotionStreams loco(space(), 2, config);
  loco.set_agents(c.positions, c.yaws, c.speeds);
  EXPECT_EQ(loco.animate(nullptr).retargeted, 2);  // both join a stream (at once: nothing to blend from)
  EXPECT_EQ(loco.crowd().clusters_of(0)[0].blend_frames, 0.0f);
  for (int f = 0; f < 10; ++f) EXPECT_EQ(loco.animate(nullptr).retargeted, 0);
  const std::int32_t old_key = loco.crowd().clusters_of(0)[0].source;
  c.speeds[0] = 2.4f;
  loco.set_agents(c.positions, c.yaws, c.speeds);
  const LocomotionStreamsStats& s = loco.animate(nullptr);
  EXPECT_EQ(s.retargeted, 1);
  const std::int32_t frame = loco.crowd().frame();
  for (const ClusterRef& r : loco.crowd().clusters_of(0)) {
    EXPECT_EQ(r.from_source, old_key);
    EXPECT_NE(r.source, old_key);
    EXPECT_EQ(r.t0, frame);
    EXPECT_FLOAT_EQ(r.blend_frames, 0.2f * kFps);
  }
  // Half way the pose is between the two streams; once blended, exactly the new bucket's.
  for (int f = 0; f < 7; ++f) loco.animate(nullptr);
  EXPECT_LT(largest_distance(palette_joints(loco, 0), synthesised(loco, 0, 0.05f)), 2e-4);
}

// The palettes composed from references (what the renderer draws) against
// the stream crowd's own resolve (forward kinematics of the slots' local
// rotations, SLERP across a transition): the same for agents on one
// stream, within a few millimetres while a bucket change cross-fades.
TEST(LocomotionStreams, PaletteReferencesComposeWhatTheStreamResolveWrites) {
  Crowd c = grid_crowd(speed_sweep(60, 3.0f), 11);
  LocomotionStreams loco(space(), 60);
  loco.set_agents(c.positions, c.yaws, c.speeds);
  for (int f = 0; f < 5; ++f) loco.animate(nullptr);
  for (std::size_t i = 0; i < c.speeds.size(); i += 3) c.speeds[i] += 0.35f;  // a third change bucket
  loco.set_agents(c.positions, c.yaws, c.speeds);
  loco.animate(nullptr);
  loco.animate(nullptr);  // 2 of the 7.5 frames of the cross-fade

  std::vector<Mat3x4> reference(static_cast<std::size_t>(60 * loco.joint_count()));
  loco.crowd().resolve(Span<const glm::vec3>(c.positions), Span<const float>(c.yaws), Span<Mat3x4>(reference));
  const Span<const Mat3x4> composed = loco.palettes();
  const Rig& rig = loco.rig();
  double steady = 0.0, blending = 0.0;
  int blended = 0;
  for (Index a = 0; a < 60; ++a) {
    const ClusterRef ref = loco.crowd().clusters_of(a)[0];
    const bool fading = transition_alpha(ref, loco.crowd().frame()) < 1.0f;
    blended += fading ? 1 : 0;
    for (std::int32_t j = 0; j < loco.joint_count(); ++j) {
      const glm::vec3 bind = rig.bind_positions[static_cast<std::size_t>(j)];
      const Index k = a * loco.joint_count() + j;
      const double d = glm::length(transform_point(composed[k], bind) - transform_point(reference[k], bind));
      (fading ? blending : steady) = std::max(fading ? blending : steady, d);
    }
  }
  std::cout << "[ figures ] composed against resolve: " << 60 - blended << " agents on one stream, worst joint "
            << steady * 1000.0 << " mm; " << blended << " cross-fading, worst joint " << blending * 1000.0 << " mm\n";
  EXPECT_GE(blended, 15);
  EXPECT_LT(steady, 1e-4);
  // The error of sharing tells the fading agents from the steady ones, and
  // measures a sample when asked.
  const SharingError all = loco.sharing_error();
  EXPECT_EQ(all.agents, 60);
  EXPECT_EQ(all.fading, blended);
  EXPECT_LE(all.steady_max_cm, all.max_cm);
  EXPECT_LT(all.steady_max_cm, 5.0);  // half a bucket from its stream's centre (derived bound 5.3 cm)
  const SharingError some = loco.sharing_error(12);
  EXPECT_EQ(some.agents, 12);
  for (Index k = 0; k < 12; ++k)  // agents 0, 5, 10, ...: the full measure's figures for them
    EXPECT_FLOAT_EQ(some.agent_max_cm[static_cast<std::size_t>(k)], all.agent_max_cm[static_cast<std::size_t>(k * 5)]);
  EXPECT_LT(blending, 0.015);
}

TEST(LocomotionStreams, AgentsNearTheCameraAreSynthesisedExactly) {
  // A line of agents walking away from a camera: the nearest are large on screen.
  std::vector<glm::vec3> positions;
  std::vector<float> yaws, speeds;
  for (int i = 0; i < 60; ++i) {
    positions.emplace_back(0.0f, 0.0f, -1.5f * static_cast<float>(i));
    yaws.push_back(0.3f * static_cast<float>(i));
    speeds.push_back(0.07f * static_cast<float>(i));
  }
  Camera camera;
  camera.position = glm::vec3(0.0f, 1.6f, 4.0f);
  camera.target = glm::vec3(0.0f, 1.0f, -20.0f);
  LocomotionStreams loco(space(), 60);
  loco.set_agents(positions, yaws, speeds);
  for (int frame = 0; frame < 5; ++frame) {
    const LocomotionStreamsStats& s = loco.animate(&camera);
    EXPECT_GT(s.exact, 0);
    EXPECT_GT(s.streamed, 0);
    EXPECT_EQ(s.exact + s.streamed, 60);
    EXPECT_GT(s.exact_bytes, 0u);
    Index exact = 0;
    for (Index a = 0; a < 60; ++a) {
      if (!loco.exact()[a]) continue;
      ++exact;
      EXPECT_LT(largest_distance(palette_joints(loco, a), synthesised(loco, a, 0.0f)), 1e-4) << a;
      EXPECT_EQ(loco.crowd().clusters_of(a)[0].source, kNoSource);
    }
    EXPECT_EQ(exact, s.exact);
    // Exact where joint LOD under the same threshold puts some body part at level 0.
    const BodyParts parts = make_body_parts(space()->skeleton());
    const LodTables tables(make_lod_config(parts, {LocomotionStreamsConfig{}.exact_coverage}), Memory::Host);
    std::vector<std::uint8_t> levels(60 * kBodyPartCount);
    std::vector<std::uint32_t> masks(static_cast<std::size_t>(60 * tables.mask_words));
    make_lod_job(camera, tables, parts, {positions, yaws, {}}, levels, masks).run();
    for (Index a = 0; a < 60; ++a) {
      bool level0 = false;
      for (int p = 0; p < kBodyPartCount; ++p)
        level0 = level0 || levels[static_cast<std::size_t>(a * kBodyPartCount + p)] == 0;
      EXPECT_EQ(loco.exact()[a] != 0, level0) << a;
    }
    EXPECT_TRUE(loco.exact()[0]);    // 4 m from the camera
    EXPECT_FALSE(loco.exact()[59]);  // 90 m away
  }
  // Moving the camera away hands everybody to the streams.
  camera.position = glm::vec3(0.0f, 60.0f, 200.0f);
  const LocomotionStreamsStats& s = loco.animate(&camera);
  EXPECT_EQ(s.exact, 0);
  EXPECT_EQ(loco.sharing_error().agents, 60);
  EXPECT_LT(largest_distance(palette_joints(loco, 0), synthesised(loco, 0, 0.05f)), 2e-4);
}

TEST(LocomotionStreams, StreamsStartFilledWhenNeededAndStopWhenUnused) {
  Crowd c = grid_crowd({1.0f, 1.0f, 3.0f}, 9);
  LocomotionStreamsConfig config;
  config.stop_after_seconds = 0.5f;
  LocomotionStreams loco(space(), 3, config);
  loco.set_agents(c.positions, c.yaws, c.speeds);
  const LocomotionStreamsStats& s = loco.animate(nullptr);
  EXPECT_EQ(s.streams_started, 2);
  EXPECT_EQ(s.streams_running, 2);
  const std::int32_t fast = loco.crowd().clusters_of(2)[0].source;
  const AnimStream& stream = loco.crowd().streams()[fast];
  EXPECT_EQ(stream.max_offset(), stream.history() - 1);  // filled: every offset readable at once
  EXPECT_EQ(stream.written(), stream.history());
  c.speeds[2] = 1.0f;
  loco.set_agents(c.positions, c.yaws, c.speeds);
  for (int f = 0; f < 15; ++f) loco.animate(nullptr);
  EXPECT_EQ(loco.last_frame().streams_in_use, 1);
  EXPECT_EQ(loco.crowd().streams()[fast].state(), StreamState::Running);  // 0.5 s not over yet
  for (int f = 0; f < 2; ++f) loco.animate(nullptr);
  EXPECT_EQ(loco.crowd().streams()[fast].state(), StreamState::Stopped);
  EXPECT_EQ(loco.last_frame().streams_running, 1);
  c.speeds[1] = 3.0f;
  loco.set_agents(c.positions, c.yaws, c.speeds);
  EXPECT_EQ(loco.animate(nullptr).streams_started, 1);  // restarted, filled again
  const ClusterRef r = loco.crowd().clusters_of(1)[0];
  EXPECT_EQ(r.source, fast);
  EXPECT_NE(r.from_source, kNoSource);  // blending in from the slow stream
  EXPECT_EQ(loco.crowd().streams()[fast].max_offset(), loco.crowd().streams()[fast].history() - 1);
  for (int f = 0; f < 8; ++f) loco.animate(nullptr);
  EXPECT_LT(largest_distance(palette_joints(loco, 1), synthesised(loco, 1, 0.05f)), 2e-4);
}

// What sharing costs: the streamed palettes against exact synthesis at the
// agents' own speed and shown phase. The only difference is w: exact w
// against its bucket's centre, at most half a bucket away. So the error is at
// most (b / 2) * D with D the largest derivative of a joint position with
// respect to w, measured here on loco's synthesis by central differences.
TEST(LocomotionStreams, SharingErrorShrinksWithTheBucketWidthWithinTheDerivedBound) {
  const motion::BlendSpaceView v = space()->view();
  const std::int32_t J = v.joint_count;
  double D = 0.0;  // m per unit of w
  {
    std::vector<glm::vec3> p0(static_cast<std::size_t>(J)), p1(p0.size());
    std::vector<glm::quat> q(p0.size());
    const float h = 1e-3f;
    for (std::int32_t seg = 0; seg < v.segment_count(); ++seg)
      for (int wi = 0; wi <= 100; ++wi)
        for (int pi = 0; pi < 48; ++pi) {
          const float w = std::clamp(0.01f * static_cast<float>(wi), h, 1.0f - h);
          const float phase = static_cast<float>(pi) / 48.0f;
          motion::BlendPoint a{seg, seg + 1, seg, w - h}, b{seg, seg + 1, seg, w + h};
          motion::synthesise_pose(v, motion::character_frame_at(v, a, phase, glm::vec3(0.0f), 0.0f, 1.0f), p0.data(),
                                  q.data());
          motion::synthesise_pose(v, motion::character_frame_at(v, b, phase, glm::vec3(0.0f), 0.0f, 1.0f), p1.data(),
                                  q.data());
          for (std::int32_t j = 0; j < J; ++j)
            D = std::max(
                D, static_cast<double>(glm::length(p1[static_cast<std::size_t>(j)] - p0[static_cast<std::size_t>(j)])) /
                       (2.0 * h));
        }
  }
  const Crowd c = grid_crowd(speed_sweep(401, 4.5f), 11);
  const auto n = static_cast<Index>(c.speeds.size());
  std::vector<float> phases;
  Rng rng(12);
  for (Index a = 0; a < n; ++a) phases.push_back(static_cast<float>(rng.uniform()));
  double previous_max = 1e9, previous_mean = 1e9;
  std::cout << "[ figures  ] D = " << 100.0 * D << " cm per unit of w\n";
  for (const float width : {0.2f, 0.1f, 0.05f, 0.025f}) {
    LocomotionStreamsConfig config;
    config.bucket_width = width;
    LocomotionStreams loco(space(), n, config);
    loco.set_agents(c.positions, c.yaws, c.speeds);
    loco.set_phases(phases);
    for (int f = 0; f < 4; ++f) loco.animate(nullptr);
    const SharingError e = loco.sharing_error();
    EXPECT_EQ(e.agents, n);
    const double bound = 100.0 * D * width / 2.0;
    std::cout << "[ figures  ] bucket width " << width << ": max " << e.max_cm << " cm, mean " << e.mean_cm
              << " cm, p95 " << e.p95_cm << " cm, bound " << bound << " cm, streams in use "
              << loco.last_frame().streams_in_use << ", pose bytes " << loco.last_frame().pose_bytes << "\n";
    EXPECT_LE(e.max_cm, 1.05 * bound + 0.02) << width;
    EXPECT_LT(e.max_cm, previous_max) << width;
    EXPECT_LT(e.mean_cm, 0.75 * previous_mean) << width;  // about halves with the width
    previous_max = e.max_cm;
    previous_mean = e.mean_cm;
  }
}

// Feet of streamed agents: an agent plays its bucket's stream at the
// stream's cadence while it moves at its own speed v, so a planted foot
// slides by |v - v_c| per second of contact (v_c the bucket's speed) on top
// of what synthesis itself leaves. Agents walk straight; positions are
// integrated here, as the simulation would.
TEST(LocomotionStreams, StreamedFeetStayPlanted) {
  const std::vector<float> speeds = {0.45f, 0.9f, 1.1f, 1.35f, 1.6f, 1.8f, 2.25f, 2.7f, 3.15f, 3.6f, 4.05f, 4.5f};
  const auto n = static_cast<Index>(speeds.size());
  Crowd c = grid_crowd(speeds, 13);
  for (float& y : c.yaws) y = 0.0f;
  LocomotionStreams loco(space(), n);
  std::vector<Index> all;
  for (Index a = 0; a < n; ++a) all.push_back(a);
  const float dt = 1.0f / kFps;
  loco.set_agents(c.positions, c.yaws, c.speeds);
  loco.animate(nullptr);
  loco.track(all);
  for (int f = 0; f < 8 * 30; ++f) {
    for (Index a = 0; a < n; ++a)
      c.positions[static_cast<std::size_t>(a)].z += speeds[static_cast<std::size_t>(a)] * dt;
    loco.set_agents(c.positions, c.yaws, c.speeds);
    loco.animate(nullptr);
  }
  double worst_max = 0.0, worst_mean = 0.0;
  const motion::FootSkatingReport streamed = loco.foot_skating();
  // The bound: |v - v_c| times the longest contact (a foot is down at most
  // one cycle), plus the slide of per-character synthesis.
  double allowance = 0.0;
  const motion::BlendSpaceView v = space()->view();
  for (Index a = 0; a < n; ++a) {
    const float s = speeds[static_cast<std::size_t>(a)];
    const std::int32_t key =
        cache_key(motion::blend_point(v, motion::blend_coordinate(v, s)), 0.05f, loco.bucket_count());
    const double period =
        1.0 / motion::cycle_rate(v, motion::blend_point(v, motion::blend_coordinate(v, loco.key_speed(key))),
                                 loco.key_speed(key));
    allowance = std::max(allowance, 100.0 * std::abs(s - loco.key_speed(key)) * period);
    const motion::FootSkatingReport exact =
        motion::locomotion_foot_skating(*space(), s, 8.0, motion::LocomotionStep{dt});
    worst_mean = std::max(worst_mean, exact.mean_cm);
    worst_max = std::max(worst_max, exact.max_cm);
  }
  std::cout << "[ figures  ] streamed foot skating: mean " << streamed.mean_cm << " cm, p95 " << streamed.p95_cm
            << " cm, max " << streamed.max_cm << " cm over " << streamed.contacts
            << " contacts; exact synthesis worst mean " << worst_mean << " cm, worst max " << worst_max
            << " cm; allowance " << allowance << " cm\n";
  EXPECT_GT(streamed.contacts, 8 * n);
  EXPECT_LE(streamed.max_cm, worst_max + allowance);
  EXPECT_LE(streamed.mean_cm, 1.0);
}

TEST(LocomotionStreams, IdenticalResultsForOneTwoAndManyThreads) {
  const Index n = 3000;
  std::vector<float> speeds;
  Rng rng(21);
  for (Index a = 0; a < n; ++a) speeds.push_back(static_cast<float>(rng.uniform(0.0, 4.5)));
  const Crowd c = grid_crowd(speeds, 22);
  Camera camera;
  camera.position = glm::vec3(10.0f, 2.0f, -6.0f);
  camera.target = glm::vec3(40.0f, 0.0f, 60.0f);
  auto run = [&](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    LocomotionStreams loco(space(), n);
    Crowd moving = c;
    Index exact = 0;
    for (int f = 0; f < 12; ++f) {
      for (Index a = 0; a < n; ++a)
        moving.speeds[static_cast<std::size_t>(a)] = speeds[static_cast<std::size_t>(a)] * (f < 6 ? 1.0f : 0.8f);
      loco.set_agents(moving.positions, moving.yaws, moving.speeds);
      exact += loco.animate(&camera).exact;
    }
    return std::make_pair(std::vector<Mat3x4>(loco.palettes().begin(), loco.palettes().end()), exact);
  };
  const auto one = run(1);
  EXPECT_GT(one.second, 0);
  for (const int threads : {2, 5}) {
    const auto other = run(threads);
    EXPECT_EQ(other.second, one.second) << threads;
    EXPECT_EQ(std::memcmp(one.first.data(), other.first.data(), one.first.size() * sizeof(Mat3x4)), 0) << threads;
  }
}

TEST(LocomotionStreams, RejectsBadInput) {
  LocomotionStreamsConfig config;
  config.bucket_width = 0.0f;
  EXPECT_THROW(LocomotionStreams(space(), 1, config), Error);
  config = {};
  config.exact_coverage = -1.0f;
  EXPECT_THROW(LocomotionStreams(space(), 1, config), Error);
  config = {};
  config.frame_rate = 0.0f;
  EXPECT_THROW(LocomotionStreams(space(), 1, config), Error);
  EXPECT_THROW(LocomotionStreams(nullptr, 1), Error);
  LocomotionStreams loco(space(), 2);
  EXPECT_THROW(loco.set_agents(std::vector<glm::vec3>(3), std::vector<float>(2), std::vector<float>(2)), Error);
  EXPECT_THROW(loco.set_phases(std::vector<float>{0.0f, 1.0f}), Error);
  EXPECT_THROW(loco.track({2}), Error);

  // The per-frame jobs name the span that does not fit.
  std::vector<float> speeds(2, 1.0f);
  std::vector<std::uint8_t> exact(2);
  std::vector<std::int32_t> flags(2), keys(1);
  StreamBucketJob buckets;
  buckets.speeds = speeds;
  buckets.exact = exact;
  buckets.exact_flags = flags;
  buckets.keys = keys;
  try {
    buckets.run();
    ADD_FAILURE() << "short keys accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("StreamBucketJob.keys"), std::string::npos) << e.what();
  }
  StreamSelectJob select;
  select.speeds = speeds;
  select.exact = exact;
  select.keys = flags;
  select.phases = speeds;
  select.sources = flags;
  select.offsets = flags;
  std::vector<ClusterRef> refs(1);
  select.clusters = refs;  // one agent's, for two
  EXPECT_THROW(select.run(), Error);

  std::vector<PaletteRef> palette_refs(2);
  std::vector<glm::vec3> positions(2);
  std::vector<Mat3x4> palettes(2 * 22 - 1);
  PaletteComposeJob compose{22, palette_refs, positions, speeds, {}, palettes};
  try {
    compose.run();
    ADD_FAILURE() << "a short palette buffer accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("PaletteComposeJob.palettes"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace throng::anim
