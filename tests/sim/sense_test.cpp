// The sense stage's neighbour sift (for_each_neighbour, sim/sense.h): the
// same neighbours, at the same images, in the same order as a plain filter
// that branches on each candidate; every model's sum relies on that order
// for its bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "sim/sense.h"

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
  NeighbourArrays arrays(const Periodic& periodic) const {
    return {Span<const glm::vec2>(position), Span<const glm::vec2>(velocity), Span<const float>(radius),
            Span<const std::uint8_t>(flags), periodic};
  }
};

void expect_same_as_plain_filter(const Crowd& c, const Periodic& periodic, float range) {
  const NeighbourArrays n = c.arrays(periodic);
  auto candidates = [&](const auto& fn) {
    for (Index j : c.order) fn(j);
  };
  std::size_t most = 0;
  for (Index self = 0; self < static_cast<Index>(c.position.size()); self += 7) {
    const glm::vec2 p = c.position[static_cast<std::size_t>(self)];
    std::vector<Seen> plain, sifted;
    candidates([&](Index j) {
      if (j == self || (n.flags[j] & kAgentActive) == 0) return;
      const glm::vec2 q = n.at(j, p);
      if (length2(q - p) < range * range) plain.push_back({j, q});
    });
    for_each_neighbour(candidates, self, n, p, range * range, [&](Index j, glm::vec2 q) { sifted.push_back({j, q}); });
    ASSERT_EQ(plain.size(), sifted.size()) << "agent " << self;
    for (std::size_t k = 0; k < plain.size(); ++k) {
      EXPECT_EQ(plain[k].j, sifted[k].j) << "agent " << self << ", neighbour " << k;
      EXPECT_EQ(plain[k].q, sifted[k].q) << "agent " << self << ", neighbour " << k;
    }
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

TEST(Sense, NeighbourSiftOfNoCandidatesVisitsNothing) {
  const Crowd c(10, 5.0f, 3);
  const NeighbourArrays n = c.arrays(Periodic{});
  int visits = 0;
  for_each_neighbour([](const auto&) {}, 0, n, c.position[0], 100.0f, [&](Index, glm::vec2) { ++visits; });
  EXPECT_EQ(visits, 0);
}

}  // namespace
}  // namespace throng::sim
