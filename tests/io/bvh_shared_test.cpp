// Every real BVH file in ../shared/data/bvh: loads, agrees with its own
// header (parsed here independently), has its roles found, and survives a
// write/read round trip within 0.1 mm for every joint of every frame.
// Skipped with a message when the shared folder is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "io/bvh_info.h"
#include "io/bvh_reader.h"
#include "io/bvh_writer.h"
#include "motion/fk.h"
#include "tests/shared_data.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> shared_files(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".bvh") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The header facts, read with nothing from the reader: count ROOT/JOINT and
// "End Site" lines, read "Frames:" and "Frame Time:" with strtol/strtod.
struct Header {
  int joints = 0;
  int end_sites = 0;
  long frames = -1;
  double frame_time = -1;
};
Header read_header(const std::string& text) {
  Header h;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    const std::string l = line.substr(first);
    if (l.rfind("ROOT", 0) == 0 || l.rfind("JOINT", 0) == 0) ++h.joints;
    if (l.rfind("End Site", 0) == 0) ++h.end_sites;
    if (l.rfind("Frames:", 0) == 0) h.frames = std::strtol(l.c_str() + 7, nullptr, 10);
    if (l.rfind("Frame Time:", 0) == 0) {
      h.frame_time = std::strtod(l.c_str() + 11, nullptr);
      break;
    }
  }
  return h;
}

bool is_mb(const fs::path& p) { return p.filename().string().find("_mb") != std::string::npos; }
bool is_daz(const fs::path& p) { return p.filename().string().find("_daz") != std::string::npos; }
bool is_max(const fs::path& p) { return p.filename().string().find("_max") != std::string::npos; }

TEST(BvhShared, EveryFileLoadsAndMatchesItsHeader) {
  THRONG_NEED_SHARED_BVH(dir);
  const auto files = shared_files(*dir);
  ASSERT_FALSE(files.empty());
  for (const auto& path : files) {
    SCOPED_TRACE(path.filename().string());
    const Header h = read_header(slurp(path));
    const BvhFile b = read_bvh(path.string());
    EXPECT_EQ(b.skeleton.joint_count(), h.joints);
    EXPECT_EQ(b.end_site_count, h.end_sites);
    EXPECT_EQ(b.clip.frame_count, h.frames);
    EXPECT_EQ(b.frame_time, h.frame_time);
    EXPECT_EQ(b.bytes, fs::file_size(path));
    const nlohmann::json j = bvh_info(b);
    EXPECT_EQ(j["joints"].get<int>(), h.joints);
    EXPECT_EQ(j["frames"].get<long>(), h.frames);
    EXPECT_EQ(j["frame_time"].get<double>(), h.frame_time);
    // The channel layouts SOURCES.md describes.
    EXPECT_EQ(b.channel_list(0), "Xposition Yposition Zposition Zrotation Yrotation Xrotation");
    const auto& orders = j["rotation_orders"];
    const nlohmann::json want = is_mb(path)    ? nlohmann::json({{"ZYX", 31}})
                                : is_daz(path) ? nlohmann::json({{"ZYX", 1}, {"ZXY", 42}})
                                               : nlohmann::json({{"ZYX", 19}, {"ZXY", 12}});
    EXPECT_EQ(orders, want);
    // Units: CMU ASF units for mb and max, centimetres for daz.
    EXPECT_TRUE(b.unit_detected);
    EXPECT_EQ(b.unit, is_daz(path) ? motion::LengthUnit::Centimetre : motion::LengthUnit::CmuAsf);
    float off_unit = 0;
    for (const glm::quat& q : b.clip.rotations) off_unit = std::max(off_unit, std::abs(glm::dot(q, q) - 1.0f));
    EXPECT_LT(off_unit, 1e-5f);
    // In metres the rest pose is human sized.
    const double extent = j["rest_extent_m"].get<double>();
    EXPECT_GT(extent, 1.2);
    EXPECT_LT(extent, 2.2);
  }
}

std::string role_name(const motion::Skeleton& s, motion::Role r) {
  return s.role(r) >= 0 ? s.names[static_cast<std::size_t>(s.role(r))] : "-";
}

