#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "anim/locomotion_streams.h"
#include "anim/controller.h"
#include "anim/crowd_animator.h"
#include "anim/rig.h"
#include "anim/skin.h"
#include "anim/stream_crowd.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "core/error.h"
#include "io/crowd_gltf.h"
#include "motion/default_set.h"
#include "motion/locomotion.h"
#include "render/framebuffer.h"
#include "render/headless.h"
#include "render/image.h"
#include "tests/render/scene_fixture.h"

namespace throng::render {
namespace {

using testing::TPoseCrowd;

// Three characters in view with levels 0, 1, 2 and one behind the camera.
TPoseCrowd test_crowd() {
  TPoseCrowd c;
  c.add({-4.0f, 0.0f, 0.0f}, 0.0f, 0);
  c.add({0.0f, 0.0f, 0.0f}, 0.5f, 1);
  c.add({4.0f, 0.0f, 0.0f}, -0.5f, 2);
  c.add({0.0f, 0.0f, 30.0f}, 0.0f, 0);
  return c;
}

class RendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = std::make_unique<HeadlessContext>(); }
  static void TearDownTestSuite() { context_.reset(); }
  static std::unique_ptr<HeadlessContext> context_;

  static Camera camera(std::int32_t w = 320, std::int32_t h = 180) {
    Camera c;
    c.width = w;
    c.height = h;
    c.position = {0.0f, 6.0f, 14.0f};
    c.target = {0.0f, 0.9f, 0.0f};
    return c;
  }
  static TPoseCrowd crowd() { return test_crowd(); }
  static Image draw(Renderer& r, const Camera& cam, const CharacterPoses& poses, const RenderOptions& o = {},
                    RenderStats* stats = nullptr, std::int32_t samples = 4) {
    OffscreenTarget target(cam.width, cam.height, samples);
    target.bind();
    const RenderStats s = r.render(cam, poses, o);
    if (stats != nullptr) *stats = s;
    return target.read();
  }
};
std::unique_ptr<HeadlessContext> RendererTest::context_;

TEST_F(RendererTest, ContextIsOpenGl43OrLater) {
  EXPECT_NE(context_->description().find("EGL"), std::string::npos);
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  EXPECT_GE(major * 10 + minor, 43) << context_->description();
}

TEST_F(RendererTest, AgentsShowWhereTheyStandAndNowhereElse) {
  TPoseCrowd c = crowd();
  Renderer r(make_joint_rig(c.skeleton));
  const Camera cam = camera();
  RenderStats stats;
  RenderOptions by_level;
  by_level.lod_colours = true;
  const Image with = draw(r, cam, c.poses(), by_level, &stats);
  TPoseCrowd none;
  const Image without = draw(r, cam, none.poses(), by_level);
  EXPECT_EQ(stats.characters, 4);
  EXPECT_EQ(stats.visible, 3);  // the one behind the camera is culled
  EXPECT_EQ(stats.instances, 3 * r.rig().bone_count());

  // Each visible character's chest is drawn in its level's colour.
  const CameraView view = make_camera_view(cam);
  const std::int32_t J = c.skeleton.joint_count();
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 chest = c.positions[static_cast<std::size_t>(k * J + motion::default_joint::Spine1)];
    const glm::vec3 px = world_to_pixel(view, chest);
    const auto x = static_cast<std::int32_t>(px.x), y = static_cast<std::int32_t>(px.y);
    ASSERT_TRUE(x >= 0 && x < cam.width && y >= 0 && y < cam.height);
    const std::uint8_t* bg = without.pixel(x, y);
    EXPECT_GT(colour_distance(with, x, y, bg), 40) << "character " << k << " at pixel " << x << "," << y;
    // Closest palette colour (after shading) is its level's: compare hues by
    // the dominant channel ordering.
    const std::uint8_t* p = with.pixel(x, y);
    const glm::vec3 expect = lod_level_colour(k);
    const auto order = [](float red, float green, float blue) {
      return (red > green) * 4 + (green > blue) * 2 + (red > blue);
    };
    EXPECT_EQ(order(p[0], p[1], p[2]), order(expect.r, expect.g, expect.b)) << "level " << k;
  }

  // Away from every character's projected box, the picture is the empty scene.
  std::vector<std::array<float, 4>> boxes;
  for (int k = 0; k < 3; ++k) {
    std::array<float, 4> b = {1e9f, 1e9f, -1e9f, -1e9f};
    for (std::int32_t j = 0; j < J; ++j) {
      const glm::vec3 px = world_to_pixel(view, c.positions[static_cast<std::size_t>(k * J + j)]);
      b = {std::min(b[0], px.x), std::min(b[1], px.y), std::max(b[2], px.x), std::max(b[3], px.y)};
    }
    boxes.push_back(b);
  }
  const float margin = 12.0f;  // end sites and bone thickness, in pixels
  std::int64_t checked = 0, differing = 0;
  for (std::int32_t y = 0; y < cam.height; ++y)
    for (std::int32_t x = 0; x < cam.width; ++x) {
      bool near = false;
      for (const auto& b : boxes)
        near = near || (x > b[0] - margin && x < b[2] + margin && y > b[1] - margin && y < b[3] + margin);
      if (near) continue;
      ++checked;
      if (colour_distance(with, x, y, without.pixel(x, y)) > 2) ++differing;
    }
  EXPECT_GT(checked, cam.width * cam.height / 2);
  EXPECT_EQ(differing, 0);
}

