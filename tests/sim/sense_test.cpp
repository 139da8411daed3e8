// The sense stage's neighbour sift (for_each_neighbour, sim/neighbours.h): the
// same neighbours, at the same images, in the same order as a plain filter
// that branches on each candidate; every model's sum relies on that order
// for its bits. The same for the far look's sift (add_far_anticipation).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "sim/sense.h"
#include "sim/simulation.h"

namespace throng::sim {
namespace {

struct Seen {
  Index j;
  glm::vec2 q;
};

// Agents scattered over a square of side `extent`, one in five inactive;
// candidates visited in a shuffled order (the bins' order is arbitrary too).
struct Crowd {
  std::vector<glm::vec2> position, velocity;
  std::vector<float> radius;
  std::vector<std::uint8_t> flags;
  std::vector<Index> order;
  Crowd(std::size_t n, float extent, unsigned seed) : velocity(n), radius(n, 0.2f), flags(n) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, extent);
    for (std::size_t i = 0; i < n; ++i) {
      position.emplace_back(u(rng), u(rng));
      flags[i] = (rng() % 5 == 0) ? 0 : kAgentActive;
    }
    order.resize(n);
    std::iota(order.begin(), order.end(), Index{0});
    std::shuffle(order.begin(), order.end(), rng);
  }
  // fn(j, position) for every active agent, in `order`.
  template <class Fn>
  void visit_active(const Fn& fn) const {
    for (Index j : order)
      if ((flags[static_cast<std::size_t>(j)] & kAgentActive) != 0) fn(j, position[static_cast<std::size_t>(j)]);
  }
  NeighbourArrays arrays(const Periodic& periodic) const {
    return {Span<const glm::vec2>(position), Span<const glm::vec2>(velocity), Span<const float>(radius),
            Span<const std::uint8_t>(flags), periodic};
  }
};

// The same agents at the same points, in the same order.
void expect_same_seen(const std::vector<Seen>& expected, const std::vector<Seen>& got) {
  ASSERT_EQ(expected.size(), got.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(expected[k].j, got[k].j) << "neighbour " << k;
    EXPECT_EQ(expected[k].q, got[k].q) << "neighbour " << k;
  }
}

void expect_same_as_plain_filter(const Crowd& c, const Periodic& periodic, float range) {
  const NeighbourArrays n = c.arrays(periodic);
  auto candidates = [&](const auto& fn) { c.visit_active(fn); };
  std::size_t most = 0;
  for (Index self = 0; self < static_cast<Index>(c.position.size()); self += 7) {
    const glm::vec2 p = c.position[static_cast<std::size_t>(self)];
    std::vector<Seen> plain, sifted;
    candidates([&](Index j, glm::vec2) {
      if (j == self) return;
      const glm::vec2 q = n.at(j, p);
      if (length2(q - p) < range * range) plain.push_back({j, q});
    });
    for_each_neighbour(candidates, self, n, p, range * range, [&](Index j, glm::vec2 q) { sifted.push_back({j, q}); });
    SCOPED_TRACE("agent " + std::to_string(self));
    expect_same_seen(plain, sifted);
    most = std::max(most, plain.size());
  }
  // Some agents have more neighbours than one batch holds, so batches are
  // visited mid-way as well as at the end.
  EXPECT_GT(most, static_cast<std::size_t>(2 * kNeighbourBatch));
}

TEST(Sense, NeighbourSiftMatchesThePlainFilter) {
  const Crowd c(2000, 40.0f, 1);  // about 50 active within 4 m
  expect_same_as_plain_filter(c, Periodic{}, 4.0f);
}

TEST(Sense, NeighbourSiftTakesTheImageAcrossTheSeam) {
  const Crowd c(2000, 40.0f, 2);
  const Periodic periodic{{0.0f, 0.0f}, {40.0f, 0.0f}};  // wraps along x
  expect_same_as_plain_filter(c, periodic, 4.0f);
}

