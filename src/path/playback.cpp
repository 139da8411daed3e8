#include "path/playback.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/quaternion.hpp>

#include "core/error.h"
#include "core/ground.h"
#include "motion/phase.h"
#include "sim/geometry.h"

namespace throng::path {

namespace {

struct Item {
  std::int32_t segment;
  glm::vec2 place;  // where the segment's origin goes
  float turn;       // map rotation applied to the clip
  double start, duration;
  std::int32_t curve;  // -1 for the start and end segments
};

// The segments of `sequence` laid end to end along `path`: where each
// segment's origin goes, the turn applied to it and its start (s); `total`
// gets the length of them all (s).
std::vector<Item> lay_out(const MotionGraph& machine, const ResampledPath& path, const Sequence& sequence,
                          double& total) {
  const std::int32_t k = machine.k();
  const auto curves = static_cast<std::int32_t>(sequence.segments.size());
  const auto& segs = machine.segments();
  auto seg_of = [&](std::int32_t id) -> const MotionSegment& { return segs[static_cast<std::size_t>(id)]; };
  std::vector<Item> items;
  double t = 0;
  auto add = [&](std::int32_t seg, glm::vec2 place, float heading, std::int32_t curve) {
    const MotionSegment& m = seg_of(seg);
    items.push_back({seg, place, heading - m.heading, t, m.duration, curve});
    t += m.duration;
  };
  auto heading_of = [](glm::vec2 v) { return std::atan2(v.y, v.x); };
  if (sequence.start_segment >= 0) add(sequence.start_segment, path.points[0], heading_of(path.tangents[0]), -1);
  glm::vec2 end_place = path.points[0];
  float end_heading = heading_of(path.tangents[0]);
  for (std::int32_t c = 0; c < curves; ++c) {
    const auto i = static_cast<std::size_t>(c) * static_cast<std::size_t>(k);
    const float theta = heading_of(path.tangents[i]);
    const MotionSegment& m = seg_of(sequence.segments[static_cast<std::size_t>(c)]);
    add(sequence.segments[static_cast<std::size_t>(c)], path.points[i], theta, c);
    end_place = path.points[i] + rotate_ccw(m.end_point, theta);
    end_heading = theta + m.end_heading;
  }
  if (sequence.end_segment >= 0) add(sequence.end_segment, end_place, end_heading, -1);
  total = t;
  return items;
}

// Distance (m) from ground point g to the path's polyline around curve
// `curve` (k points a curve, the curves either side included).
double deviation(const ResampledPath& path, std::int32_t k, std::int32_t curve, glm::vec2 g) {
  const std::int64_t lo = std::max<std::int64_t>(0, (static_cast<std::int64_t>(curve) - 1) * k);
  const std::int64_t hi = std::min<std::int64_t>(static_cast<std::int64_t>(path.points.size()) - 1,
                                                 (static_cast<std::int64_t>(curve) + 2) * k);
  double d = INFINITY;
  for (std::int64_t i = lo; i < hi; ++i)
    d = std::min(d, static_cast<double>(sim::distance_to_segment(g, path.points[static_cast<std::size_t>(i)],
                                                                 path.points[static_cast<std::size_t>(i) + 1])));
  if (hi <= lo) d = sim::length_of(g - path.points[static_cast<std::size_t>(lo)]);
  return d;
}

}  // namespace

Playback play(const MotionGraph& machine, const ResampledPath& path, const Sequence& sequence) {
  const std::int32_t k = machine.k();
  const auto curves = static_cast<std::int32_t>(sequence.segments.size());
  if (static_cast<std::size_t>(curves) * static_cast<std::size_t>(k) > path.points.size())
    throw Error("the sequence has more curves than the path", at_field("playback.sequence"));
  if (path.points.empty()) throw Error("empty path", at_field("playback.path"));
  const auto& segs = machine.segments();
  auto seg_of = [&](std::int32_t id) -> const MotionSegment& { return segs[static_cast<std::size_t>(id)]; };
  double t = 0;
  const std::vector<Item> items = lay_out(machine, path, sequence, t);
  if (items.empty()) throw Error("nothing to play: no segments", at_field("playback.sequence"));

  const double fps = machine.spec().fps;
  const double blend = machine.spec().transition_frames / fps;
  const auto frames = static_cast<std::int32_t>(std::floor(t * fps)) + 1;
  const std::int32_t J = machine.skeleton().joint_count();
  Playback out;
  out.clip.resize(frames, J);
  out.clip.frame_time = static_cast<float>(1.0 / fps);
  out.root_ground.resize(static_cast<std::size_t>(frames));

  std::vector<glm::quat> ra, rb;
  glm::vec3 root_a, root_b;
  auto placed = [&](const Item& it, double u, std::vector<glm::quat>& rot, glm::vec3& root) {
    machine.pose(it.segment, u, rot, root);
    const MotionSegment& m = seg_of(it.segment);
    const glm::vec2 g = it.place + rotate_ccw(ground_from_world(root) - m.origin, it.turn);
    root = world_from_ground(g, root.y);
    rot[0] = glm::angleAxis(it.turn, glm::vec3(0, 1, 0)) * rot[0];
  };
  std::size_t cur = 0;
  double dev_sum = 0;
  out.first_matched_frame = -1;
  for (std::int32_t f = 0; f < frames; ++f) {
    const double tau = f / fps;
    while (cur + 1 < items.size() && tau >= items[cur + 1].start) ++cur;
    const Item& it = items[cur];
    placed(it, tau - it.start, ra, root_a);
    // Blend across the nearest boundary when within half the blend of it.
    const Item* other = nullptr;
    double w = 0;
    if (cur + 1 < items.size() && tau > items[cur + 1].start - 0.5 * blend) {
      other = &items[cur + 1];
      w = (tau - (other->start - 0.5 * blend)) / blend;
    } else if (cur > 0 && tau < it.start + 0.5 * blend) {
      other = &items[cur - 1];
      w = 1.0 - (tau - (it.start - 0.5 * blend)) / blend;
    }
    if (other != nullptr && blend > 0) {
      w = std::clamp(w, 0.0, 1.0);
      w = w * w * (3 - 2 * w);
      placed(*other, tau - other->start, rb, root_b);
      const auto wf = static_cast<float>(w);
      root_a = glm::mix(root_a, root_b, wf);
      const motion::SlerpAt blend_at(wf);
      for (std::size_t j = 0; j < ra.size(); ++j) ra[j] = blend_at(ra[j], rb[j]);
    }
    for (std::int32_t j = 0; j < J; ++j) out.clip.rotation(f, j) = ra[static_cast<std::size_t>(j)];
    out.clip.root_positions[static_cast<std::size_t>(f)] = root_a;
    const glm::vec2 g = ground_from_world(root_a);
    out.root_ground[static_cast<std::size_t>(f)] = g;
    if (it.curve >= 0) {
      if (out.first_matched_frame < 0) out.first_matched_frame = f;
      ++out.matched_frames;
      const double d = deviation(path, k, it.curve, g);
      dev_sum += d;
      out.deviation_max = std::max(out.deviation_max, d);
    }
  }
  if (out.first_matched_frame < 0) out.first_matched_frame = 0;
  out.deviation_mean = out.matched_frames > 0 ? dev_sum / out.matched_frames : 0.0;
  return out;
}

}  // namespace throng::path