TEST_F(RendererTest, CullingCanBeTurnedOff) {
  TPoseCrowd c = crowd();
  Renderer r(make_joint_rig(c.skeleton));
  RenderOptions o;
  o.cull = false;
  RenderStats stats;
  draw(r, camera(), c.poses(), o, &stats);
  EXPECT_EQ(stats.visible, 4);
}

// Each draw tier (fine, coarse, lines) draws every character, in both modes.
TEST_F(RendererTest, EveryTierDrawsTheCharacters) {
  TPoseCrowd c = crowd();
  Renderer r(make_crowd_rigs(c.skeleton));
  TPoseCrowd none;
  for (RenderMode mode : {RenderMode::Joints, RenderMode::Skinned}) {
    RenderOptions look;
    look.mode = mode;
    const Image empty = draw(r, camera(), none.poses(), look);
    for (int tier = 0; tier < 3; ++tier) {
      RenderOptions o = look;
      o.fine_min_pixels = tier == 0 ? 0.0f : 1e6f;   // all fine, or none
      o.lines_max_pixels = tier == 2 ? 1e6f : 0.0f;  // all lines, or none
      RenderStats stats;
      const Image im = draw(r, camera(), c.poses(), o, &stats);
      EXPECT_EQ(stats.visible, 3);
      EXPECT_EQ(stats.fine, tier == 0 ? 3 : 0);
      EXPECT_EQ(stats.lines, tier == 2 ? 3 : 0);
      const ImageDifference d = compare_images(im, empty, 20);
      // Three people of about a hundred pixels each at this distance; lines fewer.
      EXPECT_GT(d.fraction_differing * im.width * im.height, tier == 2 ? 30.0 : 150.0)
          << to_string(mode) << " tier " << tier;
    }
  }
}

