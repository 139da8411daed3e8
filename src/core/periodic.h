// Periodic boundaries: a rectangular walkable area whose opposite sides are
// joined along x and/or y (a corridor without ends, for measuring the
// fundamental diagram at a density that holds for as long as one likes).
// Agents live in [origin, origin + period) along a wrapping axis; whatever
// looks across the seam sees the image of the other side (the minimum
// image: of the copies of q one period apart, the one nearest p).
#pragma once

#include <cmath>
#include <glm/vec2.hpp>

#include "core/config.h"

namespace throng {

struct Periodic {
  glm::vec2 origin{0.0f};  // m: the area's lower corner
  glm::vec2 period{0.0f};  // m: its extent along an axis that wraps, 0 along one that does not

  THRONG_HOST_DEVICE bool wraps() const { return period.x > 0.0f || period.y > 0.0f; }
  // The copy of q nearest p.
  THRONG_HOST_DEVICE THRONG_INLINE glm::vec2 near(glm::vec2 q, glm::vec2 p) const {
    return {near_axis(q.x, p.x, period.x), near_axis(q.y, p.y, period.y)};
  }
  // Calls fn(shift) with the shift to each copy of the area that touches
  // it, the area itself (0, 0) among them: 1, 3 or 9 shifts, rows of y,
  // each from -period to +period. (Host code: spawning, indexing, metrics.)
  template <class Fn>
  void for_each_shift(Fn&& fn) const {
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i)
        if ((i == 0 || period.x > 0.0f) && (j == 0 || period.y > 0.0f))
          fn(glm::vec2(static_cast<float>(i) * period.x, static_cast<float>(j) * period.y));
  }
  // p moved by whole periods into [origin, origin + period).
  THRONG_HOST_DEVICE glm::vec2 wrap(glm::vec2 p) const {
    return {wrap_axis(p.x, origin.x, period.x), wrap_axis(p.y, origin.y, period.y)};
  }

 private:
  THRONG_HOST_DEVICE THRONG_INLINE static float near_axis(float q, float p, float L) {
    if (!(L > 0.0f)) return q;
    const float d = q - p;
    if (d > 0.5f * L) return q - L * floorf(d / L + 0.5f);
    if (d < -0.5f * L) return q + L * floorf(-d / L + 0.5f);
    return q;
  }
  THRONG_HOST_DEVICE static float wrap_axis(float x, float o, float L) {
    if (!(L > 0.0f) || !(x == x)) return x;
    float u = x - o;
    u -= L * floorf(u / L);
    // Rounding can leave u == L for x a hair below o, or o + u == o + L.
    const float w = o + u;
    return u < L && w < o + L ? w : o;
  }
};

}  // namespace throng
