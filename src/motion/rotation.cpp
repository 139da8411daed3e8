#include "motion/rotation.h"

#include <cmath>

namespace throng::motion {

const char* to_string(EulerOrder order) {
  switch (order) {
    case EulerOrder::XYZ: return "XYZ";
    case EulerOrder::XZY: return "XZY";
    case EulerOrder::YXZ: return "YXZ";
    case EulerOrder::YZX: return "YZX";
    case EulerOrder::ZXY: return "ZXY";
    case EulerOrder::ZYX: return "ZYX";
  }
  return "?";
}

std::optional<EulerOrder> parse_euler_order(std::string_view text) {
  if (text.size() != 3) return std::nullopt;
  char up[3];
  for (int i = 0; i < 3; ++i) up[i] = static_cast<char>(text[static_cast<std::size_t>(i)] & ~0x20);  // ASCII upper case
  for (EulerOrder o : kAllEulerOrders) {
    const char* name = to_string(o);
    if (up[0] == name[0] && up[1] == name[1] && up[2] == name[2]) return o;
  }
  return std::nullopt;
}

std::array<int, 3> euler_axes(EulerOrder order) {
  const char* name = to_string(order);
  return {name[0] - 'X', name[1] - 'X', name[2] - 'X'};
}

glm::dquat axis_rotation(int axis, double angle) {
  const double s = std::sin(0.5 * angle);
  const double c = std::cos(0.5 * angle);
  glm::dquat q(c, 0.0, 0.0, 0.0);
  q[axis] = s;  // glm::quat indexes x, y, z, w
  return q;
}

glm::dquat euler_to_quat(EulerOrder order, glm::dvec3 angles_xyz) {
  const auto a = euler_axes(order);
  return axis_rotation(a[0], angles_xyz[a[0]]) * axis_rotation(a[1], angles_xyz[a[1]]) *
         axis_rotation(a[2], angles_xyz[a[2]]);
}

glm::dvec3 quat_to_euler(EulerOrder order, const glm::dquat& q_in) {
  const glm::dquat q = glm::normalize(q_in);
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  // m[row][col] of the rotation matrix acting on column vectors.
  const double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  const auto ax = euler_axes(order);
  const int i = ax[0], j = ax[1], k = ax[2];
  // +1 when (i, j, k) is a cyclic permutation of (X, Y, Z); flips the signs.
  const double s = (j == (i + 1) % 3) ? 1.0 : -1.0;
  // R = R_i(a) R_j(b) R_k(c): row i is [cb cc, -s cb sc, s sb] up to column order.
  const double cos_b = std::sqrt(m[i][i] * m[i][i] + m[i][j] * m[i][j]);
  double a, b, c;
  b = std::atan2(s * m[i][k], cos_b);
  if (cos_b > 1e-8) {
    a = std::atan2(-s * m[j][k], m[k][k]);
    c = std::atan2(-s * m[i][j], m[i][i]);
  } else {
    // Gimbal lock: only a +- c is defined; put it all in a.
    c = 0.0;
    a = std::atan2(s * m[k][j], m[j][j]);
  }
  glm::dvec3 out(0.0);
  out[i] = a;
  out[j] = b;
  out[k] = c;
  return out;
}

}  // namespace throng::motion
