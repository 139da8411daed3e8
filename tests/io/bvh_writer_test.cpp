// BVH writer: read(write(skeleton, clip)) gives the same model-space joints
// for every rotation order and unit, animated translations and gimbal lock.
#include "io/bvh_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "io/bvh_reader.h"
#include "motion/fk.h"
#include "tests/motion/random_motion.h"

namespace throng::io {
namespace {

using motion::EulerOrder;
using motion::LengthUnit;

// Largest distance between the same joint (matched by name) in two clips.
double max_joint_distance(const motion::Skeleton& sa, const motion::Clip& ca, const motion::Skeleton& sb,
                          const motion::Clip& cb) {
  const motion::ModelSpaceClip a = motion::forward_kinematics(sa, ca);
  const motion::ModelSpaceClip b = motion::forward_kinematics(sb, cb);
  EXPECT_EQ(a.frame_count, b.frame_count);
  double worst = 0;
  for (std::int32_t j = 0; j < sa.joint_count(); ++j) {
    const std::int32_t k = sb.find(sa.names[static_cast<std::size_t>(j)]);
    EXPECT_GE(k, 0) << sa.names[static_cast<std::size_t>(j)];
    if (k < 0) continue;
    for (std::int32_t f = 0; f < a.frame_count; ++f)
      worst = std::max(worst, static_cast<double>(glm::length(a.position(f, j) - b.position(f, k))));
  }
  return worst;
}

BvhFile round_trip(const motion::Skeleton& s, const motion::Clip& c, EulerOrder order, LengthUnit unit) {
  BvhWriteOptions w;
  w.order = order;
  w.unit = unit;
  BvhReadOptions r;
  r.unit = unit;
  return parse_bvh(write_bvh_string(s, c, w), "written.bvh", r);
}

TEST(BvhWriter, RoundTripEveryOrderAndUnit) {
  std::mt19937 rng(21);
  for (bool translations : {false, true}) {
    const motion::Skeleton s = motion::testing::random_skeleton(rng, 18);
    const motion::Clip c = motion::testing::random_clip(s, 30, rng, translations);
    for (EulerOrder order : motion::kAllEulerOrders)
      for (LengthUnit unit :
           {LengthUnit::Metre, LengthUnit::Centimetre, LengthUnit::Millimetre, LengthUnit::Inch, LengthUnit::CmuAsf}) {
        const BvhFile b = round_trip(s, c, order, unit);
        ASSERT_EQ(b.skeleton.joint_count(), s.joint_count());
        EXPECT_EQ(b.skeleton.names, s.names);  // depth-first skeleton: same indices
        EXPECT_EQ(b.skeleton.parents, s.parents);
        EXPECT_EQ(b.skeleton.has_end_site, s.has_end_site);
        for (std::int32_t j = 1; j < s.joint_count(); ++j) {
          EXPECT_EQ(b.rotation_order(j), motion::to_string(order));
          // Position channels only where the translation is animated.
          EXPECT_EQ(b.channels[static_cast<std::size_t>(j)].size(), (translations && j % 4 == 3) ? 6u : 3u) << j;
        }
        const double d = max_joint_distance(s, c, b.skeleton, b.clip);
        EXPECT_LT(d, 1e-5) << motion::to_string(order) << " " << motion::to_string(unit) << " translations "
                           << translations;
        for (std::size_t i = 0; i < c.rotations.size(); ++i) {
          const float diff = std::min(glm::length(c.rotations[i] - b.clip.rotations[i]),
                                      glm::length(c.rotations[i] + b.clip.rotations[i]));
          ASSERT_LT(diff, 2e-6f) << i;
        }
      }
  }
}

TEST(BvhWriter, NonDepthFirstSkeletonIsWrittenDepthFirst) {
  std::mt19937 rng(22);
  const motion::Skeleton s = motion::testing::random_skeleton(rng, 25, false);
  const motion::Clip c = motion::testing::random_clip(s, 5, rng, false);
  const BvhFile b = round_trip(s, c, EulerOrder::YXZ, LengthUnit::Centimetre);
  EXPECT_LT(max_joint_distance(s, c, b.skeleton, b.clip), 1e-5);
  // Parents of each name agree even though the indices may differ.
  for (std::int32_t j = 1; j < s.joint_count(); ++j) {
    const std::int32_t k = b.skeleton.find(s.names[static_cast<std::size_t>(j)]);
    EXPECT_EQ(b.skeleton.names[static_cast<std::size_t>(b.skeleton.parents[static_cast<std::size_t>(k)])],
              s.names[static_cast<std::size_t>(s.parents[static_cast<std::size_t>(j)])]);
  }
}

TEST(BvhWriter, HeaderAndFrameTime) {
  motion::Skeleton s;
  s.add_joint("Hips", -1, glm::vec3(0.0f));
  s.add_joint("Bad{name}\n", 0, glm::vec3(0, 0.5f, 0));
  s.add_joint("", 1, glm::vec3(0, 0.25f, 0));
  s.has_end_site[2] = 1;
  s.end_sites[2] = glm::vec3(0, 0.125f, 0);
  motion::Clip c;
  c.resize(2, 3);
  c.frame_time = 1.0f / 30.0f;
  BvhWriteOptions w;
  w.unit = LengthUnit::Centimetre;
  w.order = EulerOrder::ZYX;
  std::string text = write_bvh_string(s, c, w);
  EXPECT_NE(
      text.find(
          "ROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("\tJOINT Bad_name__\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\t\tJOINT joint_2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 0 12.5 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("MOTION\nFrames: 2\nFrame Time: 0.033333335\n"), std::string::npos) << text;
  w.frame_time = 0.0083333;
  text = write_bvh_string(s, c, w);
  EXPECT_NE(text.find("Frame Time: 0.0083333\n"), std::string::npos);
  EXPECT_EQ(parse_bvh(text, "t.bvh").frame_time, 0.0083333);
}

TEST(BvhWriter, BadInputIsAnError) {
  std::mt19937 rng(23);
  const motion::Skeleton s = motion::testing::random_skeleton(rng, 5);
  motion::Clip c = motion::testing::random_clip(s, 3, rng, false);
  motion::Clip bad = c;
  bad.rotations.pop_back();
  EXPECT_THROW(write_bvh_string(s, bad), Error);
  bad = c;
  bad.rotation(1, 2) = glm::quat(NAN, 0, 0, 0);
  EXPECT_THROW(write_bvh_string(s, bad), Error);
  bad = c;
  bad.rotation(1, 2) = glm::quat(0, 0, 0, 0);
  EXPECT_THROW(write_bvh_string(s, bad), Error);
  bad = c;
  bad.root_positions[2].x = INFINITY;
  EXPECT_THROW(write_bvh_string(s, bad), Error);
  bad = c;
  bad.frame_time = 0;
  EXPECT_THROW(write_bvh_string(s, bad), Error);
  EXPECT_THROW(write_bvh("/nonexistent/dir/out.bvh", s, c), Error);
}

TEST(BvhWriter, WritesFiles) {
  std::mt19937 rng(24);
  const motion::Skeleton s = motion::testing::random_skeleton(rng, 6);
  const motion::Clip c = motion::testing::random_clip(s, 4, rng, false);
  const auto path = std::filesystem::temp_directory_path() / "throng_bvh_writer_test.bvh";
  write_bvh(path.string(), s, c);
  BvhReadOptions r;
  r.unit = LengthUnit::Centimetre;
  const BvhFile b = read_bvh(path.string(), r);
  std::filesystem::remove(path);
  EXPECT_LT(max_joint_distance(s, c, b.skeleton, b.clip), 1e-5);
}

}  // namespace
}  // namespace throng::io