TEST_F(RendererTest, ObstacleTopsFollowTheEvenOddRule) {
  TPoseCrowd none;
  Renderer r(make_joint_rig(none.skeleton));
  Camera cam = camera();
  cam.position = {0.0f, 25.0f, 8.0f};
  cam.target = {0.0f, 0.0f, -2.0f};
  const Image empty = draw(r, cam, none.poses());
  // A 10 m square with a 6 m square hole, on the map around (0, 2).
  std::vector<sim::Polygon> polygons(1);
  polygons[0].outer = {{-5.0f, -3.0f}, {5.0f, -3.0f}, {5.0f, 7.0f}, {-5.0f, 7.0f}};
  polygons[0].holes = {{{-3.0f, -1.0f}, {3.0f, -1.0f}, {3.0f, 5.0f}, {-3.0f, 5.0f}}};
  std::vector<sim::Circle> circles = {{{7.0f, 2.0f}, 1.0f}};
  ObstacleStyle style;
  style.height = 1.0f;
  r.set_obstacles(polygons, circles, style);
  const Image with = draw(r, cam, none.poses());
  const CameraView view = make_camera_view(cam);
  const auto differs = [&](glm::vec2 map, float height) {
    const glm::vec3 px = world_to_pixel(view, world_from_ground(map, height));
    return colour_distance(with, static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y),
                           empty.pixel(static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y))) > 20;
  };
  EXPECT_TRUE(differs({-4.0f, 2.0f}, 1.0f));  // solid rim, top
  EXPECT_TRUE(differs({4.0f, 2.0f}, 1.0f));
  EXPECT_TRUE(differs({7.0f, 2.0f}, 1.0f));    // the disc's top
  EXPECT_FALSE(differs({0.0f, 2.0f}, 0.0f));   // the ground seen through the hole
  EXPECT_FALSE(differs({-8.0f, 2.0f}, 0.0f));  // outside
  RenderOptions hidden;
  hidden.obstacles = false;
  EXPECT_EQ(compare_images(draw(r, cam, none.poses(), hidden), empty).max_abs, 0);
}

TEST_F(RendererTest, BinsOverlayTintsOccupiedCells) {
  TPoseCrowd none;
  Renderer r(make_joint_rig(none.skeleton));
  const Camera cam = camera();
  std::vector<std::int32_t> counts = {0, 5, 0, 0};  // 2 x 2 cells of 4 m from map (-4, -4)
  BinsOverlay bins;
  bins.min = {-4.0f, -4.0f};
  bins.cell_size = 4.0f;
  bins.columns = 2;
  bins.rows = 2;
  bins.counts = counts;
  r.set_bins(bins);
  RenderOptions on;
  on.bins = true;
  const Image with = draw(r, cam, none.poses(), on);
  const Image without = draw(r, cam, none.poses());
  const CameraView view = make_camera_view(cam);
  const auto diff_at = [&](glm::vec2 map) {
    const glm::vec3 px = world_to_pixel(view, world_from_ground(map));
    return colour_distance(with, static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y),
                           without.pixel(static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y)));
  };
  EXPECT_GT(diff_at({2.0f, -2.0f}), 20);  // cell (1, 0) holds 5
  EXPECT_LE(diff_at({-2.0f, -2.5f}), 2);  // empty cell: only its border is drawn
  EXPECT_LE(diff_at({12.0f, 0.0f}), 2);   // outside the grid
  bins.counts = Span<const std::int32_t>(counts.data(), 3);
  EXPECT_THROW(r.set_bins(bins), Error);
}

TEST_F(RendererTest, BadInputIsAnError) {
  TPoseCrowd c = crowd();
  Renderer r(make_joint_rig(c.skeleton));
  CharacterPoses poses = c.poses();
  poses.joint_rotations = poses.joint_rotations.subspan(0, poses.joint_rotations.size() - 1);
  try {
    draw(r, camera(), poses);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "poses.joint_rotations");
  }
  RenderOptions skinned;
  skinned.mode = RenderMode::Skinned;
  EXPECT_THROW(draw(r, camera(), c.poses(), skinned), Error);
  RenderOptions bad;
  bad.fine_min_pixels = -1.0f;
  EXPECT_THROW(draw(r, camera(), c.poses(), bad), Error);
  Camera cam = camera();
  cam.fov_y = 0.0f;
  EXPECT_THROW(draw(r, cam, c.poses()), Error);
}