TEST(BvhShared, RolesOfEveryFile) {
  THRONG_NEED_SHARED_BVH(dir);
  using motion::Role;
  for (const auto& path : shared_files(*dir)) {
    SCOPED_TRACE(path.filename().string());
    const BvhFile b = read_bvh(path.string());
    const motion::Skeleton& s = b.skeleton;
    std::printf("%s:", path.filename().c_str());
    for (std::size_t r = 0; r < motion::kRoleCount; ++r)
      std::printf(" %s=%s", motion::to_string(static_cast<Role>(r)), role_name(s, static_cast<Role>(r)).c_str());
    std::printf(" | spine:");
    for (std::int32_t j : s.spine_chain) std::printf(" %s", s.names[static_cast<std::size_t>(j)].c_str());
    std::printf("\n");
    std::vector<std::pair<Role, std::string>> want;
    std::vector<std::string> spine;
    if (is_mb(path)) {
      want = {{Role::Hips, "Hips"},
              {Role::Neck, "Neck"},
              {Role::Head, "Head"},
              {Role::LeftShoulder, "LeftArm"},
              {Role::RightShoulder, "RightArm"},
              {Role::LeftElbow, "LeftForeArm"},
              {Role::RightElbow, "RightForeArm"},
              {Role::LeftWrist, "LeftHand"},
              {Role::RightWrist, "RightHand"},
              {Role::LeftThigh, "LeftUpLeg"},
              {Role::RightThigh, "RightUpLeg"},
              {Role::LeftKnee, "LeftLeg"},
              {Role::RightKnee, "RightLeg"},
              {Role::LeftAnkle, "LeftFoot"},
              {Role::RightAnkle, "RightFoot"},
              {Role::LeftToe, "LeftToeBase"},
              {Role::RightToe, "RightToeBase"}};
      spine = {"LowerBack", "Spine", "Spine1"};
    } else if (is_daz(path)) {
      want = {{Role::Hips, "hip"},
              {Role::Neck, "neck"},
              {Role::Head, "head"},
              {Role::LeftShoulder, "lShldr"},
              {Role::RightShoulder, "rShldr"},
              {Role::LeftElbow, "lForeArm"},
              {Role::RightElbow, "rForeArm"},
              {Role::LeftWrist, "lHand"},
              {Role::RightWrist, "rHand"},
              {Role::LeftThigh, "lThigh"},
              {Role::RightThigh, "rThigh"},
              {Role::LeftKnee, "lShin"},
              {Role::RightKnee, "rShin"},
              {Role::LeftAnkle, "lFoot"},
              {Role::RightAnkle, "rFoot"},
              {Role::LeftToe, "-"},
              {Role::RightToe, "-"}};  // the DAZ feet end in an End Site
      spine = {"abdomen", "chest"};
    } else if (is_max(path)) {
      want = {{Role::Hips, "Hips"},
              {Role::Neck, "lowerneck"},
              {Role::Head, "Head"},
              {Role::LeftShoulder, "LeftShoulder"},
              {Role::RightShoulder, "RightShoulder"},
              {Role::LeftElbow, "LeftElbow"},
              {Role::RightElbow, "RightElbow"},
              {Role::LeftWrist, "LeftWrist"},
              {Role::RightWrist, "RightWrist"},
              {Role::LeftThigh, "LeftHip"},
              {Role::RightThigh, "RightHip"},
              {Role::LeftKnee, "LeftKnee"},
              {Role::RightKnee, "RightKnee"},
              {Role::LeftAnkle, "LeftAnkle"},
              {Role::RightAnkle, "RightAnkle"},
              {Role::LeftToe, "LeftToe"},
              {Role::RightToe, "RightToe"}};
      spine = {"lowerback", "Chest", "Chest2"};
    } else {
      ADD_FAILURE() << "unknown naming scheme; add its expected roles here";
    }
    for (const auto& [role, name] : want) EXPECT_EQ(role_name(s, role), name) << motion::to_string(role);
    std::vector<std::string> got;
    for (std::int32_t j : s.spine_chain) got.push_back(s.names[static_cast<std::size_t>(j)]);
    EXPECT_EQ(got, spine);
  }
}

double max_joint_distance(const BvhFile& a, const BvhFile& b) {
  const motion::ModelSpaceClip ma = motion::forward_kinematics(a.skeleton, a.clip);
  const motion::ModelSpaceClip mb = motion::forward_kinematics(b.skeleton, b.clip);
  EXPECT_EQ(ma.positions.size(), mb.positions.size());
  double worst = 0;
  for (std::size_t i = 0; i < std::min(ma.positions.size(), mb.positions.size()); ++i)
    worst = std::max(worst, static_cast<double>(glm::length(ma.positions[i] - mb.positions[i])));
  return worst;
}

TEST(BvhShared, RoundTripWithinATenthOfAMillimetre) {
  THRONG_NEED_SHARED_BVH(dir);
  const motion::LengthUnit units[] = {motion::LengthUnit::Centimetre, motion::LengthUnit::Metre,
                                      motion::LengthUnit::Inch};
  std::size_t k = 0;
  for (const auto& path : shared_files(*dir)) {
    SCOPED_TRACE(path.filename().string());
    const BvhFile original = read_bvh(path.string());
    // Each file in two rotation orders (and three units in turn); one in all six.
    std::vector<motion::EulerOrder> orders = {motion::kAllEulerOrders[k % 6], motion::kAllEulerOrders[(k + 3) % 6]};
    if (k == 0) orders.assign(motion::kAllEulerOrders.begin(), motion::kAllEulerOrders.end());
    for (motion::EulerOrder order : orders) {
      BvhWriteOptions w;
      w.order = order;
      w.unit = units[k % 3];
      w.frame_time = original.frame_time;
      BvhReadOptions r;
      r.unit = w.unit;
      const BvhFile again = parse_bvh(write_bvh_string(original.skeleton, original.clip, w), "round_trip.bvh", r);
      EXPECT_EQ(again.skeleton.names, original.skeleton.names);
      EXPECT_EQ(again.skeleton.parents, original.skeleton.parents);
      EXPECT_EQ(again.frame_time, original.frame_time);
      const double d = max_joint_distance(original, again);
      std::printf("%s as %s in %s: max joint distance %.3g m over %d frames\n", path.filename().c_str(),
                  motion::to_string(order), motion::to_string(w.unit), d, original.clip.frame_count);
      EXPECT_LT(d, 1e-4) << motion::to_string(order);
    }
    ++k;
  }
}

}  // namespace
}  // namespace throng::io
