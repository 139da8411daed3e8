// Distance fields by fast marching: against the straight-line distance in
// an open room, against the closed-form shortest way round a wall, blocked
// nodes, the aim the kernels derive, the node budget and bad options.
#include "path/distance_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "sim/world.h"
#include "tests/path/path_worlds.h"

namespace throng::path {
namespace {

using testing::Shapes;

FreeSpace space_of(const Shapes& s) { return FreeSpace::build(&s.walkable, s.polygons, s.circles); }

float node_distance(const sim::FieldData& f, std::int32_t i, std::int32_t j) {
  return f.distance[static_cast<std::size_t>(j) * static_cast<std::size_t>(f.grid.nx) + static_cast<std::size_t>(i)];
}
glm::vec2 node_point(const sim::FieldData& f, std::int32_t i, std::int32_t j) {
  return f.grid.origin + glm::vec2(static_cast<float>(i), static_cast<float>(j)) * f.grid.cell;
}

DistanceFieldOptions plain() {
  DistanceFieldOptions o;
  o.wall_cost = 0.0f;  // the plain walking distance
  return o;
}

// An open 20 x 10 m room: every node the disc fits at is as far as the
// straight line (first-order fast marching lengthens diagonals: within 5 %
// and a cell; measured 4.3 %), and the nodes nearer a wall than the radius
// are blocked.
TEST(DistanceField, OpenRoomIsTheStraightLineDistance) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {20, 10});
  const float r = 0.25f;
  const glm::vec2 target(3.1f, 4.3f);
  const sim::FieldData f = build_distance_field(space_of(s), target, r, plain());
  float worst = 0;
  std::int64_t free_nodes = 0;
  for (std::int32_t j = 0; j < f.grid.ny; ++j)
    for (std::int32_t i = 0; i < f.grid.nx; ++i) {
      const glm::vec2 p = node_point(f, i, j);
      const bool fits = p.x >= r + 0.01f && p.x <= 20 - r - 0.01f && p.y >= r + 0.01f && p.y <= 10 - r - 0.01f;
      const bool blocked = p.x < r - 0.01f || p.x > 20 - r + 0.01f || p.y < r - 0.01f || p.y > 10 - r + 0.01f;
      const float d = node_distance(f, i, j);
      if (blocked) {
        EXPECT_FALSE(d < INFINITY) << p.x << ", " << p.y;
      }
      if (!fits) continue;
      ++free_nodes;
      const float straight = sim::length_of(p - target);
      ASSERT_LT(d, INFINITY) << p.x << ", " << p.y;
      worst = std::max(worst, std::fabs(d - straight) / std::max(straight, 1.0f));
      EXPECT_GE(d, straight - 1e-3f) << p.x << ", " << p.y;
      EXPECT_LE(d, 1.05f * straight + f.grid.cell) << p.x << ", " << p.y;
    }
  EXPECT_GT(free_nodes, 4000);
  std::printf("  open room: %lld free nodes, worst error %.2f %% of the distance\n", static_cast<long long>(free_nodes),
              100.0 * static_cast<double>(worst));
}

// A door line 6 m long across the open room (x = 14, y from 2 to 8): every
// node the disc fits at is as far as the nearest point of the line (closed
// form: the distance to a segment), within first order's diagonal error;
// in front of the line that is the distance to the line itself, not to its
// middle.
TEST(DistanceField, ADoorLineIsTheDistanceToItsNearestPoint) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {20, 10});
  const float r = 0.25f;
  const glm::vec2 middle(14.0f, 5.0f), half(0.0f, 3.0f);
  const sim::FieldData f = build_distance_field(space_of(s), middle, r, plain(), half);
  EXPECT_EQ(f.grid.target_half, half);
  float worst = 0;
  for (std::int32_t j = 0; j < f.grid.ny; ++j)
    for (std::int32_t i = 0; i < f.grid.nx; ++i) {
      const glm::vec2 p = node_point(f, i, j);
      if (!(p.x >= r + 0.01f && p.x <= 20 - r - 0.01f && p.y >= r + 0.01f && p.y <= 10 - r - 0.01f)) continue;
      const glm::vec2 near = middle + half * std::clamp((p.y - middle.y) / half.y, -1.0f, 1.0f);
      const float straight = sim::length_of(p - near), d = node_distance(f, i, j);
      ASSERT_LT(d, INFINITY) << p.x << ", " << p.y;
      worst = std::max(worst, std::fabs(d - straight) / std::max(straight, 1.0f));
      EXPECT_GE(d, straight - 1e-3f) << p.x << ", " << p.y;
      EXPECT_LE(d, 1.05f * straight + f.grid.cell) << p.x << ", " << p.y;
    }
  std::printf("  door line: worst error %.2f %% of the distance\n", 100.0 * static_cast<double>(worst));
  // 4 m in front of the line, 2.6 m off its middle: 4 m, where the middle is 4.8 m away.
  const sim::FieldGrid grids[] = {f.grid};
  const sim::FieldsView view{{grids, 1}, {f.distance.data(), static_cast<Index>(f.distance.size())}};
  EXPECT_NEAR(sim::field_distance(view, 0, {10.0f, 7.6f}), 4.0f, 0.15f);
  // Within two cells of the line the aim is its nearest point, not its middle.
  EXPECT_EQ(sim::field_aim(view, 0, {13.8f, 7.0f}), glm::vec2(14.0f, 7.0f));
}