// Skinned mode: where the CPU reference skin (anim::skin_reference) puts
// the mannequin's vertices, pixels change, in the LOD level's colour; the
// rest of the picture is the empty scene.
TEST_F(RendererTest, SkinnedAgentsShowWhereTheyStandAndNowhereElse) {
  TPoseCrowd c = crowd();
  const anim::Rig rig = anim::make_rig("humanoid", c.skeleton);
  Renderer r(make_crowd_rigs(c.skeleton));
  RenderOptions skinned;
  skinned.mode = RenderMode::Skinned;
  skinned.lod_colours = true;
  skinned.fine_min_pixels = 0.0f;  // the rig's own mesh for all, as the CPU reference skins it
  const Camera cam = camera();
  RenderStats stats;
  const Image with = draw(r, cam, c.poses(), skinned, &stats);
  TPoseCrowd none;
  const Image without = draw(r, cam, none.poses(), skinned);
  EXPECT_EQ(stats.characters, 4);
  EXPECT_EQ(stats.visible, 3);
  EXPECT_EQ(stats.fine, 3);
  EXPECT_EQ(stats.instances, 3);
  EXPECT_EQ(stats.triangles, 3 * rig.mesh.triangle_count());

  const CameraView view = make_camera_view(cam);
  const std::int32_t J = c.skeleton.joint_count();
  std::vector<std::array<float, 4>> boxes;
  for (int k = 0; k < 3; ++k) {
    // The chest, in its level's colour.
    const glm::vec3 chest = c.positions[static_cast<std::size_t>(k * J + motion::default_joint::Spine1)];
    const glm::vec3 px = world_to_pixel(view, chest);
    const auto x = static_cast<std::int32_t>(px.x), y = static_cast<std::int32_t>(px.y);
    EXPECT_GT(colour_distance(with, x, y, without.pixel(x, y)), 40) << "character " << k;
    const std::uint8_t* p = with.pixel(x, y);
    const glm::vec3 expect = lod_level_colour(k);
    const auto order = [](float red, float green, float blue) {
      return (red > green) * 4 + (green > blue) * 2 + (red > blue);
    };
    EXPECT_EQ(order(p[0], p[1], p[2]), order(expect.r, expect.g, expect.b)) << "level " << k;
    // Its skinned vertices' box (palette T(at) R(yaw)).
    anim::Mat3x4 m = anim::mat3x4_from(glm::angleAxis(c.yaws[static_cast<std::size_t>(k)], glm::vec3(0, 1, 0)),
                                       c.places[static_cast<std::size_t>(k)]);
    const std::vector<anim::Mat3x4> palette(static_cast<std::size_t>(J), m);
    std::vector<glm::vec3> skinned_vertices(static_cast<std::size_t>(rig.mesh.vertex_count()));
    anim::skin_reference(rig.mesh, palette, skinned_vertices, {});
    std::array<float, 4> b = {1e9f, 1e9f, -1e9f, -1e9f};
    for (const glm::vec3& v : skinned_vertices) {
      const glm::vec3 q = world_to_pixel(view, v);
      b = {std::min(b[0], q.x), std::min(b[1], q.y), std::max(b[2], q.x), std::max(b[3], q.y)};
    }
    boxes.push_back(b);
  }
  const float margin = 2.0f;  // antialiased edges
  std::int64_t checked = 0, differing = 0;
  for (std::int32_t y = 0; y < cam.height; ++y)
    for (std::int32_t x = 0; x < cam.width; ++x) {
      bool near = false;
      for (const auto& b : boxes)
        near = near || (x > b[0] - margin && x < b[2] + margin && y > b[1] - margin && y < b[3] + margin);
      if (near) continue;
      ++checked;
      if (colour_distance(with, x, y, without.pixel(x, y)) > 2) ++differing;
    }
  EXPECT_GT(checked, cam.width * cam.height / 2);
  EXPECT_EQ(differing, 0);
  // Inside the boxes, the characters cover a good share.
  std::int64_t covered = 0;
  for (const auto& b : boxes)
    for (auto y = static_cast<std::int32_t>(b[1]); y <= static_cast<std::int32_t>(b[3]); ++y)
      for (auto x = static_cast<std::int32_t>(b[0]); x <= static_cast<std::int32_t>(b[2]); ++x)
        covered += colour_distance(with, x, y, without.pixel(x, y)) > 20 ? 1 : 0;
  EXPECT_GT(covered, 200);
}

