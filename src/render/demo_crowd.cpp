#include "render/demo_crowd.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "anim/lod.h"
#include "core/error.h"
#include "core/ground.h"
#include "motion/default_set.h"
#include "render/demo_crowd_kernels.h"

namespace throng::render {

const char* to_string(DemoLayout l) { return l == DemoLayout::Grid ? "grid" : "ring"; }

DemoLayout parse_demo_layout(const std::string& text, const std::string& field) {
  if (text == "grid") return DemoLayout::Grid;
  if (text == "ring") return DemoLayout::Ring;
  throw Error(fmt::format("unknown layout '{}' (grid or ring)", text), at_field(field));
}

void DemoCrowdSpec::validate() const {
  if (characters < 0 || characters > (Index{1} << 24))
    throw Error(fmt::format("{} is outside 0..{}", characters, Index{1} << 24), at_field("demo.characters"));
  if (!(spacing >= 0.5f && spacing <= 100.0f)) throw Error("must be within 0.5..100 metres", at_field("demo.spacing"));
  if (!(idle_fraction >= 0.0f && idle_fraction <= 1.0f)) throw Error("must be within 0..1", at_field("demo.idle_fraction"));
}

struct DemoCrowd::State {
  DemoCrowdSpec spec;
  motion::Skeleton skeleton;
  std::int32_t J = 0;
  // Per clip, as the pose stage reads it.
  struct ClipData {
    Buffer<glm::quat> rotations;  // frames * J
    Buffer<glm::vec3> roots;      // frames: the root with the clip's forward travel removed
    std::int32_t frames = 0;
    float duration = 1.0f;
    float speed = 0.0f;
    Index first = 0, count = 0;   // its characters (contiguous)
  };
  std::vector<ClipData> clips;
  Buffer<std::int32_t> parents;
  Buffer<glm::vec3> offsets;
  DemoPlacement placement;  // per character, in current_memory()
  Buffer<float> phase_offset, phases, speeds, yaw0, radius, angle0;
  Buffer<glm::vec3> base, ground, model_roots, positions;
  Buffer<float> yaws;
  Buffer<glm::quat> rotations;
  Buffer<std::uint32_t> all_joints;
  Buffer<std::int32_t> evaluated;
  glm::vec3 centre{0.0f};
  float extent = 1.0f;
};

DemoCrowd::DemoCrowd(const DemoCrowdSpec& spec) : s_(std::make_unique<State>()) {
  spec.validate();
  State& s = *s_;
  s.spec = spec;
  s.skeleton = motion::default_skeleton();
  s.J = s.skeleton.joint_count();
  const Memory memory = current_memory();
  s.parents = Buffer<std::int32_t>(std::span<const std::int32_t>(s.skeleton.parents), memory);
  s.offsets = Buffer<glm::vec3>(std::span<const glm::vec3>(s.skeleton.offsets), memory);

  // Clips that go straight or stand: idle, then walks and runs.
  std::vector<motion::DefaultMotion> motions = motion::make_default_motions(s.skeleton);
  std::vector<const motion::DefaultMotion*> moving;
  const motion::DefaultMotion* idle = nullptr;
  for (const motion::DefaultMotion& m : motions) {
    if (m.spec.turn_rate != 0.0) continue;
    if (m.spec.gait == motion::biomech::Gait::Stand)
      idle = &m;
    else
      moving.push_back(&m);
  }
  std::vector<const motion::DefaultMotion*> used;
  if (idle != nullptr) used.push_back(idle);
  used.insert(used.end(), moving.begin(), moving.end());

  // Characters per clip: idle_fraction idle, the rest spread over the
  // moving clips, walks twice as common as runs.
  const Index n = spec.characters;
  std::vector<double> weight;
  for (const auto* m : used)
    weight.push_back(m == idle ? spec.idle_fraction : (1.0 - spec.idle_fraction) * (m->spec.gait == motion::biomech::Gait::Run ? 1.0 : 2.0));
  const double total_weight = std::accumulate(weight.begin(), weight.end(), 0.0);
  Index first = 0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    const motion::Clip& clip = used[k]->clip;
    State::ClipData d;
    d.frames = clip.frame_count;
    d.duration = clip.duration();
    d.speed = static_cast<float>(used[k]->spec.speed);
    // Root with the forward travel (+Z at the clip's speed) taken out: the
    // placement moves the character instead, so the cycle loops in place.
    std::vector<glm::vec3> roots(static_cast<std::size_t>(clip.frame_count));
    for (std::int32_t f = 0; f < clip.frame_count; ++f) {
      glm::vec3 r = clip.root_positions[static_cast<std::size_t>(f)] - clip.root_positions[0];
      r.z -= d.speed * clip.frame_time * static_cast<float>(f);
      r.y = clip.root_positions[static_cast<std::size_t>(f)].y;
      roots[static_cast<std::size_t>(f)] = r;
    }
    d.rotations = Buffer<glm::quat>(std::span<const glm::quat>(clip.rotations), memory);
    d.roots = Buffer<glm::vec3>(std::span<const glm::vec3>(roots), memory);
    d.first = first;
    d.count = k + 1 == used.size() ? n - first : static_cast<Index>(std::floor(static_cast<double>(n) * weight[k] / total_weight));
    first += d.count;
    s.clips.push_back(std::move(d));
  }

