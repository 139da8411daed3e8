// Controllers: clip sampling against a double-precision SLERP, events on
// clip times, layers with bone masks, and a state machine driven by
// scripted parameters.
#include "anim/controller.h"

#include <gtest/gtest.h>

#include <map>

#include "core/error.h"
#include "motion/default_set.h"
#include "stream_reference.h"
#include "tests/motion/reference_rotation.h"

namespace throng::anim {
namespace {

using namespace testing;
constexpr float kDt = 1.0f / 30.0f;

using test::rotation_between_deg;

TEST(ClipPlayer, SamplesBetweenFramesBySlerp) {
  const AnimClip clip = wiggle_clip(6, 10, kDt);
  Pose p;
  for (double t : {0.0, 0.31 * kDt, 3.7 * kDt, 8.999 * kDt}) {
    sample_clip(clip, t, p);
    const int f = static_cast<int>(t / kDt);
    const double a = t / kDt - f;
    for (int j = 0; j < 6; ++j) {
      const glm::dquat want =
          sine_slerp(glm::dquat(clip.clip->rotation(f, j)), glm::dquat(clip.clip->rotation(f + 1, j)), a);
      EXPECT_LT(rotation_between_deg(glm::dquat(p.local[static_cast<std::size_t>(j)]), want), 1e-3) << t << " " << j;
    }
    const glm::vec3 r = glm::mix(clip.clip->root_positions[static_cast<std::size_t>(f)],
                                 clip.clip->root_positions[static_cast<std::size_t>(f + 1)], static_cast<float>(a));
    EXPECT_LT(glm::length(p.root - r), 1e-5f);
  }
}

TEST(ClipPlayer, LoopWrapsFromLastFrameToFirstAndOneShotHolds) {
  AnimClip clip = wiggle_clip(4, 10, kDt);
  Pose p;
  sample_clip(clip, 9.5 * kDt, p);  // half way from frame 9 to frame 0
  for (int j = 0; j < 4; ++j) {
    const glm::dquat want =
        sine_slerp(glm::dquat(clip.clip->rotation(9, j)), glm::dquat(clip.clip->rotation(0, j)), 0.5);
    EXPECT_LT(rotation_between_deg(glm::dquat(p.local[static_cast<std::size_t>(j)]), want), 1e-3);
  }
  // Root carried on by the last frame's step, not jumping back.
  const auto& r = clip.clip->root_positions;
  EXPECT_LT(glm::length(p.root - (r[9] + 0.5f * (r[9] - r[8]))), 1e-5f);
  sample_clip(clip, 10.0 * kDt + 2.0 * kDt, p);  // one loop later
  EXPECT_LT(rotation_between_deg(glm::dquat(p.local[1]), glm::dquat(clip.clip->rotation(2, 1))), 1e-3);

  clip.loop = false;
  ClipPlayer player(clip);
  EXPECT_NEAR(player.duration(), 9.0 * kDt, 1e-9);
  ParameterSet params;
  EventMask ev = 0;
  for (int i = 0; i < 20; ++i) player.advance(kDt, params, ev);
  EXPECT_TRUE(player.finished());
  player.evaluate(p);
  EXPECT_LT(rotation_between_deg(glm::dquat(p.local[2]), glm::dquat(clip.clip->rotation(9, 2))), 1e-3);
}

TEST(ClipPlayer, EventsFireOnceEachTimeThePlayheadPassesThem) {
  AnimClip clip = wiggle_clip(3, 30, kDt);  // loops in 1 s
  clip.events = {{0.0f, 0}, {0.5f, 1}};
  ParameterSet params;
  for (float rate : {1.0f, 2.0f, -1.0f}) {
    ClipPlayer player(clip, rate);
    std::map<int, std::vector<int>> fired;  // event -> frames
    for (int f = 0; f < 90; ++f) {
      EventMask ev = 0;
      player.advance(kDt, params, ev);
      for (int e = 0; e < 2; ++e)
        if ((ev >> e) & 1u) fired[e].push_back(f);
    }
    const std::size_t expect = rate == 2.0f ? 6u : 3u;  // 3 s of playback, twice as fast
    EXPECT_EQ(fired[0].size(), expect) << rate;
    EXPECT_EQ(fired[1].size(), expect) << rate;
    if (rate == 1.0f) {
      EXPECT_EQ(fired[0].front(), 0);   // the start position passes event 0 on the first advance
      EXPECT_EQ(fired[1].front(), 14);  // advance 14 covers [14 dt, 15 dt), which holds 0.5 s
    }
  }
  ClipPlayer fast(clip, 1.0f);
  EventMask ev = 0;
  fast.advance(2.5f, params, ev);  // more than a whole loop at once
  EXPECT_EQ(ev, 3u);
  EXPECT_THROW(ClipPlayer(clip, std::nanf("")), Error);
  clip.events = {{1.5f, 0}};
  EXPECT_THROW(ClipPlayer{clip}, Error);
}

TEST(ClipEvents, FootstepsOfTheDefaultWalkAlternate) {
  EventNames names;
  const AnimClip walk = default_clip("walk");
  const auto events = footstep_events(motion::default_skeleton(), walk, names);
  const std::int32_t left = names.find("footstep_left"), right = names.find("footstep_right");
  ASSERT_GE(left, 0);
  ASSERT_GE(right, 0);
  ASSERT_EQ(events.size(), 2u);  // one stride
  // The generator puts the left heel strike at frame 0 and the right half a stride later.
  EXPECT_EQ(events[0].id, left);
  EXPECT_NEAR(events[0].time, 0.0f, 2.0f * walk.clip->frame_time);
  EXPECT_EQ(events[1].id, right);
  EXPECT_NEAR(events[1].time, 0.5 * walk.duration(), 2.0 * walk.clip->frame_time);
  EXPECT_EQ(names.describe((1u << left) | (1u << right)), "footstep_left|footstep_right");
}

TEST(Layers, OverrideAndAdditiveWithBoneMasks) {
  const motion::Skeleton skel = motion::default_skeleton();
  const int J = skel.joint_count();
  const AnimClip base_clip = wiggle_clip(J, 12, kDt, "base");
  auto layer_clip = wiggle_clip(J, 12, kDt, "layer");
  auto mutable_clip = std::make_shared<motion::Clip>(*layer_clip.clip);
  for (auto& q : mutable_clip->rotations) q = glm::normalize(q * glm::angleAxis(0.8f, glm::vec3(1, 0, 0)));
  layer_clip.clip = mutable_clip;

  LayeredController layered(std::make_unique<ClipPlayer>(base_clip));
  Layer over;
  over.controller = std::make_unique<ClipPlayer>(layer_clip);
  over.weight = 0.5f;
  over.mask = BoneMask::subtrees(skel, {"LeftArm"});
  layered.add_layer(std::move(over));
  Layer add;
  add.controller = std::make_unique<ClipPlayer>(layer_clip);
  add.mode = LayerMode::Additive;
  add.weight_parameter = "nod";
  add.mask = BoneMask::subtrees(skel, {"Neck"}, 0.5f);
  add.reference = std::vector<glm::quat>(static_cast<std::size_t>(J), glm::angleAxis(0.3f, glm::vec3(0, 0, 1)));
  layered.add_layer(std::move(add));

  ParameterSet params;
  params.set("nod", 0.8f);
  EventMask ev = 0;
  for (int i = 0; i < 5; ++i) layered.advance(kDt, params, ev);
  Pose got, b, l;
  layered.evaluate(got);
  sample_clip(base_clip, 5 * kDt, b);
  sample_clip(layer_clip, 5 * kDt, l);
  namespace dj = motion::default_joint;
  for (int j = 0; j < J; ++j) {
    const glm::dquat qb(b.local[static_cast<std::size_t>(j)]), ql(l.local[static_cast<std::size_t>(j)]);
    glm::dquat want = qb;
    if (j == dj::LeftArm || j == dj::LeftForeArm || j == dj::LeftHand) want = sine_slerp(qb, ql, 0.5);
    if (j == dj::Neck || j == dj::Head) {
      const glm::dquat ref(glm::angleAxis(0.3f, glm::vec3(0, 0, 1)));
      want = qb * sine_slerp(glm::dquat(1, 0, 0, 0), glm::inverse(ref) * ql, 0.8 * 0.5);
    }
    EXPECT_LT(rotation_between_deg(glm::dquat(got.local[static_cast<std::size_t>(j)]), want), 2e-3)
        << skel.names[static_cast<std::size_t>(j)];
  }
  // A clone evolves independently and equally.
  auto copy = layered.clone();
  layered.advance(kDt, params, ev);
  copy->advance(kDt, params, ev);
  Pose a1, a2;
  layered.evaluate(a1);
  copy->evaluate(a2);
  EXPECT_EQ(a1.local, a2.local);

  Layer bad;
  bad.controller = std::make_unique<ClipPlayer>(wiggle_clip(J - 1, 4, kDt));
  try {
    layered.add_layer(std::move(bad));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "layers[2].controller");
  }
}

// idle -> walk -> run -> walk -> idle -> wave -> idle, driven by speed and "waiting".
struct ScriptedMachine {
  EventNames names;
  std::unique_ptr<StateMachine> sm = std::make_unique<StateMachine>();
  std::int32_t idle = 0, walk = 0, run = 0, wave = 0;
  std::int32_t step_left = 0, step_right = 0, wave_start = 0;