TEST_F(RendererTest, SkinnedPartsTakeTheirOwnLevelsAndClothesOtherwise) {
  TPoseCrowd c;
  c.add({0.0f, 0.0f, 0.0f});
  std::vector<std::uint8_t> levels = {1, 2, 3, 4, 0};  // left arm, right arm, torso, left leg, right leg
  CharacterPoses poses = c.poses();
  poses.lod_levels = levels;
  Renderer r(make_crowd_rigs(c.skeleton));
  RenderOptions skinned;
  skinned.mode = RenderMode::Skinned;
  skinned.lod_colours = true;
  Camera cam = camera();
  cam.position = {0.0f, 1.3f, 4.0f};
  cam.target = {0.0f, 1.0f, 0.0f};
  const Image im = draw(r, cam, poses, skinned);
  const CameraView view = make_camera_view(cam);
  const auto colour_at = [&](std::int32_t joint_a, std::int32_t joint_b) {
    const glm::vec3 mid =
        0.5f * (c.positions[static_cast<std::size_t>(joint_a)] + c.positions[static_cast<std::size_t>(joint_b)]);
    const glm::vec3 px = world_to_pixel(view, mid);
    const std::uint8_t* p = im.pixel(static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y));
    return glm::vec3(p[0], p[1], p[2]) / 255.0f;
  };
  // The shaded colour is the level's colour times a light factor: compare directions.
  const auto closest_level = [](glm::vec3 got) {
    int best = -1;
    float best_cos = -1.0f;
    for (int l = 0; l < 5; ++l) {
      const float cosine = glm::dot(glm::normalize(got), glm::normalize(lod_level_colour(l)));
      if (cosine > best_cos) best_cos = cosine, best = l;
    }
    return best;
  };
  namespace dj = motion::default_joint;
  EXPECT_EQ(closest_level(colour_at(dj::LeftArm, dj::LeftForeArm)), 1);
  EXPECT_EQ(closest_level(colour_at(dj::RightArm, dj::RightForeArm)), 2);
  EXPECT_EQ(closest_level(colour_at(dj::Spine, dj::Spine1)), 3);
  EXPECT_EQ(closest_level(colour_at(dj::LeftUpLeg, dj::LeftLeg)), 4);
  EXPECT_EQ(closest_level(colour_at(dj::RightUpLeg, dj::RightLeg)), 0);
  // Clothes: shirt, trousers and skin differ.
  skinned.lod_colours = false;
  const Image dressed = draw(r, cam, poses, skinned);
  const auto pixel_at = [&](std::int32_t joint_a, std::int32_t joint_b, float t) {
    const glm::vec3 at =
        glm::mix(c.positions[static_cast<std::size_t>(joint_a)], c.positions[static_cast<std::size_t>(joint_b)], t);
    const glm::vec3 px = world_to_pixel(view, at);
    return dressed.pixel(static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y));
  };
  const std::uint8_t* chest = pixel_at(dj::Spine, dj::Spine1, 0.5f);
  const auto x = [&](std::int32_t a, std::int32_t b, float t) {
    const glm::vec3 px = world_to_pixel(
        view, glm::mix(c.positions[static_cast<std::size_t>(a)], c.positions[static_cast<std::size_t>(b)], t));
    return std::array<std::int32_t, 2>{static_cast<std::int32_t>(px.x), static_cast<std::int32_t>(px.y)};
  };
  const auto thigh = x(dj::LeftUpLeg, dj::LeftLeg, 0.5f);
  const auto head = x(dj::Neck, dj::Head, 1.0f);
  EXPECT_GT(colour_distance(dressed, thigh[0], thigh[1], chest), 30);
  EXPECT_GT(colour_distance(dressed, head[0], head[1], chest), 30);
}

