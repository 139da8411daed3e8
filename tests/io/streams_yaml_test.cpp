// Animation streams from YAML: the example file builds and animates; bad
// files fail at the right line and column; a crowd mixing the default
// humanoid and a real CMU skeleton (from ../shared) animates without padding.
#include "io/streams_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "anim/blend_controller.h"
#include "core/error.h"
#include "tests/anim/stream_reference.h"
#include "tests/shared_data.h"

namespace throng::io {
namespace {

using namespace anim;
using namespace anim::testing;

std::string error_of(const std::string& yaml, StreamsYamlOptions options = {}) {
  try {
    parse_stream_crowd(yaml, "t.yaml", options);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(StreamsYaml, ExampleBuildsAndItsStateMachineFollowsTheParameters) {
  auto crowd = load_stream_crowd("examples/streams/crowd.yaml");
  ASSERT_EQ(crowd->rig_count(), 1);
  EXPECT_EQ(crowd->rig(0).clusters.count(), 3);
  EXPECT_EQ(crowd->streams().size(), 6);
  EXPECT_EQ(crowd->uniques().capacity(0), 64);
  EXPECT_EQ(crowd->uniques().find_animation("stop_and_turn"), 0);
  EXPECT_GE(crowd->event_names().find("footstep_left"), 0);
  const std::int32_t run_event = crowd->event_names().find("started_running");
  ASSERT_GE(run_event, 0);
  const std::int32_t loco = crowd->streams().find("locomotion");
  ASSERT_GE(loco, 0);
  EXPECT_EQ(crowd->memory().stream_poses, 6u * 64u * (22u * 64u + 12u));

  crowd->add_agents(0, 300);
  crowd->assign_random(0, 300, {{{0, 1, 3}, {0, 1, 2, 3}, {0, 1, 2, 3}}, true}, 3);
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd->palette_size()));
  const auto& sm = dynamic_cast<const StateMachine&>(crowd->streams()[loco].controller());
  std::vector<std::string> states;
  int run_events = 0;
  for (int f = 0; f < 240; ++f) {
    ParameterSet& p = crowd->streams()[loco].parameters();
    p.set("speed", f < 30 ? 0.0f : (f < 120 ? 1.4f : (f < 180 ? 3.0f : 0.0f)));
    p.set("waiting", f >= 200 ? 1.0f : 0.0f);
    crowd->step();
    crowd->resolve({}, {}, palettes);
    const std::string name = sm.state_name(sm.state());
    if (states.empty() || states.back() != name) states.push_back(name);
    run_events += (crowd->streams()[loco].events_at(0) >> run_event) & 1u;
  }
  EXPECT_EQ(states, (std::vector<std::string>{"idle", "walk", "run", "walk", "idle"}));
  EXPECT_EQ(run_events, 1);
  for (const Mat3x4& m : palettes) ASSERT_TRUE(std::isfinite(m.r0.w) && std::isfinite(m.r1.x) && std::isfinite(m.r2.z));
}

// blend1d and blend2d play what the controllers built in C++ play.
TEST(StreamsYaml, BlendControllersMatchTheirCppCounterparts) {
  auto crowd = load_stream_crowd("examples/streams/crowd.yaml");
  const std::int32_t one = crowd->streams().find("walk_by_speed");
  const std::int32_t two = crowd->streams().find("walk_and_turn");
  ASSERT_GE(one, 0);
  ASSERT_GE(two, 0);
  const auto& blend = dynamic_cast<const Blend1DController&>(crowd->streams()[one].controller());
  EXPECT_EQ(blend.space().clip_count(), 4);
  EXPECT_EQ(blend.space().clips().front().name, "idle");
  EXPECT_EQ(blend.space().clips().back().name, "run");
  const std::int32_t left = crowd->event_names().find("footstep_left");
  ASSERT_GE(left, 0);
  EXPECT_EQ(blend.options().footstep_left, left);
  const auto& default_spaces = default_blend_spaces();
  Blend2DController reference(default_spaces.speeds, default_spaces.turn_left, default_spaces.turn_right);
  ParameterSet params;
  params.set("speed", 1.2f);
  params.set("turn", 0.3f);
  int steps = 0;
  Pose want;
  for (int f = 0; f < 40; ++f) {
    crowd->step();
    EventMask e = 0;
    if (f > 0) reference.advance(1.0f / 30.0f, params, e);
    reference.evaluate(want);
    EXPECT_EQ(crowd->streams()[two].pose_at(0).local, want.local) << f;
    steps += (crowd->streams()[one].events_at(0) >> left) & 1u;
  }
  EXPECT_GE(steps, 1);  // 1.33 s at 1.4 m/s: at least one left step
  EXPECT_GT(reference.turn_weight(), 0.0f);
}

TEST(StreamsYaml, ErrorsNameLineAndColumn) {
  const std::string rig = "rigs:\n  - {name: h, skeleton: default}\n";
  const std::string clip = rig + "clips:\n  - {name: w, rig: h, default: walk}\n";
  struct Case {
    std::string yaml, where, what;
  };
  const std::vector<Case> cases = {
      {rig + "streams:\n  - name: s\n    rig: h\n    histroy: 8\n", "t.yaml:6:5", "unknown key 'histroy'"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {clip: nope}}\n", "t.yaml:6:42", "no clip named 'nope'"},
      {clip + "streams:\n  - {name: s, rig: h, history: -3, controller: {clip: w}}\n", "t.yaml:6:32",
       "must be in [1, 65536], got -3"},
      {clip + "streams:\n  - {name: s, rig: h, history: 64, time_to_dilate: 1, controller: {clip: w}}\n", "t.yaml:6:5",
       "time_to_dilate: must be at least"},
      {clip + "streams:\n  - name: s\n    rig: h\n    controller:\n      state_machine:\n        states: [{name: a, "
              "controller: {clip: w}}]\n"
              "        transitions: [{from: a, to: b}]\n",
       "t.yaml:11:37", "no state named 'b'"},
      {clip + "streams:\n  - name: s\n    rig: h\n    controller:\n      state_machine:\n        states: [{name: a, "
              "controller: {clip: w}}, "
              "{name: b, controller: {clip: w}}]\n        transitions: [{from: a, to: b, when: 'speed >> 2'}]\n",
       "t.yaml:11:46", "expected a number after the comparison"},
      {"rigs: [{name: h, skeleton: robot}]\n", "t.yaml:1:28", "the only built-in skeleton is 'default'"},
      {"rigs: [{name: h, bvh: /no/such/file.bvh}]\n", "t.yaml:1:23", "cannot read '/no/such/file.bvh'"},
      {"rigs: [{name: h, skeleton: default}\n", "t.yaml:", "end of sequence flow"},
      {rig + "clips:\n  - {name: w, rig: h, default: sprint}\n", "t.yaml:4:32", "no default motion 'sprint'"},
      {rig + "clips:\n  - {name: w, rig: h, default: walk, events: [{name: e, time: 9}]}\n", "t.yaml:4:63",
       "must be in [0, "},
      {rig + "clips:\n  - {name: w, rig: h, default: walk}\nstreams:\n  - {name: s, rig: h, controller: {layered: "
             "{base: {clip: w}, "
             "layers: [{controller: {clip: w}, mask: [Tail]}]}}}\n",
       "t.yaml:6:102", "no joint named 'Tail'"},
      {"rigs: [{name: h, skeleton: default, clusters: [{name: up, roots: [Spine]}]}]\n", "t.yaml:1:8",
       "must be a root of some cluster"},
      {rig + "unique:\n  - {name: u, rig: h, controller: {clip: w}}\n", "t.yaml:4:20", "has no unique_capacity"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {blend1d: {clips: [w, nope]}}}\n", "t.yaml:6:57",
       "no clip named 'nope'"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {blend1d: {clips: [w, w]}}}\n", "t.yaml:6:53",
       "have the same speed"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {blend1d: {space: mine}}}\n", "t.yaml:6:53",
       "the only built-in blend space"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {blend1d: {space: default, speed: -1}}}\n", "t.yaml:6:69",
       "must be in [0, 100], got -1"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {blend2d: {clips: [w]}}}\n", "t.yaml:6:45",
       "missing required key 'turn_left'"},
      {clip + "streams:\n  - {name: s, rig: h, controller: {blend2d: {space: default, turn_left: w, turn_right: w}}}\n",
       "t.yaml:", "must turn"},
  };
  // Each position is the first character of the offending value (or of the
  // mapping that lacks or contradicts something).
  for (const Case& c : cases) {
    const std::string e = error_of(c.yaml);
    EXPECT_EQ(e.rfind(c.where, 0), 0u) << e << "\n--- for ---\n" << c.yaml;
    EXPECT_NE(e.find(c.what), std::string::npos) << e << "\n--- for ---\n" << c.yaml;
  }
  StreamsYamlOptions small;
  small.limits.max_pose_bytes = 10000;
  EXPECT_NE(error_of(clip + "streams:\n  - {name: s, rig: h, history: 64, controller: {clip: w}}\n", small)
                .find("pose memory would exceed"),
            std::string::npos);
  StreamsYamlOptions no_files;
  no_files.allow_files = false;
  EXPECT_NE(error_of("rigs: [{name: h, bvh: x.bvh}]\n", no_files).find("not allowed"), std::string::npos);
}

