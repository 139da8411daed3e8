// Joint roles (hips, knees, elbows, ...) found from joint names.
//
// Naming schemes differ (CMU "LeftUpLeg"/"LeftLeg", 3ds Max "LeftHip"/
// "LeftKnee", DAZ "lThigh"/"lShin", ASF "lfemur"/"ltibia", Mixamo
// "mixamorig:LeftLeg", Biped "Bip01 L Calf", SMPL "L_Knee"), and the same
// word means different joints ("LeftShoulder" is the clavicle in CMU and the
// upper arm in 3ds Max). So names only find the middle joints of each limb
// (knee, elbow); the joints around them come from the hierarchy: the thigh
// is the knee's parent, the ankle the first foot-like joint below the knee.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motion/skeleton.h"

namespace throng::motion {

enum class Side : std::uint8_t { Center, Left, Right };

// A joint name split into side and body part: "mixamorig:LeftUpLeg" ->
// {Left, "upleg"}; "Bip01 R Calf" -> {Right, "calf"}; "Spine1" -> {Center, "spine"}.
// The part is lower case with separators and trailing digits removed.
struct JointName {
  Side side = Side::Center;
  std::string part;
};
JointName split_joint_name(std::string_view name);

// Role names as printed by to_string(Role): "left_knee". nullopt if unknown.
std::optional<Role> parse_role(std::string_view name);

// A user's correction: this role is played by the joint of this name.
struct RoleOverride {
  Role role;
  std::string joint;
};

// Fills skeleton.roles and skeleton.spine_chain from the joint names, then
// applies the overrides (an override naming no joint is an Error naming the
// role). Roles that cannot be found stay -1.
void assign_roles(Skeleton& skeleton, const std::vector<RoleOverride>& overrides = {});

// The joints strictly between `from` and its descendant `to` (top down);
// empty when `to` is not below `from`.
std::vector<std::int32_t> chain_between(const Skeleton& skeleton, std::int32_t from, std::int32_t to);

}  // namespace throng::motion