  // Places: grid cells or ring seats, shuffled so clips mix in space.
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec2> seat(static_cast<std::size_t>(n));   // map position
  std::vector<float> seat_radius(static_cast<std::size_t>(n), 0.0f), seat_angle(static_cast<std::size_t>(n), 0.0f);
  float extent = spec.spacing;
  if (spec.layout == DemoLayout::Grid) {
    const Index side = std::max<Index>(1, static_cast<Index>(std::ceil(std::sqrt(static_cast<double>(n)))));
    const float half = 0.5f * spec.spacing * static_cast<float>(side);
    for (Index i = 0; i < n; ++i)
      seat[static_cast<std::size_t>(i)] =
          glm::vec2(spec.spacing * (static_cast<float>(i % side) + 0.5f) - half, spec.spacing * (static_cast<float>(i / side) + 0.5f) - half);
    extent = half * 1.4142f;
  } else {
    // Rings 1.5 spacings apart, seats about one spacing apart along each.
    Index placed = 0;
    for (int ring = 1; placed < n; ++ring) {
      const float r = 1.5f * spec.spacing * static_cast<float>(ring);
      const Index seats = std::min<Index>(n - placed, std::max<Index>(1, static_cast<Index>(6.2831853f * r / spec.spacing)));
      for (Index k = 0; k < seats; ++k, ++placed) {
        const float a = 6.2831853f * (static_cast<float>(k) + 0.5f * static_cast<float>(ring % 2)) / static_cast<float>(seats);
        seat_radius[static_cast<std::size_t>(placed)] = r;
        seat_angle[static_cast<std::size_t>(placed)] = a;
        seat[static_cast<std::size_t>(placed)] = r * glm::vec2(std::cos(a), std::sin(a));
      }
      extent = r;
    }
  }
  std::vector<Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), Index{0});
  std::shuffle(order.begin(), order.end(), rng);

  std::vector<float> phase_offset(static_cast<std::size_t>(n)), speeds(static_cast<std::size_t>(n)), yaw0(static_cast<std::size_t>(n)),
      radius(static_cast<std::size_t>(n)), angle0(static_cast<std::size_t>(n)), clip_duration(static_cast<std::size_t>(n));
  std::vector<glm::vec3> base(static_cast<std::size_t>(n));
  for (const State::ClipData& d : s.clips)
    for (Index c = d.first; c < d.first + d.count; ++c) {
      const auto i = static_cast<std::size_t>(c);
      const auto at = static_cast<std::size_t>(order[i]);
      phase_offset[i] = unit(rng) * d.duration;
      clip_duration[i] = d.duration;
      speeds[i] = d.speed;
      base[i] = world_from_ground(seat[at]);
      radius[i] = seat_radius[at];
      angle0[i] = seat_angle[at];
      // Grid walkers go along one of the four axes; ring walkers counter-clockwise.
      yaw0[i] = spec.layout == DemoLayout::Grid ? kHalfPi * static_cast<float>(static_cast<int>(unit(rng) * 4.0f) % 4) : 0.0f;
    }
  s.phase_offset = Buffer<float>(std::span<const float>(phase_offset), memory);
  s.speeds = Buffer<float>(std::span<const float>(speeds), memory);
  s.yaw0 = Buffer<float>(std::span<const float>(yaw0), memory);
  s.radius = Buffer<float>(std::span<const float>(radius), memory);
  s.angle0 = Buffer<float>(std::span<const float>(angle0), memory);
  s.base = Buffer<glm::vec3>(std::span<const glm::vec3>(base), memory);
  s.phases = Buffer<float>(n, memory);
  s.ground = Buffer<glm::vec3>(n, memory);
  s.yaws = Buffer<float>(n, memory);
  s.model_roots = Buffer<glm::vec3>(n, memory);
  s.positions = Buffer<glm::vec3>(n * s.J, memory);
  s.rotations = Buffer<glm::quat>(n * s.J, memory);
  s.evaluated = Buffer<std::int32_t>(n, memory);
  const std::int32_t words = anim::mask_word_count(s.J);
  std::vector<std::uint32_t> ones(static_cast<std::size_t>(n * words), 0xffffffffu);
  s.all_joints = Buffer<std::uint32_t>(std::span<const std::uint32_t>(ones), memory);
  s.centre = glm::vec3(0.0f);
  s.extent = extent + spec.spacing;
  // Grid walkers wrap round a square of this side.
  s.placement.grid_side = spec.layout == DemoLayout::Grid
                              ? spec.spacing * static_cast<float>(std::max<Index>(1, static_cast<Index>(std::ceil(std::sqrt(static_cast<double>(n))))))
                              : 0.0f;
  update(0.0);
}