// The vertex shader's skinning, read back by transform feedback, against the
// CPU reference (anim::SkinJob): characters posed by the locomotion stage
// (palettes made from world joint frames) and by animation streams (palettes
// given).
TEST_F(RendererTest, GpuSkinningMatchesTheCpuReference) {
  const motion::BlendSpace1D space = motion::make_default_blend_space();
  const Index n = 6;
  anim::CrowdAnimator crowd(space, n);
  std::vector<glm::vec3> at;
  std::vector<float> yaws, scales, speeds;
  for (Index i = 0; i < n; ++i) {
    at.emplace_back(3.0f * static_cast<float>(i), 0.0f, -2.0f * static_cast<float>(i));
    yaws.push_back(0.7f * static_cast<float>(i));
    scales.push_back(0.85f + 0.06f * static_cast<float>(i));
    speeds.push_back(0.4f * static_cast<float>(i));
  }
  crowd.place(at, yaws, scales);
  crowd.set_speeds(speeds);
  for (int f = 0; f < 10; ++f) crowd.animate({1.0f / 30.0f, nullptr, true});
  const anim::Rig rig = anim::make_rig("humanoid", space.skeleton());
  Renderer r(make_crowd_rigs(space.skeleton()));
  const std::int32_t J = rig.joint_count();
  const auto compare = [&](const SkinCapture& got, const std::vector<anim::Mat3x4>& palettes,
                           const anim::SkinnedMesh& mesh, Index characters) {
    ASSERT_EQ(got.vertices, mesh.vertex_count());
    ASSERT_EQ(got.positions.size(), static_cast<std::size_t>(characters * mesh.vertex_count()));
    std::vector<Index> offsets;
    for (Index c = 0; c < characters; ++c) offsets.push_back(c * J);
    std::vector<glm::vec3> want_p(got.positions.size()), want_n(got.positions.size());
    anim::SkinJob job;
    job.positions = mesh.positions;
    job.normals = mesh.normals;
    job.joints = mesh.joints;
    job.weights = mesh.weights;
    job.joint_count = J;
    job.palettes = palettes;
    job.palette_offsets = offsets;
    job.out_positions = want_p;
    job.out_normals = want_n;
    job.run();
    float worst_p = 0.0f, worst_n = 0.0f;
    for (std::size_t i = 0; i < want_p.size(); ++i) {
      worst_p = std::max(worst_p, glm::length(got.positions[i] - want_p[i]));
      worst_n = std::max(worst_n, glm::length(got.normals[i] - want_n[i]));
    }
    EXPECT_LT(worst_p, 1e-4f);  // metres, characters up to 20 m from the origin
    EXPECT_LT(worst_n, 1e-4f);
  };
  // Palettes from the joint frames: T(p) R(q) S(s) * inverse bind, computed here.
  const std::vector<glm::vec3> p(crowd.joint_positions().begin(),
                                 crowd.joint_positions().end());  // host memory in tests
  const std::vector<glm::quat> q(crowd.joint_rotations().begin(), crowd.joint_rotations().end());
  std::vector<anim::Mat3x4> palettes;
  for (Index c = 0; c < n; ++c)
    for (std::int32_t j = 0; j < J; ++j) {
      const std::size_t k = static_cast<std::size_t>(c * J + j);
      anim::Mat3x4 world = anim::mat3x4_from(q[k], p[k]);
      for (glm::vec4* row : {&world.r0, &world.r1, &world.r2})
        *row = glm::vec4(glm::vec3(*row) * scales[static_cast<std::size_t>(c)], row->w);
      palettes.push_back(world * rig.inverse_bind[static_cast<std::size_t>(j)]);
    }
  const CharacterPoses frames = poses_of(crowd);
  compare(r.capture_skinned(frames, DrawTier::Fine), palettes, rig.mesh, n);
  compare(r.capture_skinned(frames, DrawTier::Coarse), palettes, r.rigs().skins[0].meshes[1], n);
  compare(r.capture_skinned(frames, DrawTier::Lines), palettes, r.rigs().skins[0].meshes[2], n);

  // Palettes given: a stream crowd walking at offsets, resolved in world space.
  anim::StreamCrowd streams;
  const std::int32_t human = streams.add_rig(rig);
  const std::vector<motion::DefaultMotion> motions = motion::make_default_motions(space.skeleton());
  anim::AnimClip walk{"walk", std::make_shared<motion::Clip>(motions[1].clip), true, {}};
  const std::int32_t stream = streams.streams().add(streams.rig(human), human, {.name = "walk", .history = 16},
                                                    std::make_unique<anim::ClipPlayer>(walk));
  const Index agents = 5;
  streams.add_agents(human, agents);
  streams.assign_random(0, agents, {{{stream}, {stream}, {stream}}, true}, 3);
  for (int f = 0; f < 12; ++f) streams.step();
  Buffer<anim::Mat3x4> resolved(streams.palette_size(), current_memory());
  const std::vector<glm::vec3> positions(at.begin(), at.begin() + agents);
  const std::vector<float> agent_yaws(yaws.begin(), yaws.begin() + agents);
  streams.resolve(positions, agent_yaws, resolved.span());
  compare(r.capture_skinned(poses_of(streams, resolved.span()), DrawTier::Fine), resolved.to_vector(), rig.mesh,
          agents);

  // Palette references: locomotion through streams, some agents changing
  // bucket (cross-fading two slots), composed by the renderer's packing.
  anim::LocomotionStreams loco(anim::default_blend_spaces().speeds, n);
  loco.set_agents(at, yaws, speeds);
  for (int f = 0; f < 6; ++f) loco.animate(nullptr);
  std::vector<float> faster = speeds;
  for (float& v : faster) v += 0.3f;
  loco.set_agents(at, yaws, faster);
  loco.animate(nullptr);
  ASSERT_GT(loco.last_frame().retargeted, 0);
  CharacterPoses refs;
  refs.palette_refs = loco.palette_refs();
  refs.root_positions = loco.positions();
  refs.root_yaws = loco.yaws();
  const Span<const anim::Mat3x4> composed = loco.palettes();
  compare(r.capture_skinned(refs, DrawTier::Fine), std::vector<anim::Mat3x4>(composed.begin(), composed.end()),
          rig.mesh, n);
}