// A 14 m wall across a room with the target behind it: the distance from
// the far side is the shortest way round the wall's end, kept a radius off
// it (closed form: start to the rounded corner, the arc, on to the target),
// lengthened by first order's diagonal error (measured 6.7 %) and the grid's
// blocked nodes round the corner.
TEST(DistanceField, WayRoundAWallMatchesTheClosedForm) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {20, 20});
  s.polygons.push_back({sim::rect_ring({9.9f, 0}, {10.1f, 14}), {}});
  const float r = 0.3f;
  const glm::vec2 target(15, 5), start(5, 5);
  const sim::FieldData f = build_distance_field(space_of(s), target, r, plain());
  // Tangent lines to the circle of radius r round the wall's corners
  // (9.9, 14) and (10.1, 14), joined along the top face.
  auto tangent = [&](glm::vec2 from, glm::vec2 corner) {
    const float d = sim::length_of(from - corner);
    return std::sqrt(d * d - r * r);
  };
  const glm::vec2 c0(9.9f, 14), c1(10.1f, 14);
  auto angle = [&](glm::vec2 from, glm::vec2 corner) {  // of the tangent point seen from the corner, from +y
    const glm::vec2 v = from - corner;
    const float d = sim::length_of(v);
    return std::atan2(std::fabs(v.x), v.y) + std::acos(r / d) - 1.5707964f;
  };
  const float arc = r * (3.1415927f - std::fabs(angle(start, c0)) - std::fabs(angle(target, c1)));
  const float expected = tangent(start, c0) + 0.2f + tangent(target, c1) + std::max(0.0f, arc);
  const float gx = (start.x - f.grid.origin.x) / f.grid.cell, gy = (start.y - f.grid.origin.y) / f.grid.cell;
  const float d =
      node_distance(f, static_cast<std::int32_t>(std::lround(gx)), static_cast<std::int32_t>(std::lround(gy)));
  std::printf("  round the wall: field %.3f m, closed form %.3f m\n", static_cast<double>(d),
              static_cast<double>(expected));
  EXPECT_GE(d, expected - 2 * f.grid.cell);
  EXPECT_LE(d, 1.08f * expected + 2 * f.grid.cell);
  // The agent at the start aims up, towards the wall's end, not at the wall.
  const sim::FieldGrid grids[] = {f.grid};
  const sim::FieldsView view{{grids, 1}, {f.distance.data(), static_cast<Index>(f.distance.size())}};
  const glm::vec2 aim = sim::field_aim(view, 0, start);
  const glm::vec2 dir = aim - start, to_end = glm::vec2(9.6f, 14.3f) - start;
  const float cos_angle = sim::dot2(dir, to_end) / (sim::length_of(dir) * sim::length_of(to_end));
  EXPECT_GT(cos_angle, std::cos(0.26f)) << "aim " << aim.x << ", " << aim.y;
  // In plain view of the target, the aim lies towards it (within 3 degrees);
  // next to it, it is the target itself.
  const glm::vec2 from(14, 10), seen = sim::field_aim(view, 0, from);
  const float cos_seen =
      sim::dot2(seen - from, target - from) / (sim::length_of(seen - from) * sim::length_of(target - from));
  EXPECT_GT(cos_seen, std::cos(0.05f)) << "aim " << seen.x << ", " << seen.y;
  EXPECT_EQ(sim::field_aim(view, 0, target + glm::vec2(0.2f, 0.1f)), target);
}

// A closed room's nodes are out of reach; so are those inside obstacles.
TEST(DistanceField, UnreachableAndObstacleNodesAreBlocked) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {20, 10});
  s.polygons.push_back({sim::rect_ring({9.5f, -1}, {10.5f, 11}), {}});  // splits the room
  s.circles.push_back({{4, 5}, 1.0f});
  const sim::FieldData f = build_distance_field(space_of(s), glm::vec2(2, 2), 0.25f, plain());
  for (std::int32_t j = 0; j < f.grid.ny; ++j)
    for (std::int32_t i = 0; i < f.grid.nx; ++i) {
      const glm::vec2 p = node_point(f, i, j);
      const float d = node_distance(f, i, j);
      if (p.x > 10.5f || sim::length_of(p - glm::vec2(4, 5)) < 1.2f) {
        EXPECT_FALSE(d < INFINITY) << p.x << ", " << p.y;
      }
    }
  EXPECT_LT(node_distance(f, 16, 6), INFINITY);  // (3, 1): beside the target
}

