// Euler angles <-> unit quaternions for the six Tait-Bryan orders.
//
// Convention (BVH): an order names the axes in the order the channels are
// listed, and the rotation is the product in that order applied to column
// vectors: ZXY means R = Rz(z) * Rx(x) * Ry(y). Angles are indexed by axis
// (angles.x is the rotation about X), in radians unless a name says degrees.
#pragma once

#include <array>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <string_view>

namespace throng::motion {

enum class EulerOrder : std::uint8_t { XYZ, XZY, YXZ, YZX, ZXY, ZYX };
inline constexpr std::array<EulerOrder, 6> kAllEulerOrders = {EulerOrder::XYZ, EulerOrder::XZY, EulerOrder::YXZ,
                                                              EulerOrder::YZX, EulerOrder::ZXY, EulerOrder::ZYX};

const char* to_string(EulerOrder order);  // "ZXY"
// Parses "XYZ" ... "ZYX" (case-insensitive); nullopt for anything else.
std::optional<EulerOrder> parse_euler_order(std::string_view text);
// The three axes (0 = X, 1 = Y, 2 = Z) in listed order.
std::array<int, 3> euler_axes(EulerOrder order);

// Rotation by `angle` radians about axis 0, 1 or 2.
glm::dquat axis_rotation(int axis, double angle);

// R = R_a0(angles[a0]) * R_a1(angles[a1]) * R_a2(angles[a2]).
glm::dquat euler_to_quat(EulerOrder order, glm::dvec3 angles_xyz);

// Angles (indexed by axis, each in [-pi, pi]) with euler_to_quat(order, a)
// equal to the rotation of q (q need not be exactly unit). The middle angle
// is in [-pi/2, pi/2]. At gimbal lock the last angle is set to 0.
glm::dvec3 quat_to_euler(EulerOrder order, const glm::dquat& q);

}  // namespace throng::motion
