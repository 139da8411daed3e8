// Joint LOD, motion cache and locomotion: the per-frame LOD stage for crowds
// of 10^3 to 10^6 characters under an orbiting camera, cache lookups, and the
// whole locomotion frame (the 2019 paper's Figures 10 and 11).
#include <cmath>
#include <random>
#include <vector>

#include "anim/crowd_animator.h"
#include "anim/lod.h"
#include "anim/motion_cache.h"
#include "bench/registry.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "core/exec.h"
#include "motion/roles.h"

namespace throng::bench {

namespace {

using namespace throng::anim;

// A CMU-like humanoid with hands and toes (23 joints).
motion::Skeleton bench_skeleton() {
  motion::Skeleton s;
  const int hips = s.add_joint("Hips", -1, {0, 0, 0});
  for (const char* side : {"Left", "Right"}) {
    const float x = side[0] == 'L' ? 1.0f : -1.0f;
    const std::string n = side;
    const int up = s.add_joint(n + "UpLeg", hips, {0.1f * x, -0.05f, 0});
    const int leg = s.add_joint(n + "Leg", up, {0, -0.42f, 0});
    const int foot = s.add_joint(n + "Foot", leg, {0, -0.42f, 0});
    s.add_joint(n + "ToeBase", foot, {0, -0.05f, 0.12f});
  }
  const int spine = s.add_joint("Spine", hips, {0, 0.1f, 0});
  const int spine1 = s.add_joint("Spine1", spine, {0, 0.15f, 0});
  const int neck = s.add_joint("Neck", spine1, {0, 0.2f, 0});
  s.add_joint("Head", neck, {0, 0.1f, 0});
  for (const char* side : {"Left", "Right"}) {
    const float x = side[0] == 'L' ? 1.0f : -1.0f;
    const std::string n = side;
    const int clavicle = s.add_joint(n + "Shoulder", spine1, {0.05f * x, 0.15f, 0});
    const int arm = s.add_joint(n + "Arm", clavicle, {0.15f * x, 0, 0});
    const int fore = s.add_joint(n + "ForeArm", arm, {0.28f * x, 0, 0});
    const int hand = s.add_joint(n + "Hand", fore, {0.25f * x, 0, 0});
    s.add_joint(n + "HandIndex1", hand, {0.08f * x, 0, 0});
  }
  motion::assign_roles(s);
  return s;
}

constexpr float kSpacing = 1.5f;  // metres between neighbours on the grid

// N characters on a square grid around the origin, random headings.
struct GridCrowd {
  Buffer<glm::vec3> positions;
  Buffer<float> headings;
  float half_extent = 0;
  explicit GridCrowd(Index n) {
    const auto side = static_cast<Index>(std::ceil(std::sqrt(static_cast<double>(n))));
    half_extent = 0.5f * kSpacing * static_cast<float>(side);
    std::vector<glm::vec3> p;
    std::vector<float> h;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f);
    for (Index i = 0; i < n; ++i) {
      p.emplace_back(kSpacing * static_cast<float>(i % side) - half_extent, 0.0f,
                     kSpacing * static_cast<float>(i / side) - half_extent);
      h.push_back(angle(rng));
    }
    positions = Buffer<glm::vec3>(std::span<const glm::vec3>(p), current_memory());
    headings = Buffer<float>(std::span<const float>(h), current_memory());
  }
};

// A 1080p camera circling just outside the crowd, 15 m up, one turn a minute.
Camera orbit_at(float half_extent, float seconds) {
  CameraOrbit o;
  o.radius = half_extent + 20.0f;
  o.height = 15.0f;
  o.angular_speed = 6.2831853f / 60.0f;
  Camera lens;
  lens.width = 1920;
  lens.height = 1080;
  lens.fov_y = 0.87f;
  lens.far_plane = 5000.0f;
  return orbit_camera(o, lens, seconds);
}

void register_anim(const Options& options) {
  const std::vector<Index> sizes = {1000, 10000, 100000, 1000000};

  // The LOD stage as the frame runs it: spheres placed from root transforms.
  add(options, {"anim/lod_from_roots", sizes,
                [](benchmark::State& state, Index n) {
                  const motion::Skeleton skeleton = bench_skeleton();
                  const BodyParts parts = make_body_parts(skeleton);
                  const LodConfig config = make_lod_config(parts, default_lod_thresholds());
                  const LodTables tables(config, current_memory());
                  GridCrowd crowd(n);
                  Buffer<std::uint8_t> levels(n * kBodyPartCount, current_memory());
                  Buffer<std::uint32_t> masks(n * config.mask_words, current_memory());
                  LodJob job;
                  job.set_tables(tables);
                  job.roots.positions = crowd.positions.span();
                  job.roots.headings = crowd.headings.span();
                  job.template_spheres = parts.rest_spheres;
                  job.levels = levels.span();
                  job.joint_masks = masks.span();
                  float t = 0.0f;
                  for (auto _ : state) {
                    job.camera = make_camera_view(orbit_at(crowd.half_extent, t));
                    job.run();
                    finish_device_work();
                    t += 1.0f / 60.0f;
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});

  // The same with world-space spheres given (five vec4 per character read).
  add(options, {"anim/lod_from_spheres", sizes,
                [](benchmark::State& state, Index n) {
                  const motion::Skeleton skeleton = bench_skeleton();
                  const BodyParts parts = make_body_parts(skeleton);
                  const LodConfig config = make_lod_config(parts, default_lod_thresholds());
                  const LodTables tables(config, current_memory());
                  GridCrowd crowd(n);
                  std::vector<glm::vec4> host_spheres;
                  const std::vector<glm::vec3> p = crowd.positions.to_vector();
                  for (const glm::vec3& x : p)
                    for (const glm::vec4& s : parts.rest_spheres) host_spheres.emplace_back(x + glm::vec3(s), s.w);
                  const Buffer<glm::vec4> spheres(std::span<const glm::vec4>(host_spheres), current_memory());
                  Buffer<std::uint8_t> levels(n * kBodyPartCount, current_memory());
                  Buffer<std::uint32_t> masks(n * config.mask_words, current_memory());
                  LodJob job;
                  job.set_tables(tables);
                  job.spheres = spheres.span();
                  job.levels = levels.span();
                  job.joint_masks = masks.span();
                  float t = 0.0f;
                  for (auto _ : state) {
                    job.camera = make_camera_view(orbit_at(crowd.half_extent, t));
                    job.run();
                    finish_device_work();
                    t += 1.0f / 60.0f;
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});

  // The per-frame statistics over the LOD output.
  add(options,
      {"anim/lod_histogram", sizes,
       [](benchmark::State& state, Index n) {
         const motion::Skeleton skeleton = bench_skeleton();
         const BodyParts parts = make_body_parts(skeleton);
         const LodConfig config = make_lod_config(parts, default_lod_thresholds());
         const LodTables tables(config, current_memory());
         GridCrowd crowd(n);
         Buffer<std::uint8_t> levels(n * kBodyPartCount, current_memory());
         Buffer<std::uint32_t> masks(n * config.mask_words, current_memory());
         LodJob job;
         job.set_tables(tables);
         job.camera = make_camera_view(orbit_at(crowd.half_extent, 0.0f));
         job.roots.positions = crowd.positions.span();
         job.roots.headings = crowd.headings.span();
         job.template_spheres = parts.rest_spheres;
         job.levels = levels.span();
         job.joint_masks = masks.span();
         job.run();
         for (auto _ : state) {
           benchmark::DoNotOptimize(lod_histogram(levels.span(), masks.span(), config.level_count, config.joint_count));
           finish_device_work();
         }
         state.SetItemsProcessed(state.iterations() * n);
       },
       true});

  // The 2019 paper's Figures 10 and 11: one frame of locomotion for N
  // characters (speed -> blend, phase, root motion, pose of every joint as
  // world transforms) with full skeletons, + joint LOD under a camera
  // orbiting the crowd, + the motion cache with every character's speed
  // changing every 5 s. The registry runs each on 1 thread (the paper's CPU
  // baseline) and on all threads, and on the GPU when there is one. Feet
  // are locked (anim/foot_lock.h) but in the _unlocked row, its cost.
  struct Variant {
    const char* name;
    bool lod, cache, foot_lock;
  };
  for (const Variant variant :
       {Variant{"anim/locomotion_full", false, false, true},
        Variant{"anim/locomotion_full_unlocked", false, false, false},
        Variant{"anim/locomotion_lod", true, false, true}, Variant{"anim/locomotion_lod_cache", true, true, true}}) {
    add(options, {variant.name,
                  {1000, 5000, 10000, 50000, 100000, 1000000},
                  [variant](benchmark::State& state, Index n) {
                    static const motion::BlendSpace1D space = motion::make_default_blend_space();
                    GridCrowd crowd(n);
                    const std::vector<glm::vec3> positions = crowd.positions.to_vector();
                    const std::vector<float> yaws = crowd.headings.to_vector();
                    CrowdAnimatorConfig config;
                    config.lod = variant.lod;
                    config.cache = variant.cache;
                    config.foot_lock = variant.foot_lock;
                    CrowdAnimator animator(space, n, config);
                    std::mt19937 rng(4);
                    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
                    std::vector<float> phases(static_cast<std::size_t>(n)), speeds(static_cast<std::size_t>(n));
                    for (float& p : phases) p = unit(rng);
                    const auto new_speeds = [&] {
                      for (float& v : speeds) v = space.max_speed() * unit(rng);
                      animator.set_speeds(speeds);
                    };
                    animator.place(positions, yaws, {}, phases);
                    new_speeds();
                    constexpr float kDt = 1.0f / 60.0f;
                    constexpr int kFramesPerSpeed = 300;  // 5 s
                    int frame = 0;
                    const auto step = [&] {
                      if (variant.cache && frame > 0 && frame % kFramesPerSpeed == 0) new_speeds();
                      const Camera cam = orbit_at(crowd.half_extent, static_cast<float>(frame) * kDt);
                      animator.animate({kDt, variant.lod ? &cam : nullptr, true});
                      ++frame;
                    };
                    // Warm up: the cache fills with the cycles these speeds need.
                    step();
                    while (variant.cache && animator.last_frame().cycles_stored > 0) step();
                    for (auto _ : state) {
                      step();
                      finish_device_work();
                    }
                    state.SetItemsProcessed(state.iterations() * n);
                    state.counters["joints_per_character"] =
                        static_cast<double>(animator.last_frame().joints_synthesised) / static_cast<double>(n);
                    state.counters["from_cache"] =
                        static_cast<double>(animator.last_frame().from_cache) / static_cast<double>(n);
                  },
                  true});
  }

  // Cache reads: a bucket lookup plus a SLERP pose at the character's phase.
  add(options, {"anim/motion_cache_sample",
                {1000, 100000},
                [](benchmark::State& state, Index n) {
                  const std::int32_t joints = 31;
                  const auto synthesise = [joints](float w) {
                    CachedCycle c;
                    c.joint_count = joints;
                    c.frame_count = static_cast<std::int32_t>(40.0f - 16.0f * w);
                    c.duration = 1.2f - 0.5f * w;
                    for (std::int32_t f = 0; f < c.frame_count; ++f)
                      for (std::int32_t j = 0; j < joints; ++j)
                        c.rotations.push_back(
                            glm::angleAxis(0.5f * std::sin(0.3f * static_cast<float>(f + j)) * (1.0f + w),
                                           glm::normalize(glm::vec3(1.0f, 0.1f * static_cast<float>(j), 0.3f))));
                    return c;
                  };
                  MotionCache cache;
                  std::mt19937 rng(2);
                  std::uniform_real_distribution<float> u(0.0f, 1.0f);
                  std::vector<float> w(static_cast<std::size_t>(n)), phase(static_cast<std::size_t>(n));
                  for (Index i = 0; i < n; ++i) {
                    w[static_cast<std::size_t>(i)] = u(rng);
                    phase[static_cast<std::size_t>(i)] = u(rng);
                  }
                  std::vector<glm::quat> pose(static_cast<std::size_t>(joints));
                  for (Index i = 0; i < n; ++i) cache.get(w[static_cast<std::size_t>(i)], synthesise);  // warm
                  for (auto _ : state) {
                    for (Index i = 0; i < n; ++i)
                      cache.sample(w[static_cast<std::size_t>(i)], phase[static_cast<std::size_t>(i)], synthesise,
                                   pose);
                    benchmark::DoNotOptimize(pose.data());
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                false,
                true});

  // Cache bucket lookups alone.
  add(options, {"anim/motion_cache_find",
                {1000, 100000},
                [](benchmark::State& state, Index n) {
                  MotionCache cache;
                  for (std::int32_t b = 0; b < cache.bucket_count(); ++b) {
                    CachedCycle c;
                    c.joint_count = 31;
                    c.frame_count = 30;
                    c.duration = 1.0f;
                    c.rotations.assign(30 * 31, glm::quat(1, 0, 0, 0));
                    cache.insert(b, std::move(c));
                  }
                  std::mt19937 rng(3);
                  std::uniform_real_distribution<float> u(0.0f, 1.0f);
                  std::vector<float> w(static_cast<std::size_t>(n));
                  for (float& x : w) x = u(rng);
                  for (auto _ : state)
                    for (float x : w) benchmark::DoNotOptimize(cache.find(x));
                  state.SetItemsProcessed(state.iterations() * n);
                },
                false,
                true});
}

}  // namespace

static const bool registered = register_suite("anim", &register_anim);

}  // namespace throng::bench