// The bins' candidates read from the copy in item order are the crowd's
// active agents of the 3 x 3 cells, in item order, with their positions,
// velocities, radii and flags: element j of the copy is agent id(j).
TEST(Sense, BinnedCandidatesFromTheCopyInItemOrderAreTheCrowdsOwn) {
  Crowd c(2000, 40.0f, 4);
  for (std::size_t i = 0; i < c.position.size(); ++i) {
    c.velocity[i] = glm::vec2(0.01f * static_cast<float>(i % 97), -0.02f * static_cast<float>(i % 13));
    c.radius[i] = 0.15f + 0.001f * static_cast<float>(i % 50);
  }
  AgentGrid bins(4.0f);
  bins.rebuild(Span<const glm::vec2>(c.position), Span<const std::uint8_t>(c.flags));
  const GridView g = bins.view();
  const std::size_t items = static_cast<std::size_t>(g.items.size());
  std::vector<glm::vec2> position(items), velocity(items);
  std::vector<float> radius(items);
  std::vector<std::uint8_t> flags(items);
  std::vector<glm::vec2> crowd_position = c.position, crowd_velocity = c.velocity;
  std::vector<std::uint8_t> crowd_flags = c.flags;
  AgentArrays a;
  a.position = Span<glm::vec2>(crowd_position);
  a.velocity = Span<glm::vec2>(crowd_velocity);
  a.radius = Span<const float>(c.radius);
  a.flags = Span<std::uint8_t>(crowd_flags);
  const BinnedState copy{Span<glm::vec2>(position), Span<glm::vec2>(velocity), Span<float>(radius),
                         Span<std::uint8_t>(flags), Span<AgentAim>()};
  StepContext ctx;
  ctx.bins = g;
  gather_binned_state(ctx, a, {}, copy);  // (no aims: the copy's aim is empty)
  const NeighbourArrays plain = c.arrays(Periodic{});
  const NeighbourArrays copied{Span<const glm::vec2>(position),
                               Span<const glm::vec2>(velocity),
                               Span<const float>(radius),
                               Span<const std::uint8_t>(flags),
                               Periodic{},
                               g.items};
  for (std::size_t i = 0; i < c.position.size(); i += 11) {
    const glm::vec2 p = c.position[i];
    const Cells3x3 cells = cells_3x3(g, g.cell_x(p.x), g.cell_y(p.y));
    std::vector<Seen> from_copy, from_crowd, expected;
    for_each_binned_candidate(g, cells, copied, [&](Index j, glm::vec2 at) {
      const Index agent = copied.id(j);
      const auto k = static_cast<std::size_t>(agent);
      from_copy.push_back({agent, at});
      EXPECT_EQ(copied.velocity[j], c.velocity[k]);
      EXPECT_EQ(copied.radius[j], c.radius[k]);
      EXPECT_EQ(copied.flags[j], c.flags[k]);
    });
    for_each_binned_candidate(g, cells, plain, [&](Index j, glm::vec2 at) {
      EXPECT_EQ(plain.id(j), j);
      from_crowd.push_back({j, at});
    });
    for_each_in_cells(g, cells, [&](std::int32_t j) {
      expected.push_back({j, c.position[static_cast<std::size_t>(j)]});
      EXPECT_NE(c.flags[static_cast<std::size_t>(j)] & kAgentActive, 0);
    });
    expect_same_seen(expected, from_copy);
    expect_same_seen(expected, from_crowd);
  }
}

TEST(Sense, NeighbourSiftOfNoCandidatesVisitsNothing) {
  const Crowd c(10, 5.0f, 3);
  const NeighbourArrays n = c.arrays(Periodic{});
  int visits = 0;
  for_each_neighbour([](const auto&) {}, 0, n, c.position[0], 100.0f, [&](Index, glm::vec2) { ++visits; });
  EXPECT_EQ(visits, 0);
}

// The far look's sift (add_far_anticipation) keeps only candidates whose
// position passes the far push's own tests, so its sum is, bit for bit,
// the sum of cfs_far_push over every candidate in the band, in order.
TEST(Sense, FarLookSiftSumsWhatEveryCandidatePushes) {
  const ModelParams m;
  const float query2 = m.query_radius() * m.query_radius(), reach = cfs_far_reach(m);
  Crowd c(3000, 6.0f * reach, 5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t i = 0; i < c.position.size(); ++i) {
    c.velocity[i] = glm::vec2(1.5f * u(rng), 1.5f * u(rng));
    if (rng() % 7 == 0) c.flags[i] |= kAgentStopped;
  }
  const NeighbourArrays n = c.arrays(Periodic{});
  auto candidates = [&](const auto& fn) { c.visit_active(fn); };
  auto far = [&](glm::vec2, float, const auto& fn) { fn(n, candidates); };
  int pushed = 0;
  for (std::size_t i = 0; i < c.position.size(); i += 5) {
    const float angle = 3.14159265f * u(rng);
    const CfsAgent me{c.position[i], c.velocity[i], c.radius[i], {std::cos(angle), std::sin(angle)}};
    glm::vec2 plain(0.25f, -0.5f), sifted = plain;
    candidates([&](Index j, glm::vec2 q) {
      const auto k = static_cast<std::size_t>(j);
      const float d2 = length2(q - me.p);
      glm::vec2 f;
      if (d2 >= query2 && d2 < reach * reach &&
          cfs_far_push(me, q, c.velocity[k], c.radius[k], (c.flags[k] & kAgentStopped) != 0, m.cfs, f)) {
        plain += f;
        ++pushed;
      }
    });
    add_far_anticipation(me, m, far, sifted);
    EXPECT_EQ(plain, sifted) << "agent " << i;
  }
  EXPECT_GT(pushed, 100);  // the sums are not all of nothing
}

}  // namespace
}  // namespace throng::sim