// Near walls the default slowness lengthens the distance, never shortens it.
TEST(DistanceField, WallCostOnlyLengthens) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {12, 3});
  const FreeSpace fs = space_of(s);
  const sim::FieldData a = build_distance_field(fs, glm::vec2(11, 1.5f), 0.25f, plain());
  const sim::FieldData b = build_distance_field(fs, glm::vec2(11, 1.5f), 0.25f, {});
  ASSERT_EQ(a.distance.size(), b.distance.size());
  for (std::size_t k = 0; k < a.distance.size(); ++k)
    if (a.distance[k] < INFINITY) {
      EXPECT_GE(b.distance[k], a.distance[k] - 1e-4f);
    }
}

// A target against a thin wall: the seeds round it do not reach through
// the wall, so the far side's distance is the way round its end.
TEST(DistanceField, SeedsDoNotLeakThroughAThinWall) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {10, 4});
  s.polygons.push_back({sim::rect_ring({5, 0}, {5.1f, 3}), {}});  // open above y = 3
  const glm::vec2 target(4.8f, 1);
  const sim::FieldData f = build_distance_field(space_of(s), target, 0.25f, plain());
  const float gx = (5.4f - f.grid.origin.x) / f.grid.cell, gy = (1.0f - f.grid.origin.y) / f.grid.cell;
  const float behind =
      node_distance(f, static_cast<std::int32_t>(std::lround(gx)), static_cast<std::int32_t>(std::lround(gy)));
  // Up to the wall's end, over it and down: about 2 x 2.25 m + 0.6 m.
  EXPECT_GT(behind, 4.5f);
  EXPECT_LT(behind, 7.0f);
}

// Without a walkable region the field covers the obstacles' surroundings
// and the target, however far it lies.
TEST(DistanceField, AWorldWithoutWallsCoversAFarTarget) {
  sim::WorldSpec spec;
  spec.polygons.push_back({sim::rect_ring({0, -5}, {1, 5}), {}});
  const sim::World world = sim::World::build(spec, 4.0f);
  const FastMarchingFieldBuilder builder;
  for (const glm::vec2 target : {glm::vec2(4, 0), glm::vec2(60, 0)}) {
    const sim::FieldData f = builder.build(world, target, 0.25f);
    const sim::FieldGrid grids[] = {f.grid};
    const sim::FieldsView view{{grids, 1}, {f.distance.data(), static_cast<Index>(f.distance.size())}};
    EXPECT_LT(sim::field_distance(view, 0, target + glm::vec2(0.5f, 0.5f)), 1.0f) << target.x;
    // Behind the obstacle: round it, more than the straight line.
    const float d = sim::field_distance(view, 0, glm::vec2(-1, 0));
    EXPECT_LT(d, INFINITY) << target.x;
    EXPECT_GT(d, sim::length_of(target - glm::vec2(-1, 0))) << target.x;
  }
}

// A square kilometre at 0.2 m would be 25 million nodes: the cell grows so
// the field stays within its budget, and still covers the whole area.
TEST(DistanceField, StaysWithinTheNodeBudget) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {1000, 1000});
  s.circles.push_back({{500, 500}, 3.0f});
  DistanceFieldOptions o;
  o.max_nodes = 100000;
  const sim::FieldData f = build_distance_field(space_of(s), glm::vec2(10, 10), 0.25f, o);
  EXPECT_LE(static_cast<std::int64_t>(f.grid.nx) * f.grid.ny, o.max_nodes);
  EXPECT_GT(f.grid.cell, 3.0f);
  EXPECT_LE(f.grid.origin.x, 0.0f);
  EXPECT_LE(f.grid.origin.y, 0.0f);
  EXPECT_GE(f.grid.origin.x + static_cast<float>(f.grid.nx - 1) * f.grid.cell, 1000.0f);
  EXPECT_GE(f.grid.origin.y + static_cast<float>(f.grid.ny - 1) * f.grid.cell, 1000.0f);
  EXPECT_EQ(f.distance.size(), static_cast<std::size_t>(f.grid.nx) * static_cast<std::size_t>(f.grid.ny));
}

TEST(DistanceField, RejectsBadOptions) {
  auto field_of = [](auto&& set) {
    DistanceFieldOptions o;
    set(o);
    try {
      o.validate();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(field_of([](DistanceFieldOptions& o) { o.cell = NAN; }).find("field.cell"), std::string::npos);
  EXPECT_NE(field_of([](DistanceFieldOptions& o) { o.wall_band = 0; }).find("field.wall_band"), std::string::npos);
  EXPECT_NE(field_of([](DistanceFieldOptions& o) { o.wall_cost = -1; }).find("field.wall_cost"), std::string::npos);
  EXPECT_NE(field_of([](DistanceFieldOptions& o) { o.max_nodes = 0; }).find("field.max_nodes"), std::string::npos);
}

}  // namespace
}  // namespace throng::path