// A crowd exported to glTF and read back (io/crowd_gltf.h) draws like the
// crowd itself: palettes from the file's nodes (forward kinematics of its
// keys) and its inverse bind matrices against throng's own pose of the same
// frame (world joint frames). Silhouettes (pixels differing from the empty
// scene) overlap by at least 97%.
TEST_F(RendererTest, ACrowdReadBackFromItsGltfDrawsLikeThrongsOwn) {
  const motion::BlendSpace1D space = motion::make_default_blend_space();
  const Index n = 8;
  anim::CrowdAnimatorConfig config;
  config.lod = false;
  anim::CrowdAnimator crowd(space, n, config);
  std::vector<glm::vec3> at;
  std::vector<float> yaws, scales, speeds;
  for (Index i = 0; i < n; ++i) {
    at.emplace_back(-5.0f + 1.4f * static_cast<float>(i), 0.0f, -1.0f * static_cast<float>(i % 3));
    yaws.push_back(0.8f * static_cast<float>(i));
    scales.push_back(0.9f + 0.03f * static_cast<float>(i));
    speeds.push_back(0.3f + 0.2f * static_cast<float>(i));
  }
  crowd.place(at, yaws, scales);
  crowd.set_speeds(speeds);
  io::CrowdTake take(anim::make_rig("mannequin", space.skeleton()), scales, 30.0);
  for (int f = 0; f < 15; ++f) {
    crowd.animate({1.0f / 30.0f, nullptr, true});
    take.add_frame(crowd.joint_positions(), crowd.joint_rotations());
  }
  const std::string path = (std::filesystem::temp_directory_path() / "throng_renderer_crowd.glb").string();
  io::write_crowd_glb(path, take);
  const io::CrowdGlb glb(path);
  std::filesystem::remove(path);
  const std::int32_t J = glb.joints();
  std::vector<anim::Mat3x4> palettes;
  std::vector<Index> offsets;
  std::vector<glm::vec3> p;
  std::vector<glm::quat> q;
  std::vector<float> s;
  for (Index c = 0; c < n; ++c) {
    offsets.push_back(c * J);
    glb.joint_frames(c, glb.frames() - 1, p, q, s);
    for (std::int32_t j = 0; j < J; ++j) {
      const auto k = static_cast<std::size_t>(j);
      anim::Mat3x4 world = anim::mat3x4_from(q[k], p[k]);
      for (glm::vec4* row : {&world.r0, &world.r1, &world.r2}) *row = glm::vec4(glm::vec3(*row) * s[k], row->w);
      palettes.push_back(world * glb.inverse_bind()[k]);
    }
  }
  CharacterPoses from_file;
  from_file.palettes = palettes;
  from_file.palette_offsets = offsets;

  Renderer r(make_crowd_rigs(space.skeleton()));
  const Camera cam = camera(480, 270);
  RenderOptions skinned;
  skinned.mode = RenderMode::Skinned;
  const Image own = draw(r, cam, poses_of(crowd), skinned);
  const Image exported = draw(r, cam, from_file, skinned);
  const Image empty = draw(r, cam, TPoseCrowd().poses(), skinned);
  std::int64_t both = 0, either = 0;
  for (std::int32_t y = 0; y < cam.height; ++y)
    for (std::int32_t x = 0; x < cam.width; ++x) {
      const bool a = colour_distance(own, x, y, empty.pixel(x, y)) > 24,
                 b = colour_distance(exported, x, y, empty.pixel(x, y)) > 24;
      both += a && b;
      either += a || b;
    }
  const double overlap = either > 0 ? static_cast<double>(both) / static_cast<double>(either) : 0.0;
  std::printf("  silhouettes: %lld pixels in both, %lld in either: overlap %.4f\n", static_cast<long long>(both),
              static_cast<long long>(either), overlap);
  EXPECT_GT(either, 1000);  // eight characters, 12 to 16 m away
  EXPECT_GT(overlap, 0.97);
}

