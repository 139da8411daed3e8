#include "render/camera_path.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/ground.h"

namespace throng::render {
namespace {

TEST(CameraPath, OrbitIsTheCoreOrbit) {
  CameraPath p = framing_orbit(glm::vec3(3.0f, 0.0f, -2.0f), 20.0f, Camera{}, 30.0f);
  p.validate();
  for (double t : {0.0, 1.5, 17.0}) {
    const Camera a = p.at(t), b = orbit_camera(p.orbit, p.lens, static_cast<float>(t));
    EXPECT_EQ(a.position, b.position);
    EXPECT_EQ(a.target, b.target);
  }
  // The framed disc fits: its rim points project inside the viewport.
  const CameraView v = make_camera_view(p.at(4.0));
  for (int k = 0; k < 16; ++k) {
    const float a = 6.2831853f * static_cast<float>(k) / 16.0f;
    const glm::vec3 px = world_to_pixel(v, glm::vec3(3.0f + 20.0f * std::cos(a), 0.0f, -2.0f + 20.0f * std::sin(a)));
    EXPECT_GT(px.z, 0.0f);
    EXPECT_GE(px.x, 0.0f);
    EXPECT_LE(px.x, v.width);
    EXPECT_GE(px.y, 0.0f);
    EXPECT_LE(px.y, v.height);
  }
}

TEST(CameraPath, FlyoverPassesThroughItsKeysSmoothly) {
  const CameraPath p = framing_flyover(glm::vec3(0.0f), 10.0f, Camera{}, 8.0f);
  p.validate();
  for (const CameraKey& k : p.keys) {
    EXPECT_NEAR(glm::length(p.at(k.time).position - k.position), 0.0f, 1e-4f);
    EXPECT_NEAR(glm::length(p.at(k.time).target - k.target), 0.0f, 1e-4f);
  }
  EXPECT_EQ(p.at(-1.0).position, p.keys.front().position);  // held before and after
  EXPECT_EQ(p.at(100.0).position, p.keys.back().position);
  // C1 at an inner key: velocities just before and after agree.
  const float t = p.keys[1].time, h = 1e-3f;
  const glm::vec3 before = (p.at(t).position - p.at(t - h).position) / h;
  const glm::vec3 after = (p.at(t + h).position - p.at(t).position) / h;
  EXPECT_LT(glm::length(before - after), 0.05f * glm::length(before) + 1e-3f);
}

// A scenario's camera, given on the map (x, y, z up) as scenario files do.
Camera scenario_camera(glm::vec3 map_eye, glm::vec3 map_target) {
  Camera c;
  c.position = world_from_map(map_eye);
  c.target = world_from_map(map_target);
  return c;
}

TEST(CameraPath, AScenarioCameraSetInMotionStartsAsGiven) {
  const Camera given = scenario_camera({-20.0f, -30.0f, 25.0f}, {5.0f, 2.0f, 0.0f});
  for (CameraPath::Kind kind : {CameraPath::Kind::Fixed, CameraPath::Kind::Orbit, CameraPath::Kind::Flyover}) {
    const CameraPath p = animate_camera(given, kind, 20.0f);
    p.validate();
    const Camera c = p.at(0.0);
    EXPECT_LT(glm::length(c.position - given.position), 1e-4f) << to_string(kind);
    EXPECT_LT(glm::length(c.target - given.target), 1e-4f) << to_string(kind);
    EXPECT_EQ(c.width, given.width);
    EXPECT_EQ(c.fov_y, given.fov_y);
  }
  // Orbit: same height and distance from the target's ground point all the
  // way round; half a period later on the opposite side.
  const CameraPath orbit = animate_camera(given, CameraPath::Kind::Orbit, 20.0f);
  const glm::vec3 ground(given.target.x, 0.0f, given.target.z);
  const auto horizontal = [](glm::vec3 v) { return glm::length(glm::vec2(v.x, v.z)); };
  for (double t : {3.0, 10.0, 17.5}) {
    const Camera c = orbit.at(t);
    EXPECT_NEAR(c.position.y, given.position.y, 1e-4f);
    EXPECT_NEAR(horizontal(c.position - ground), horizontal(given.position - ground), 1e-3f);
    EXPECT_LT(glm::length(c.target - given.target), 1e-4f);
  }
  const glm::vec3 half = orbit.at(10.0).position - ground, start = given.position - ground;
  EXPECT_LT(glm::length(glm::vec2(half.x + start.x, half.z + start.z)), 1e-3f);
  // Fly-over: ends mirrored through the target, having passed over it.
  const CameraPath fly = animate_camera(given, CameraPath::Kind::Flyover, 20.0f);
  const glm::vec3 end = fly.at(20.0).position - ground;
  EXPECT_LT(glm::length(glm::vec2(end.x + start.x, end.z + start.z)), 1e-3f);
  EXPECT_GT(fly.at(10.0).position.y, given.position.y);
  // Straight down (north up): an orbit still works, barely tilted.
  Camera down = scenario_camera({0.0f, 0.0f, 50.0f}, {0.0f, 0.0f, 0.0f});
  down.up = world_from_map(glm::vec3(0.0f, 1.0f, 0.0f));
  const CameraPath top = animate_camera(down, CameraPath::Kind::Orbit, 30.0f);
  top.validate();
  top.at(7.0).validate();
  EXPECT_LT(glm::length(top.at(0.0).position - down.position), 1.5f);
  EXPECT_THROW(animate_camera(given, CameraPath::Kind::Orbit, 0.0f), Error);
}

TEST(CameraPath, InvalidPathsNameTheField) {
  CameraPath p = framing_flyover(glm::vec3(0.0f), 10.0f, Camera{}, 8.0f);
  p.keys[2].time = p.keys[1].time;
  try {
    p.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "camera.keys[2].time");
  }
  p.keys.resize(1);
  EXPECT_THROW(p.validate(), Error);
  CameraPath o = framing_orbit(glm::vec3(0.0f), 10.0f, Camera{});
  o.orbit.radius = -1.0f;
  EXPECT_THROW(o.validate(), Error);
  EXPECT_EQ(parse_camera_kind("flyover", "x"), CameraPath::Kind::Flyover);
  EXPECT_THROW(parse_camera_kind("dolly", "x"), Error);
}

}  // namespace
}  // namespace throng::render
