// Joint roles from names over the common naming schemes, with the hierarchy
// deciding between look-alike names.
#include "motion/roles.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace throng::motion {
namespace {

// A skeleton from (name, parent name) pairs in parent-before-child order.
Skeleton make(const std::vector<std::pair<std::string, std::string>>& joints) {
  Skeleton s;
  for (const auto& [name, parent] : joints)
    s.add_joint(name, parent.empty() ? -1 : s.find(parent), glm::vec3(0.0f, 0.1f, 0.0f));
  return s;
}

// A chain: each joint the child of the previous one, the first under `parent`.
void chain(std::vector<std::pair<std::string, std::string>>& out, const std::string& parent,
           const std::vector<std::string>& names) {
  std::string p = parent;
  for (const auto& n : names) {
    out.emplace_back(n, p);
    p = n;
  }
}

std::string role_name(const Skeleton& s, Role r) {
  return s.role(r) >= 0 ? s.names[static_cast<std::size_t>(s.role(r))] : "-";
}

void expect_roles(const Skeleton& s, const std::map<Role, std::string>& want) {
  for (const auto& [role, name] : want) EXPECT_EQ(role_name(s, role), name) << to_string(role);
}

std::vector<std::string> spine(const Skeleton& s) {
  std::vector<std::string> out;
  for (std::int32_t j : s.spine_chain) out.push_back(s.names[static_cast<std::size_t>(j)]);
  return out;
}

TEST(Roles, SplitJointName) {
  const std::vector<std::tuple<std::string, Side, std::string>> cases = {{"mixamorig:LeftUpLeg", Side::Left, "upleg"},
                                                                         {"Bip01 R Calf", Side::Right, "calf"},
                                                                         {"Bip001 L UpperArm", Side::Left, "upperarm"},
                                                                         {"Spine1", Side::Center, "spine"},
                                                                         {"lShldr", Side::Left, "shldr"},
                                                                         {"rForeArm", Side::Right, "forearm"},
                                                                         {"LHipJoint", Side::Left, "hipjoint"},
                                                                         {"lhumerus", Side::Left, "humerus"},
                                                                         {"rtibia", Side::Right, "tibia"},
                                                                         {"lowerback", Side::Center, "lowerback"},
                                                                         {"lowerneck", Side::Center, "lowerneck"},
                                                                         {"L_Knee", Side::Left, "knee"},
                                                                         {"knee_r", Side::Right, "knee"},
                                                                         {"ThighL", Side::Left, "thigh"},
                                                                         {"RightToe_End", Side::Right, "toeend"},
                                                                         {"Left Hand", Side::Left, "hand"},
                                                                         {"Leg", Side::Center, "leg"},
                                                                         {"radius", Side::Center, "radius"},
                                                                         {"Neck1", Side::Center, "neck"},
                                                                         {"rig|Head", Side::Center, "head"},
                                                                         {"Pelvis", Side::Center, "pelvis"},
                                                                         {"Spinal", Side::Center, "spinal"}};
  for (const auto& [name, side, part] : cases) {
    const JointName n = split_joint_name(name);
    EXPECT_EQ(n.side, side) << name;
    EXPECT_EQ(n.part, part) << name;
  }
}

TEST(Roles, ParseRoleNames) {
  for (std::size_t i = 0; i < kRoleCount; ++i)
    EXPECT_EQ(parse_role(to_string(static_cast<Role>(i))), static_cast<Role>(i));
  EXPECT_EQ(parse_role("LEFT_KNEE"), Role::LeftKnee);
  EXPECT_FALSE(parse_role("left_kne").has_value());
}

// CMU MotionBuilder naming: LeftShoulder is the clavicle, LeftArm the humerus.
TEST(Roles, CmuMotionBuilder) {
  std::vector<std::pair<std::string, std::string>> j = {{"Hips", ""}};
  for (std::string side : {"Left", "Right"}) {
    const std::string s1 = side.substr(0, 1);
    chain(j, "Hips", {s1 + "HipJoint", side + "UpLeg", side + "Leg", side + "Foot", side + "ToeBase"});
  }
  chain(j, "Hips", {"LowerBack", "Spine", "Spine1", "Neck", "Neck1", "Head"});
  for (std::string side : {"Left", "Right"})
    chain(j, "Spine1", {side + "Shoulder", side + "Arm", side + "ForeArm", side + "Hand", side + "FingerBase"});
  Skeleton s = make(j);
  assign_roles(s);
  expect_roles(s, {{Role::Hips, "Hips"},
                   {Role::Neck, "Neck"},
                   {Role::Head, "Head"},
                   {Role::LeftShoulder, "LeftArm"},
                   {Role::RightShoulder, "RightArm"},
                   {Role::LeftElbow, "LeftForeArm"},
                   {Role::LeftWrist, "LeftHand"},
                   {Role::LeftThigh, "LeftUpLeg"},
                   {Role::RightThigh, "RightUpLeg"},
                   {Role::LeftKnee, "LeftLeg"},
                   {Role::LeftAnkle, "LeftFoot"},
                   {Role::RightToe, "RightToeBase"}});
  EXPECT_EQ(spine(s), (std::vector<std::string>{"LowerBack", "Spine", "Spine1"}));
}

// 3ds Max naming of the same data: LeftShoulder is the humerus here.
TEST(Roles, CmuMax) {
  std::vector<std::pair<std::string, std::string>> j = {{"Hips", ""}};
  chain(j, "Hips", {"LHipJoint", "LeftHip", "LeftKnee", "LeftAnkle", "LeftToe"});
  chain(j, "Hips", {"RHipJoint", "RightHip", "RightKnee", "RightAnkle", "RightToe"});
  chain(j, "Hips", {"lowerback", "Chest", "Chest2", "lowerneck", "Neck", "Head"});
  chain(j, "Chest2", {"LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist", "lhand", "LFingers"});
  chain(j, "Chest2", {"RightCollar", "RightShoulder", "RightElbow", "RightWrist", "rhand", "RFingers"});
  Skeleton s = make(j);
  assign_roles(s);
  expect_roles(s, {{Role::Neck, "lowerneck"},
                   {Role::LeftShoulder, "LeftShoulder"},
                   {Role::RightElbow, "RightElbow"},
                   {Role::LeftWrist, "LeftWrist"},
                   {Role::LeftThigh, "LeftHip"},
                   {Role::RightKnee, "RightKnee"},
                   {Role::RightAnkle, "RightAnkle"},
                   {Role::LeftToe, "LeftToe"}});
  EXPECT_EQ(spine(s), (std::vector<std::string>{"lowerback", "Chest", "Chest2"}));
}

// CMU ASF names (lfemur, ltibia, lfoot, ltoes, lhumerus, lradius, lwrist).
TEST(Roles, CmuAsf) {
  std::vector<std::pair<std::string, std::string>> j = {{"root", ""}};
  for (std::string p : {"l", "r"}) chain(j, "root", {p + "hipjoint", p + "femur", p + "tibia", p + "foot", p + "toes"});
  chain(j, "root", {"lowerback", "upperback", "thorax", "lowerneck", "upperneck", "head"});
  for (std::string p : {"l", "r"})
    chain(j, "thorax", {p + "clavicle", p + "humerus", p + "radius", p + "wrist", p + "hand"});
  Skeleton s = make(j);
  assign_roles(s);
  expect_roles(s, {{Role::Hips, "root"},
                   {Role::Neck, "lowerneck"},
                   {Role::Head, "head"},
                   {Role::LeftShoulder, "lhumerus"},
                   {Role::LeftElbow, "lradius"},
                   {Role::RightWrist, "rwrist"},
                   {Role::LeftThigh, "lfemur"},
                   {Role::RightKnee, "rtibia"},
                   {Role::LeftAnkle, "lfoot"},
                   {Role::RightToe, "rtoes"}});
  EXPECT_EQ(spine(s), (std::vector<std::string>{"lowerback", "upperback", "thorax"}));
}

TEST(Roles, MixamoWithNamespace) {
  std::vector<std::pair<std::string, std::string>> j = {{"mixamorig:Hips", ""}};
  for (std::string side : {"Left", "Right"})
    chain(j, "mixamorig:Hips",
          {"mixamorig:" + side + "UpLeg", "mixamorig:" + side + "Leg", "mixamorig:" + side + "Foot",
           "mixamorig:" + side + "ToeBase", "mixamorig:" + side + "Toe_End"});
  chain(j, "mixamorig:Hips",
        {"mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2", "mixamorig:Neck", "mixamorig:Head",
         "mixamorig:HeadTop_End"});
  for (std::string side : {"Left", "Right"})
    chain(j, "mixamorig:Spine2",
          {"mixamorig:" + side + "Shoulder", "mixamorig:" + side + "Arm", "mixamorig:" + side + "ForeArm",
           "mixamorig:" + side + "Hand"});
  Skeleton s = make(j);
  assign_roles(s);
  expect_roles(s, {{Role::Hips, "mixamorig:Hips"},
                   {Role::Head, "mixamorig:Head"},
                   {Role::Neck, "mixamorig:Neck"},
                   {Role::LeftShoulder, "mixamorig:LeftArm"},
                   {Role::RightWrist, "mixamorig:RightHand"},
                   {Role::LeftKnee, "mixamorig:LeftLeg"},
                   {Role::RightToe, "mixamorig:RightToeBase"}});
  EXPECT_EQ(spine(s).size(), 3u);
}

// 3ds Max Biped (common in Truebones files) and the old Biovision sample names.
TEST(Roles, BipedAndBiovision) {
  std::vector<std::pair<std::string, std::string>> j = {{"Bip01", ""}, {"Bip01 Pelvis", "Bip01"}};
  for (std::string s1 : {"L", "R"})
    chain(j, "Bip01 Pelvis",
          {"Bip01 " + s1 + " Thigh", "Bip01 " + s1 + " Calf", "Bip01 " + s1 + " Foot", "Bip01 " + s1 + " Toe0"});
  chain(j, "Bip01 Pelvis", {"Bip01 Spine", "Bip01 Spine1", "Bip01 Neck", "Bip01 Head"});
  for (std::string s1 : {"L", "R"})
    chain(j, "Bip01 Neck",
          {"Bip01 " + s1 + " Clavicle", "Bip01 " + s1 + " UpperArm", "Bip01 " + s1 + " Forearm",
           "Bip01 " + s1 + " Hand"});
  Skeleton s = make(j);
  assign_roles(s);
  expect_roles(s, {{Role::Hips, "Bip01 Pelvis"},
                   {Role::Neck, "Bip01 Neck"},
                   {Role::LeftThigh, "Bip01 L Thigh"},
                   {Role::RightKnee, "Bip01 R Calf"},
                   {Role::LeftToe, "Bip01 L Toe0"},
                   {Role::LeftShoulder, "Bip01 L UpperArm"},
                   {Role::RightElbow, "Bip01 R Forearm"},
                   {Role::RightWrist, "Bip01 R Hand"}});
  EXPECT_EQ(spine(s), (std::vector<std::string>{"Bip01 Spine", "Bip01 Spine1"}));

  std::vector<std::pair<std::string, std::string>> b = {{"Hips", ""}};
  for (std::string side : {"Left", "Right"}) chain(b, "Hips", {side + "UpLeg", side + "LowLeg", side + "Foot"});
  chain(b, "Hips", {"Chest", "Neck", "Head"});
  for (std::string side : {"Left", "Right"})
    chain(b, "Chest", {side + "Collar", side + "UpArm", side + "LowArm", side + "Hand"});
  Skeleton bv = make(b);
  assign_roles(bv);
  expect_roles(bv, {{Role::LeftThigh, "LeftUpLeg"},
                    {Role::LeftKnee, "LeftLowLeg"},
                    {Role::RightAnkle, "RightFoot"},
                    {Role::LeftToe, "-"},
                    {Role::LeftShoulder, "LeftUpArm"},
                    {Role::RightElbow, "RightLowArm"},
                    {Role::Neck, "Neck"}});
  EXPECT_EQ(spine(bv), (std::vector<std::string>{"Chest"}));
}

// SMPL-style: L_Ankle comes before L_Foot (which is the toe joint there).
TEST(Roles, SmplStyle) {
  std::vector<std::pair<std::string, std::string>> j = {{"Pelvis", ""}};
  for (std::string s1 : {"L", "R"}) chain(j, "Pelvis", {s1 + "_Hip", s1 + "_Knee", s1 + "_Ankle", s1 + "_Foot"});
  chain(j, "Pelvis", {"Spine1", "Spine2", "Spine3", "Neck", "Head"});
  for (std::string s1 : {"L", "R"})
    chain(j, "Spine3", {s1 + "_Collar", s1 + "_Shoulder", s1 + "_Elbow", s1 + "_Wrist", s1 + "_Hand"});
  Skeleton s = make(j);
  assign_roles(s);
  expect_roles(s, {{Role::Hips, "Pelvis"},
                   {Role::LeftThigh, "L_Hip"},
                   {Role::LeftAnkle, "L_Ankle"},
                   {Role::LeftToe, "L_Foot"},
                   {Role::RightShoulder, "R_Shoulder"},
                   {Role::RightWrist, "R_Wrist"}});
}

TEST(Roles, OverridesWinAndUnknownJointsAreErrors) {
  std::vector<std::pair<std::string, std::string>> j = {{"root", ""}};
  chain(j, "root", {"a", "b", "c"});
  chain(j, "root", {"torso", "skull"});
  Skeleton s = make(j);
  assign_roles(s);
  EXPECT_EQ(role_name(s, Role::Hips), "root");  // nothing named: the root
  EXPECT_EQ(s.role(Role::LeftKnee), -1);
  EXPECT_EQ(s.role(Role::Head), -1);
  assign_roles(s, {{Role::LeftKnee, "b"}, {Role::Head, "skull"}, {Role::Neck, "torso"}});
  EXPECT_EQ(role_name(s, Role::LeftKnee), "b");
  EXPECT_EQ(role_name(s, Role::Head), "skull");
  EXPECT_TRUE(s.spine_chain.empty());
  try {
    assign_roles(s, {{Role::RightElbow, "nope"}});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "roles.right_elbow");
    EXPECT_NE(std::string(e.what()).find("no joint named 'nope'"), std::string::npos);
  }
}

TEST(Roles, ChainBetween) {
  std::vector<std::pair<std::string, std::string>> j = {{"r", ""}};
  chain(j, "r", {"a", "b", "c", "d"});
  chain(j, "a", {"x"});
  const Skeleton s = make(j);
  EXPECT_EQ(chain_between(s, 0, 4), (std::vector<std::int32_t>{1, 2, 3}));
  EXPECT_TRUE(chain_between(s, 1, 2).empty());
  EXPECT_TRUE(chain_between(s, 5, 4).empty());  // x is not above d
  EXPECT_TRUE(chain_between(s, -1, 4).empty());
}

}  // namespace
}  // namespace throng::motion
