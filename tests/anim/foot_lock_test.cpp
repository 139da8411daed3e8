// Foot locking (anim/foot_lock.h) on characters driven as the simulation
// drives them: turning where they stand, stepping sideways, stopping and
// starting. The reference is the foot skating metric (motion/foot_skating.h)
// of the same motion without locking, and the skeleton's bone lengths.
#include "anim/foot_lock.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include "anim/crowd_animator.h"
#include "core/error.h"
#include "core/exec.h"
#include "tests/anim/crowd_fixture.h"

namespace throng::anim {
namespace {

using testing::kPi;
const motion::BlendSpace1D& space() { return testing::default_space(); }

constexpr float kFrame = 1.0f / 30.0f;

// Where the simulation puts one agent at time t (map: x, y; heading CCW from +x).
struct MapState {
  glm::vec2 position{0.0f};
  glm::vec2 velocity{0.0f};
  float heading = 0.0f;
};
using Motion = std::function<MapState(float t)>;

struct Drive {
  motion::FootSkatingReport skating;
  float largest_correction = 0.0f;  // m, over frames and legs
  int steps = 0;                    // steps of a foot's own started
  int most_stepping = 0;            // feet stepping in one frame, at most
  // The same metric blind to speed, with a strict height (a foot within
  // about 1 cm of the ground is in contact, however fast it moves): the
  // metric's contacts are slow by definition, so it cannot see a foot that
  // slides faster than 0.42 m/s. Counts a heel's last glide before it lands.
  motion::FootSkatingReport skating_low;
};

// One character driven through `motion` for `seconds`, its skating measured.
Drive drive(const Motion& motion, float seconds, bool lock, float frame = kFrame) {
  CrowdAnimatorConfig config;
  config.lod = false;
  config.foot_lock = lock;
  CrowdAnimator animator(space(), 1, config);
  const MapState s0 = motion(0.0f);
  const std::vector<glm::vec3> at{glm::vec3(s0.position.x, 0.0f, -s0.position.y)};
  animator.place(at, std::vector<float>{0.0f}, {}, std::vector<float>{0.0f});
  Buffer<glm::vec2> p(1, current_memory()), v(1, current_memory());
  Buffer<float> h(1, current_memory());
  Drive run;
  float last_step[2] = {0.0f, 0.0f};
  const int frames = static_cast<int>(std::lround(seconds / frame));
  for (int k = 0; k <= frames; ++k) {
    const MapState s = motion(static_cast<float>(k) * frame);
    p.copy_from(std::vector<glm::vec2>{s.position});
    v.copy_from(std::vector<glm::vec2>{s.velocity});
    h.copy_from(std::vector<float>{s.heading});
    animator.drive_from_map(p.span(), v.span(), h.span());
    animator.animate({k == 0 ? 0.0f : frame, nullptr, false});
    if (k == 0) animator.track({0});
    if (lock) {
      std::vector<FootLock> locks(2);
      copy_to_host(animator.foot_locks(), std::span<FootLock>(locks));
      for (const FootLock& l : locks)
        run.largest_correction = std::max(run.largest_correction, glm::length(l.correction));
      int stepping = 0;
      for (int leg = 0; leg < 2; ++leg) {
        if (locks[static_cast<std::size_t>(leg)].step_left > last_step[leg]) ++run.steps;
        last_step[leg] = locks[static_cast<std::size_t>(leg)].step_left;
        stepping += last_step[leg] > 0.0f ? 1 : 0;
      }
      run.most_stepping = std::max(run.most_stepping, stepping);
    }
  }
  run.skating = animator.foot_skating();
  motion::ContactOptions low;
  low.speed_fraction = 50.0;
  low.height_fraction = 0.012;
  run.skating_low = animator.foot_skating(low);
  return run;
}

// Contacts of a report classified as `regime` (motion::GaitRegime).
int contacts_of(const motion::FootSkatingReport& r, motion::GaitRegime regime) {
  int n = 0;
  for (const std::uint8_t k : r.regimes) n += k == static_cast<std::uint8_t>(regime) ? 1 : 0;
  return n;
}

// Prints and checks one motion with and without locking; returns both.
std::pair<Drive, Drive> expect_planted(const char* what, const Motion& motion, float seconds, float frame = kFrame) {
  const Drive free = drive(motion, seconds, false, frame);
  const Drive locked = drive(motion, seconds, true, frame);
  std::printf(
      "%-22s without locking: %s (max %.2f cm; whatever the speed %.2f cm); locked: %s (max %.2f cm; "
      "whatever the speed %.2f cm), largest correction %.1f cm\n",
      what, motion::describe(free.skating).c_str(), free.skating.max_cm, free.skating_low.max_cm,
      motion::describe(locked.skating).c_str(), locked.skating.max_cm, locked.skating_low.max_cm,
      100.0f * locked.largest_correction);
  EXPECT_TRUE(locked.skating.measured()) << what;
  EXPECT_LT(locked.skating.max_cm, 2.0) << what << ": every contact slides less than 2 cm";
  return {free, locked};
}

// Standing still, then turning by `angle` over a second, then standing.
Motion turn_on_the_spot(float angle) {
  return [angle](float t) {
    MapState s;
    s.heading = kPi / 2.0f + angle * std::clamp(t - 0.5f, 0.0f, 1.0f);
    return s;
  };
}

// Turning where it stands, a character steps: each foot at least once for
// a quarter turn, twice for a half turn, never both feet at once.
TEST(FootLock, TurningOnTheSpotKeepsTheFeetPlanted) {
  const auto quarter = expect_planted("turn 90 deg on the spot", turn_on_the_spot(kPi / 2.0f), 2.5f);
  const auto half = expect_planted("turn 180 deg on the spot", turn_on_the_spot(kPi), 2.5f);
  std::printf("steps: %d for a quarter turn, %d for a half turn\n", quarter.second.steps, half.second.steps);
  EXPECT_GE(quarter.second.steps, 2);
  EXPECT_GE(half.second.steps, 4);
  EXPECT_EQ(quarter.second.most_stepping, 1);
  EXPECT_EQ(half.second.most_stepping, 1);
  EXPECT_GE(contacts_of(half.second.skating, motion::GaitRegime::Turning), 1);
}

// A viewer paused in the middle of a step (frames with dt = 0) shows the
// stepping foot where it was, in the air.
TEST(FootLock, APausedFrameKeepsAStepInTheAir) {
  CrowdAnimatorConfig config;
  config.lod = false;
  CrowdAnimator animator(space(), 1, config);
  animator.place(std::vector<glm::vec3>{glm::vec3(0.0f)}, std::vector<float>{0.0f}, {}, std::vector<float>{0.0f});
  const Motion turn = turn_on_the_spot(kPi);
  Buffer<glm::vec2> p(1, current_memory()), v(1, current_memory());
  Buffer<float> h(1, current_memory());
  const motion::BlendSpaceView view = space().view();
  const auto ankles = [&] {
    std::vector<glm::vec3> joints(static_cast<std::size_t>(animator.joint_count()));
    copy_to_host(animator.joint_positions(), std::span<glm::vec3>(joints));
    std::vector<glm::vec3> out;
    for (int leg = 0; leg < 2; ++leg)
      out.push_back(joints[static_cast<std::size_t>(view.legs[leg].joints[view.legs[leg].count - 1])]);
    return out;
  };
  bool paused = false;
  for (int k = 0; k <= 75 && !paused; ++k) {
    const MapState s = turn(static_cast<float>(k) * kFrame);
    p.copy_from(std::vector<glm::vec2>{s.position});
    v.copy_from(std::vector<glm::vec2>{s.velocity});
    h.copy_from(std::vector<float>{s.heading});
    animator.drive_from_map(p.span(), v.span(), h.span());
    animator.animate({k == 0 ? 0.0f : kFrame, nullptr, false});
    std::vector<FootLock> locks(2);
    copy_to_host(animator.foot_locks(), std::span<FootLock>(locks));
    if (locks[0].step_left > 0.3f * config.foot_lock_config.step_s &&
        locks[0].step_left < 0.7f * config.foot_lock_config.step_s) {
      const std::vector<glm::vec3> before = ankles();
      animator.animate({0.0f, nullptr, false});
      const std::vector<glm::vec3> after = ankles();
      EXPECT_GT(before[0].y, 0.12f) << "the left foot is in the air mid-step";
      EXPECT_LT(glm::length(after[0] - before[0]), 1e-5f);
      EXPECT_LT(glm::length(after[1] - before[1]), 1e-5f);
      paused = true;
    }
  }
  EXPECT_TRUE(paused) << "no frame fell in the middle of a step";
}

TEST(FootLock, ASideStepKeepsTheFeetPlanted) {
  // Facing +y, 0.5 m to the right (+x) at 0.5 m/s, then standing.
  const auto [free, locked] = expect_planted(
      "side-step 0.5 m",
      [](float t) {
        MapState s;
        s.heading = kPi / 2.0f;
        const float moving = std::clamp(t - 0.5f, 0.0f, 1.0f);
        s.position = {0.5f * moving, 0.0f};
        s.velocity = {t > 0.5f && t < 1.5f ? 0.5f : 0.0f, 0.0f};
        return s;
      },
      2.5f);
  // Sideways at 0.5 m/s, too fast for the metric's contacts: measured blind
  // to speed, the feet slide half a metre without locking.
  EXPECT_GT(free.skating_low.max_cm, 20.0);
  EXPECT_LT(locked.skating_low.max_cm, 5.0);
  EXPECT_GE(contacts_of(locked.skating_low, motion::GaitRegime::SideStep), 1);
}

// Walking along +x at 1.3 m/s, braking to a stop over 0.6 s, standing 1.5 s,
// then starting again over 0.6 s: speed and the distance walked, closed form.
MapState stop_and_start(float t) {
  constexpr float v0 = 1.3f, t_stop = 2.0f, brake = 0.6f, rest = 1.5f;
  const float t_go = t_stop + brake + rest;
  const float d_stop = v0 * t_stop + 0.5f * v0 * brake;
  float speed = 0.0f, x = 0.0f;
  if (t < t_stop) {
    speed = v0;
    x = v0 * t;
  } else if (t < t_stop + brake) {
    const float u = t - t_stop;
    speed = v0 * (1.0f - u / brake);
    x = v0 * t_stop + v0 * u - 0.5f * v0 * u * u / brake;
  } else if (t < t_go) {
    x = d_stop;
  } else if (t < t_go + brake) {
    const float u = t - t_go;
    speed = v0 * u / brake;
    x = d_stop + 0.5f * v0 * u * u / brake;
  } else {
    speed = v0;
    x = d_stop + 0.5f * v0 * brake + v0 * (t - t_go - brake);
  }
  MapState s;
  s.position = {x, 0.0f};
  s.velocity = {speed, 0.0f};
  return s;
}

TEST(FootLock, StoppingAndStartingKeepTheFeetPlanted) {
  const auto [free, locked] = expect_planted("stop and start", stop_and_start, 7.0f);
  EXPECT_GE(contacts_of(locked.skating, motion::GaitRegime::StartStop), 1);
  EXPECT_GE(contacts_of(locked.skating, motion::GaitRegime::Standing), 1);
  EXPECT_GE(contacts_of(locked.skating, motion::GaitRegime::Straight), 1);
}

TEST(FootLock, AStraightWalkIsBarelyCorrected) {
  // Constant speed in a straight line: the clip's own motion, so the
  // correction stays within the clip's own slide, the most of it the heel's
  // glide from its first touch of the ground to the clip's touchdown.
  for (const float speed : {0.8f, 1.3f, 2.0f}) {
    const Drive run = drive(
        [speed](float t) {
          MapState s;
          s.position = {speed * t, 0.0f};
          s.velocity = {speed, 0.0f};
          return s;
        },
        4.0f, true);
    std::printf("straight walk at %.1f m/s: %s, largest correction %.2f cm\n", speed,
                motion::describe(run.skating).c_str(), 100.0f * run.largest_correction);
    EXPECT_LT(run.largest_correction, 0.05f) << speed << " m/s";
    // Every contact of a straight walk at a steady speed is classified so.
    for (int k = 0; k < motion::kGaitRegimes; ++k)
      std::printf("  %s %d", motion::to_string(static_cast<motion::GaitRegime>(k)),
                  contacts_of(run.skating, static_cast<motion::GaitRegime>(k)));
    std::printf("\n");
    EXPECT_EQ(contacts_of(run.skating, motion::GaitRegime::Straight), run.skating.contacts) << speed << " m/s";
  }
}

// Across a periodic seam the simulation moves an agent back by the period
// within one frame: its feet start again from no correction, instead of
// the lock pulling them a whole corridor back (to its cap, 30 cm) and
// stepping them over.
TEST(FootLock, AJumpAcrossAPeriodicSeamStartsTheFeetAgain) {
  const Drive run = drive(
      [](float t) {
        MapState s;
        s.position = {1.3f * t - (t >= 2.0f ? 20.0f : 0.0f), 0.0f};
        s.velocity = {1.3f, 0.0f};
        return s;
      },
      4.0f, true);
  EXPECT_LT(run.largest_correction, 0.05f);
  EXPECT_EQ(run.steps, 0);
}

// Creeping in a jam, as the collision-free speed model's agents do: 0.1 to
// 0.3 m/s, stop and go, the heading drifting 0.2 rad a step, at the
// simulation's 10 frames a second. The clips' cadence stays and their
// stride shrinks, so the swinging foot drags low over the ground; locked,
// low slow feet are held: p95 under 2 cm per contact (measured 1.51; 0.29
// cm mean). Without the hold the lock left p95 about 4 cm per contact in
// the circle's crowd.
MapState creep(float t) {
  MapState s;
  const float speed = 0.2f + 0.1f * std::sin(2.1f * t);
  s.heading = kPi / 2.0f + 0.6f * std::sin(0.9f * t);
  s.velocity = speed * glm::vec2(std::cos(s.heading), std::sin(s.heading));
  // (Position: the integral of the velocity, by small steps.)
  for (float u = 0.0f; u < t; u += 0.01f) {
    const float h = kPi / 2.0f + 0.6f * std::sin(0.9f * u);
    s.position += 0.01f * (0.2f + 0.1f * std::sin(2.1f * u)) * glm::vec2(std::cos(h), std::sin(h));
  }
  return s;
}

TEST(FootLock, CreepingInAJamHoldsTheLowFeet) {
  const Drive free = drive(creep, 12.0f, false, 0.1f), locked = drive(creep, 12.0f, true, 0.1f);
  std::printf("creeping: without locking %s; locked %s (max %.2f cm)\n", motion::describe(free.skating).c_str(),
              motion::describe(locked.skating).c_str(), locked.skating.max_cm);
  ASSERT_GE(locked.skating.contacts, 10);
  EXPECT_LT(locked.skating.p95_cm, 2.0);
  EXPECT_LT(locked.skating.mean_cm, 0.5);
}

// A crowd walking noisily (200 characters: several blocks of the kernel):
// every joint sits where its parent's world rotation puts its rest offset
// (bones keep their lengths, rotations agree with positions), and locking
// is the same on one thread and several.
TEST(FootLock, LegsKeepTheirBonesAndThreadsAgree) {
  const Index n = 200;
  const std::int32_t J = space().joint_count();
  struct Posed {
    std::vector<glm::vec3> p;
    std::vector<glm::quat> q;
    std::vector<float> scales;
  };
  auto run = [&](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    CrowdAnimatorConfig config;
    config.lod = false;
    CrowdAnimator animator(space(), n, config);
    const testing::Crowd crowd = testing::random_crowd(n, 5, 20.0f);
    animator.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
    std::mt19937 rng(9);
    std::normal_distribution<float> noise(0.0f, 0.6f);
    std::vector<glm::vec2> p(static_cast<std::size_t>(n)), v(p.size());
    std::vector<float> h(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = {crowd.positions[i].x, -crowd.positions[i].z};
    Buffer<glm::vec2> bp(n, current_memory()), bv(n, current_memory());
    Buffer<float> bh(n, current_memory());
    for (int k = 0; k < 120; ++k) {
      for (std::size_t i = 0; i < p.size(); ++i) {
        v[i] = {1.0f + noise(rng), noise(rng)};
        h[i] += 0.2f * noise(rng);
        p[i] += kFrame * v[i];
      }
      bp.copy_from(p);
      bv.copy_from(v);
      bh.copy_from(h);
      animator.drive_from_map(bp.span(), bv.span(), bh.span());
      animator.animate({kFrame, nullptr, false});
    }
    Posed out{std::vector<glm::vec3>(static_cast<std::size_t>(n * J)),
              std::vector<glm::quat>(static_cast<std::size_t>(n * J)), std::vector<float>(static_cast<std::size_t>(n))};
    copy_to_host(animator.joint_positions(), std::span<glm::vec3>(out.p));
    copy_to_host(animator.joint_rotations(), std::span<glm::quat>(out.q));
    copy_to_host(animator.scales(), std::span<float>(out.scales));
    return out;
  };
  const Posed one = run(1);
  const Posed two = run(2);
  ASSERT_EQ(one.p.size(), two.p.size());
  EXPECT_EQ(0, std::memcmp(one.p.data(), two.p.data(), one.p.size() * sizeof(glm::vec3)));
  EXPECT_EQ(0, std::memcmp(one.q.data(), two.q.data(), one.q.size() * sizeof(glm::quat)));
  const motion::Skeleton& skeleton = space().skeleton();
  double worst = 0.0;
  for (Index c = 0; c < n; ++c)
    for (std::int32_t j = 1; j < J; ++j) {
      const auto at = [&](std::int32_t k) { return static_cast<std::size_t>(c * J + k); };
      const std::int32_t parent = skeleton.parents[static_cast<std::size_t>(j)];
      const glm::vec3 expected =
          one.p[at(parent)] +
          one.q[at(parent)] * (one.scales[static_cast<std::size_t>(c)] * skeleton.offsets[static_cast<std::size_t>(j)]);
      worst = std::max(worst, static_cast<double>(glm::length(one.p[at(j)] - expected)));
    }
  std::printf("largest joint off its parent's bone: %.2e m\n", worst);
  EXPECT_LT(worst, 1e-5);
}

// A walk round a circle as `throng run` animates it: simulation steps of
// 0.1 s, frames between them (agents interpolated, at their displacement
// over the step), the frame rate not a multiple of the step's. The metric
// sampled this coarsely sees the foot's last glide before touchdown.
TEST(FootLock, AWalkRoundACircleBetweenSimulationSteps) {
  const auto on_circle = [](float t) {  // radius 5 m at 1.2 m/s, anticlockwise
    const float rate = 1.2f / 5.0f;
    MapState s;
    s.position = {5.0f * std::cos(rate * t), 5.0f * std::sin(rate * t)};
    s.heading = rate * t + kPi / 2.0f;
    return s;
  };
  const auto between_steps = [&](float t) {
    const float step = 0.1f;
    const float k = std::floor(t / step);
    const float alpha = t / step - k;
    const MapState a = on_circle(k * step), b = on_circle((k + 1.0f) * step);
    MapState s;
    s.position = a.position + alpha * (b.position - a.position);
    s.velocity = (b.position - a.position) / step;
    s.heading = a.heading + alpha * (b.heading - a.heading);
    return s;
  };
  // 10.08 frames a second: the demo's, a 50x time-lapse at 24 fps.
  const auto [free, locked] = expect_planted("circle between steps", between_steps, 10.0f, 2.0833f / 21.0f);
  EXPECT_LT(locked.skating.mean_cm, 0.5 * free.skating.mean_cm);
}

// PoseJob locks each character's feet right after its pose; the stage on
// its own is FootLockJob over the posed crowd. On a crowd under LOD (masks
// that turn legs off and on) with speeds and turns redrawn every second,
// frame after frame: the same joints, draw matrices and leg state, bit for bit.
TEST(FootLock, LockedInThePoseAsFootLockJobAfterIt) {
  const Index n = 300;
  const testing::Crowd crowd = testing::random_crowd(n, 21);
  const Camera cam = testing::crowd_camera();
  CrowdAnimatorConfig config;
  config.draw_matrices = true;
  config.cache = false;
  CrowdAnimator animator(space(), n, config);  // feet locked in its PoseJob
  animator.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
  const Index J = animator.joint_count();
  const motion::BlendSpaceTables tables(space(), current_memory());
  const std::vector<glm::mat4x3> shapes = joint_shapes(space().skeleton());
  Buffer<glm::vec3> p(n * J, current_memory());
  Buffer<glm::quat> q(n * J, current_memory());
  Buffer<FootLock> locks = Buffer<FootLock>::zeros(2 * n, current_memory());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> speeds(static_cast<std::size_t>(n)), turns(static_cast<std::size_t>(n));
  int stepping = 0;
  for (int frame = 0; frame < 120; ++frame) {
    if (frame % 30 == 0) {
      for (std::size_t i = 0; i < speeds.size(); ++i) {
        speeds[i] = frame == 60 && i % 3 == 0 ? 0.0f : 1.0f + u(rng);  // some stop, the rest walk
        turns[i] = 1.5f * u(rng);
      }
      animator.set_speeds(speeds);
      animator.set_turn_rates(turns);
    }
    animator.animate({kFrame, &cam, true});
    // The reference: the same gait posed, then its feet locked on their own.
    PoseJob pose = make_pose_job(
        tables.view(),
        {animator.positions(), animator.yaws(), animator.scales(), animator.phases(), animator.blend_speeds()},
        p.span(), q.span());
    pose.joint_masks = animator.joint_masks();
    pose.run();
    const FootLockJob lock{.blend = tables.view(),
                           .config = {},
                           .dt = kFrame,
                           .positions = animator.positions(),
                           .scales = animator.scales(),
                           .phases = animator.phases(),
                           .blend_speeds = animator.blend_speeds(),
                           .joint_masks = animator.joint_masks(),
                           .locks = locks.span(),
                           .joint_positions = p.span(),
                           .joint_rotations = q.span()};
    lock.run();
    const std::vector<glm::vec3> want_p = p.to_vector(),
                                 got_p(animator.joint_positions().begin(), animator.joint_positions().end());
    const std::vector<glm::quat> want_q = q.to_vector(),
                                 got_q(animator.joint_rotations().begin(), animator.joint_rotations().end());
    ASSERT_EQ(std::memcmp(want_p.data(), got_p.data(), want_p.size() * sizeof(glm::vec3)), 0) << frame;
    ASSERT_EQ(std::memcmp(want_q.data(), got_q.data(), want_q.size() * sizeof(glm::quat)), 0) << frame;
    const std::vector<FootLock> want_l = locks.to_vector(),
                                got_l(animator.foot_locks().begin(), animator.foot_locks().end());
    for (std::size_t i = 0; i < want_l.size(); ++i) {
      ASSERT_EQ(std::memcmp(&want_l[i].correction, &got_l[i].correction, sizeof(glm::vec2)), 0) << frame << " " << i;
      ASSERT_EQ(want_l[i].step_left, got_l[i].step_left) << frame << " " << i;
      ASSERT_EQ(want_l[i].seen, got_l[i].seen) << frame << " " << i;
      ASSERT_EQ(want_l[i].down, got_l[i].down) << frame << " " << i;
      stepping += want_l[i].step_left > 0.0f ? 1 : 0;
    }
    const std::vector<glm::mat4x3> draw(animator.draw_matrices().begin(), animator.draw_matrices().end());
    for (Index c = 0; c < n; c += 37) {
      std::vector<glm::mat4x3> want(static_cast<std::size_t>(J));
      character_draw_matrices(static_cast<std::int32_t>(J), want_p.data() + c * J, want_q.data() + c * J,
                              crowd.scales[static_cast<std::size_t>(c)], shapes.data(), want.data());
      ASSERT_EQ(std::memcmp(want.data(), draw.data() + c * J, want.size() * sizeof(glm::mat4x3)), 0) << frame;
    }
  }
  EXPECT_GT(stepping, 0);  // turning feet took steps of their own
}

TEST(FootLock, BadSettingsAreNamed) {
  auto message = [](FootLockConfig c) {
    try {
      c.validate();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  FootLockConfig c;
  c.max_correction_m = std::nanf("");
  EXPECT_NE(message(c).find("foot_lock.max_correction_m"), std::string::npos);
  c = {};
  c.release_s = 0.0f;
  EXPECT_NE(message(c).find("foot_lock.release_s"), std::string::npos);
  c = {};
  c.step_threshold_m = -1.0f;
  EXPECT_NE(message(c).find("foot_lock.step_threshold_m"), std::string::npos);
  c = {};
  c.step_s = INFINITY;
  EXPECT_NE(message(c).find("foot_lock.step_s"), std::string::npos);
  FootLockJob job;
  job.blend = space().view();
  job.dt = kFrame;
  EXPECT_NO_THROW(job.validate());
  Buffer<glm::vec3> one(1, current_memory());
  job.positions = one.span();
  try {
    job.validate();
    ADD_FAILURE() << "a job with one character and no phases was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("phases"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace throng::anim