// A fixed scene against a committed picture, in both modes. Regenerate
// after an intended change of the renderer's look with
//   THRONG_UPDATE_GOLDEN=1 build/release/src/render_tests --gtest_filter='*Golden*'
void expect_golden(const Image& image, const std::string& golden) {
  if (std::getenv("THRONG_UPDATE_GOLDEN") != nullptr) {
    write_png(golden, image);
    GTEST_SKIP() << "wrote " << golden;
  }
  ASSERT_TRUE(std::filesystem::exists(golden)) << "missing " << golden << " (run from the source folder)";
  const ImageDifference d = compare_images(image, read_png(golden), 40);
  // Tolerance for rasteriser differences between Mesa versions and GPUs:
  // edges may move by a pixel, nothing else.
  EXPECT_LT(d.mean_abs, 2.0);
  EXPECT_LT(d.fraction_differing, 0.01);
  if (d.fraction_differing >= 0.01) {
    const std::string actual = "/tmp/throng_" + std::filesystem::path(golden).filename().string();
    write_png(actual, image);
    ADD_FAILURE() << "see " << actual;
  }
}

Image golden_scene(RenderMode mode) {
  TPoseCrowd c = test_crowd();
  c.add({-1.5f, 0.0f, 3.0f}, 3.0f, 3);
  Renderer r(make_crowd_rigs(c.skeleton));
  std::vector<sim::Polygon> polygons(1);
  polygons[0].outer = {{-7.0f, 3.0f}, {-3.0f, 3.0f}, {-5.0f, 6.0f}};
  std::vector<sim::Circle> circles = {{{5.0f, 4.0f}, 1.0f}};
  r.set_obstacles(polygons, circles);
  r.set_paths({{{-6.0f, -3.0f}, {0.0f, -1.0f}, {6.0f, -3.0f}}});
  Camera cam;
  cam.width = 192;
  cam.height = 108;
  cam.position = {1.0f, 3.0f, 9.0f};
  cam.target = {0.0f, 1.0f, 0.0f};
  RenderOptions o;
  o.mode = mode;
  o.lod_colours = true;  // the committed pictures show the joint-LOD colours
  OffscreenTarget target(cam.width, cam.height, 4);
  target.bind();
  r.render(cam, c.poses(), o);
  return target.read();
}

TEST_F(RendererTest, GoldenImage) {
  expect_golden(golden_scene(RenderMode::Joints), "tests/data/render_golden_joints.png");
}
TEST_F(RendererTest, GoldenImageSkinned) {
  expect_golden(golden_scene(RenderMode::Skinned), "tests/data/render_golden_skinned.png");
}

}  // namespace
}  // namespace throng::render