// Two skeletons side by side: the default humanoid (22 joints) and a real
// CMU skeleton (31 joints), each with its own streams.
TEST(StreamsYaml, MixedCrowdWithARealCmuSkeleton) {
  const auto found = ::throng::test::shared_bvh("cmu_02_01_walk_mb.bvh");
  THRONG_REQUIRE_SHARED_DATA(found);
  const std::string bvh = found->string();
  const std::string yaml = "frame_rate: 30\nrigs:\n  - {name: human, skeleton: default}\n  - {name: cmu, bvh: '" + bvh +
                           "'}\nclips:\n  - {name: walk, rig: human, default: walk, footsteps: true}\n"
                           "  - {name: idle, rig: human, default: idle}\n"
                           "  - {name: cmu_walk, rig: cmu, bvh: '" +
                           bvh +
                           "', frames: [10, 130], footsteps: true}\n"
                           "streams:\n  - {name: h_walk, rig: human, history: 64, controller: {clip: walk}}\n"
                           "  - {name: h_idle, rig: human, history: 32, controller: {clip: idle}}\n"
                           "  - {name: c_walk, rig: cmu, history: 64, controller: {clip: cmu_walk}}\n"
                           "  - {name: c_slow, rig: cmu, history: 48, controller: {clip: cmu_walk, rate: 0.5}}\n";
  auto crowd = parse_stream_crowd(yaml, "mixed.yaml");
  const Rig& cmu = crowd->rig(1);
  EXPECT_EQ(cmu.joint_count(), 31);
  EXPECT_EQ(cmu.clusters.count(), 3);  // lower, upper, head from the roles found by name
  EXPECT_GT(cmu.mesh.vertex_count(), 1000);
  EXPECT_GE(crowd->event_names().find("footstep_right"), 0);

  crowd->add_agents(0, 500);
  crowd->add_agents(1, 500);
  crowd->assign_random(0, 500, {{{0, 1}, {0, 1}, {0}}, true}, 1);
  crowd->assign_random(500, 500, {{{2, 3}, {2, 3}, {2, 3}}, true}, 2);
  const std::size_t want =
      64u * (22u * 64u + 12u) + 32u * (22u * 64u + 12u) + 64u * (31u * 64u + 12u) + 48u * (31u * 64u + 12u);
  EXPECT_EQ(crowd->memory().stream_poses, want);
  EXPECT_EQ(crowd->palette_size(), 500 * 22 + 500 * 31);

  std::vector<glm::vec3> pos;
  std::vector<float> yaw;
  for (int a = 0; a < 1000; ++a) {
    pos.emplace_back(static_cast<float>(a % 40), 0.0f, static_cast<float>(a / 40));
    yaw.push_back(0.1f * static_cast<float>(a));
  }
  std::vector<Mat3x4> palettes(static_cast<std::size_t>(crowd->palette_size()));
  int steps = 0;
  for (int f = 0; f < 60; ++f) {
    crowd->step();
    for (Index a = 500; a < 1000; ++a) steps += crowd->agent_events()[a] != 0;
  }
  crowd->resolve(pos, yaw, palettes);
  EXPECT_GT(steps, 100);  // CMU agents' footsteps arrive
  // A CMU agent's palette against the matrix reference from its stream's history.
  for (Index a : {Index{500}, Index{777}, Index{999}}) {
    const auto refs = crowd->clusters_of(a);
    std::vector<glm::dquat> local(31);
    glm::dvec3 root(0.0);
    for (std::size_t j = 0; j < 31; ++j) {
      const auto& ref = refs[cmu.clusters.cluster_of_joint[j]];
      const AnimStream& s = crowd->streams()[ref.source];
      const Pose p = s.pose_at(std::min(ref.offset, s.max_offset()));
      local[j] = glm::dquat(p.local[j]);
      if (j == 0) root = glm::dvec3(p.root);
    }
    const auto want_palette = reference_palette(cmu, local, root, glm::dvec3(pos[static_cast<std::size_t>(a)]),
                                                yaw[static_cast<std::size_t>(a)]);
    const Index base = crowd->palette_offsets()[a];
    for (std::size_t j = 0; j < 31; ++j)
      ASSERT_LT(palette_error(palettes[static_cast<std::size_t>(base) + j], want_palette[j]), 3e-4) << a << " " << j;
  }
}

}  // namespace
}  // namespace throng::io