DemoCrowd::~DemoCrowd() = default;
DemoCrowd::DemoCrowd(DemoCrowd&&) noexcept = default;
DemoCrowd& DemoCrowd::operator=(DemoCrowd&&) noexcept = default;

const DemoCrowdSpec& DemoCrowd::spec() const { return s_->spec; }
const motion::Skeleton& DemoCrowd::skeleton() const { return s_->skeleton; }
Index DemoCrowd::character_count() const { return s_->spec.characters; }
std::int32_t DemoCrowd::joint_count() const { return s_->J; }
Span<const glm::vec3> DemoCrowd::ground_positions() const { return s_->ground.span(); }
Span<const float> DemoCrowd::yaws() const { return s_->yaws.span(); }
glm::vec3 DemoCrowd::centre() const { return s_->centre; }
float DemoCrowd::extent() const { return s_->extent; }

void DemoCrowd::update(double seconds, Span<const std::uint32_t> joint_masks) {
  State& s = *s_;
  const Index n = character_count();
  const std::int32_t words = anim::mask_word_count(s.J);
  if (!joint_masks.empty() && joint_masks.size() != n * words)
    throw Error(fmt::format("{} mask words for {} characters of {} words", joint_masks.size(), n, words), at_field("demo.joint_masks"));
  if (!std::isfinite(seconds)) throw Error("time must be finite", at_field("demo.seconds"));
  const Span<const std::uint32_t> masks = joint_masks.empty() ? Span<const std::uint32_t>(s.all_joints.span()) : joint_masks;
  for (const State::ClipData& d : s.clips) {
    if (d.count == 0) continue;
    DemoPlacement p = s.placement;
    p.seconds = seconds;
    p.clip_duration = d.duration;
    p.clip_frames = d.frames;
    p.clip_roots = d.roots.span();
    p.phase_offset = s.phase_offset.span().subspan(d.first, d.count);
    p.speed = s.speeds.span().subspan(d.first, d.count);
    p.yaw0 = s.yaw0.span().subspan(d.first, d.count);
    p.radius = s.radius.span().subspan(d.first, d.count);
    p.angle0 = s.angle0.span().subspan(d.first, d.count);
    p.base = s.base.span().subspan(d.first, d.count);
    p.phases = s.phases.span().subspan(d.first, d.count);
    p.model_roots = s.model_roots.span().subspan(d.first, d.count);
    p.ground = s.ground.span().subspan(d.first, d.count);
    p.yaws = s.yaws.span().subspan(d.first, d.count);
    p.ring = s.spec.layout == DemoLayout::Ring;
    demo_roots(p);

    DemoPose pose;
    pose.joint_count = s.J;
    pose.frame_count = d.frames;
    pose.parents = s.parents.span();
    pose.offsets = s.offsets.span();
    pose.clip_rotations = d.rotations.span();
    pose.phases = p.phases;
    pose.root_positions = p.model_roots;
    pose.joint_masks = masks.subspan(d.first * words, d.count * words);
    pose.out_positions = s.positions.span().subspan(d.first * s.J, d.count * s.J);
    pose.out_rotations = s.rotations.span().subspan(d.first * s.J, d.count * s.J);
    pose.evaluated = s.evaluated.span().subspan(d.first, d.count);
    demo_pose(pose);
  }
  demo_place(s.J, s.ground.span(), s.yaws.span(), s.positions.span(), s.rotations.span());
}

CharacterPoses DemoCrowd::poses() const {
  CharacterPoses p;
  p.joint_count = s_->J;
  p.joint_positions = s_->positions.span();
  p.joint_rotations = s_->rotations.span();
  return p;
}

}  // namespace throng::render