  ScriptedMachine() {
    const int J = 5;
    step_left = names.intern("footstep_left");
    step_right = names.intern("footstep_right");
    wave_start = names.intern("wave_start");
    AnimClip walk_clip = wiggle_clip(J, 30, kDt, "walk");  // 1 s loop
    walk_clip.events = {{0.0f, step_left}, {0.5f, step_right}};
    AnimClip wave_clip = wiggle_clip(J, 17, kDt, "wave");  // 16 frames long, one-shot
    wave_clip.loop = false;
    idle = sm->add_state("idle", std::make_unique<ClipPlayer>(wiggle_clip(J, 40, kDt, "idle")));
    walk = sm->add_state("walk", std::make_unique<ClipPlayer>(walk_clip));
    run = sm->add_state("run", std::make_unique<ClipPlayer>(walk_clip, 2.0f));
    wave = sm->add_state("wave", std::make_unique<ClipPlayer>(wave_clip), wave_start);
    sm->add_transition(idle, walk, {{"speed", Compare::Greater, 0.5f}}, 0.19f);
    sm->add_transition(walk, run, {{"speed", Compare::Greater, 2.5f}}, 0.19f);
    sm->add_transition(run, walk, {{"speed", Compare::LessEqual, 2.5f}}, 0.19f);
    sm->add_transition(walk, idle, {{"speed", Compare::LessEqual, 0.5f}}, 0.19f);
    sm->add_transition(StateMachine::kAnyState, wave, {{"waiting", Compare::Equal, 1.0f}}, 0.09f);
    sm->add_transition(wave, idle, {{"state_finished", Compare::Equal, 1.0f}}, 0.09f);
  }
  static void script(int f, ParameterSet& p) {
    p.set("speed", f < 10 ? 0.0f : (f < 30 ? 1.0f : (f < 50 ? 3.0f : 0.0f)));
    p.set("waiting", f == 70 ? 1.0f : 0.0f);
  }
};

TEST(StateMachine, ScriptedParametersGiveTheExpectedStatesAndEvents) {
  ScriptedMachine m;
  ParameterSet params;
  std::vector<std::pair<int, std::string>> entered;
  std::vector<std::pair<int, EventMask>> events;
  std::int32_t last = m.sm->state();
  std::vector<std::int32_t> dominant;
  for (int f = 0; f < 110; ++f) {
    ScriptedMachine::script(f, params);
    EventMask ev = 0;
    m.sm->advance(kDt, params, ev);
    if (m.sm->state() != last) entered.emplace_back(f, m.sm->state_name(m.sm->state()));
    last = m.sm->state();
    if (ev != 0) events.emplace_back(f, ev);
    dominant.push_back(m.sm->fade_weight() >= 0.5f || m.sm->fading_from() < 0 ? m.sm->state() : m.sm->fading_from());
  }
  // Fades of 0.19 s take 6 frames; no transition fires while one runs, so
  // walk -> idle waits for the run -> walk fade; the one-shot wave (16
  // frames) hands back to idle on the frame it finishes.
  const std::vector<std::pair<int, std::string>> want = {{10, "walk"}, {30, "run"},  {50, "walk"},
                                                         {56, "idle"}, {70, "wave"}, {86, "idle"}};
  EXPECT_EQ(entered, want);
  // wave_start exactly once, on entering; footsteps only while walk or run dominates.
  int waves = 0;
  std::vector<int> steps;
  for (const auto& [f, ev] : events) {
    if ((ev >> m.wave_start) & 1u) {
      EXPECT_EQ(f, 70);
      ++waves;
    }
    if ((ev >> m.step_left) & 1u || (ev >> m.step_right) & 1u) {
      steps.push_back(f);
      const auto d = dominant[static_cast<std::size_t>(f)];
      EXPECT_TRUE(d == m.walk || d == m.run) << f;
    }
  }
  EXPECT_EQ(waves, 1);
  // Walk entered at frame 10 covers [(f - 11) dt, (f - 10) dt) on frame f:
  // its 0.5 s step falls on frame 25 (its 0 s step on frame 11, while idle
  // still dominates the fade). Run (walk at rate 2) entered at 30 covers
  // [2 (f - 31) dt, 2 (f - 30) dt): 0.5 s on frame 38 and the loop's end
  // (30 dt, exactly the start of frame 46's interval) on frame 46; its
  // 1.5 s on frame 53 is dropped, walk dominating again from frame 53.
  EXPECT_EQ(steps, (std::vector<int>{25, 38, 46}));
  // Cloned mid-way, a machine continues identically.
  ScriptedMachine m2;
  for (int f = 0; f < 40; ++f) {
    ScriptedMachine::script(f, params);
    EventMask ev = 0;
    m2.sm->advance(kDt, params, ev);
  }
  auto copy = m2.sm->clone();
  for (int f = 40; f < 60; ++f) {
    ScriptedMachine::script(f, params);
    EventMask e1 = 0, e2 = 0;
    m2.sm->advance(kDt, params, e1);
    copy->advance(kDt, params, e2);
    ASSERT_EQ(e1, e2);
  }
  Pose p1, p2;
  m2.sm->evaluate(p1);
  copy->evaluate(p2);
  EXPECT_EQ(p1.local, p2.local);
}

TEST(StateMachine, CrossFadeBlendsTheTwoStatesBySlerp) {
  ScriptedMachine m;
  ParameterSet params;
  params.set("speed", 1.0f);
  EventMask ev = 0;
  m.sm->advance(kDt, params, ev);  // enters walk (time 0), idle at dt
  m.sm->advance(kDt, params, ev);  // idle at 2 dt, walk at dt, weight dt / 0.19
  ASSERT_EQ(m.sm->fading_from(), m.idle);
  const double w = kDt / 0.19;
  EXPECT_NEAR(m.sm->fade_weight(), w, 1e-6);
  Pose got, idle, walk;
  m.sm->evaluate(got);
  sample_clip(wiggle_clip(5, 40, kDt, "idle"), 2 * kDt, idle);
  sample_clip(wiggle_clip(5, 30, kDt, "walk"), kDt, walk);
  for (int j = 0; j < 5; ++j) {
    const glm::dquat want = sine_slerp(glm::dquat(idle.local[static_cast<std::size_t>(j)]),
                                       glm::dquat(walk.local[static_cast<std::size_t>(j)]), w);
    EXPECT_LT(rotation_between_deg(glm::dquat(got.local[static_cast<std::size_t>(j)]), want), 2e-3);
  }
}

TEST(StateMachine, BadDefinitionsNameTheirField) {
  StateMachine sm;
  sm.add_state("a", std::make_unique<ClipPlayer>(wiggle_clip(3, 4, kDt)));
  auto field = [](auto fn) {
    try {
      fn();
    } catch (const Error& e) {
      return e.location().field;
    }
    return std::string("no error");
  };
  EXPECT_EQ(field([&] { sm.add_state("a", std::make_unique<ClipPlayer>(wiggle_clip(3, 4, kDt))); }), "states[1].name");
  EXPECT_EQ(field([&] { sm.add_state("b", std::make_unique<ClipPlayer>(wiggle_clip(4, 4, kDt))); }),
            "states[1].controller");
  EXPECT_EQ(field([&] { sm.add_transition(0, 3, {}, 0.1f); }), "transitions[0].to");
  EXPECT_EQ(field([&] { sm.add_transition(0, 0, {}, 0.1f); }), "transitions[0].to");
  sm.add_state("b", std::make_unique<ClipPlayer>(wiggle_clip(3, 4, kDt)));
  EXPECT_EQ(field([&] { sm.add_transition(0, 1, {}, -1.0f); }), "transitions[0].fade");
  EXPECT_EQ(field([&] {
              sm.add_transition(0, 1, {{"x", Compare::Less, std::nanf("")}}, 0.1f);
            }),
            "transitions[0].when[0]");
}

TEST(Parameters, SetGetAndRejectNonFinite) {
  ParameterSet p;
  p.set("speed", 1.5f);
  p.set("speed", 2.0f);
  EXPECT_EQ(p.get("speed"), 2.0f);
  EXPECT_EQ(p.get("turn", -1.0f), -1.0f);
  EXPECT_EQ(p.values().size(), 1u);
  EXPECT_THROW(p.set("speed", INFINITY), Error);
  EventNames names;
  for (int i = 0; i < kMaxEventNames; ++i) names.intern(std::string(1, 'e').append(std::to_string(i)));
  EXPECT_EQ(names.intern("e3"), 3);
  EXPECT_THROW(names.intern("one_too_many"), Error);
}

}  // namespace
}  // namespace throng::anim
