#include "render/camera_path.h"

#include <gtest/gtest.h>

#include "core/error.h"

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
