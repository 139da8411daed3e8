// The renderer: one frame of N characters at 1280x720 with 4x multisampling,
// under an orbiting camera that frames the whole crowd: cull, pack, upload,
// draw and wait for the picture (glFinish), on whatever OpenGL the headless
// context finds (Mesa llvmpipe on a CPU-only machine, the GPU's driver where
// there is one). Characters stand on a grid, posed by the locomotion stage
// (anim::CrowdAnimator: speeds 0.8-2.4 m/s, joint LOD for the camera, motion
// cache), drawn in joint mode (a sphere per bone) or skinned mode (the
// mannequin, palettes from the world joint frames). And the CPU stages alone.
#include <memory>
#include <random>

#include "anim/crowd_animator.h"
#include "bench/registry.h"
#include "core/exec.h"
#include "core/buffer.h"
#include "core/reduce.h"
#include "render/camera_path.h"
#include "render/cull.h"
#include "render/framebuffer.h"
#include "render/headless.h"
#include "render/renderer.h"

namespace throng::bench {

namespace {

using namespace throng::render;

// One context for the process: creating EGL contexts over and over is slow.
HeadlessContext& context() {
  static std::unique_ptr<HeadlessContext> gl = std::make_unique<HeadlessContext>();
  gl->make_current();
  return *gl;
}

const motion::BlendSpace1D& blend_space() {
  static const motion::BlendSpace1D space = motion::make_default_blend_space();
  return space;
}

// N characters 1.5 m apart on a square grid, walking and running, posed once.
struct Scene {
  anim::CrowdAnimator crowd;
  CameraPath path;
  explicit Scene(Index n) : crowd(blend_space(), n) {
    const auto side = static_cast<Index>(std::ceil(std::sqrt(static_cast<double>(n))));
    const float spacing = 1.5f, half = 0.5f * spacing * static_cast<float>(side - 1);
    std::vector<glm::vec3> positions;
    std::vector<float> yaws, phases, speeds;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (Index i = 0; i < n; ++i) {
      positions.emplace_back(spacing * static_cast<float>(i % side) - half, 0.0f,
                             spacing * static_cast<float>(i / side) - half);
      yaws.push_back(6.2831853f * unit(rng));
      phases.push_back(unit(rng));
      speeds.push_back(0.8f + 1.6f * unit(rng));
    }
    crowd.place(positions, yaws, {}, phases);
    crowd.set_speeds(speeds);
    Camera lens;
    lens.width = 1280;
    lens.height = 720;
    lens.far_plane = 5000.0f;
    path = framing_orbit(glm::vec3(0.0f), half * 1.4142f, lens, 60.0f);
    const Camera camera = path.at(0.0);
    crowd.animate({1.0f / 30.0f, &camera, true});
  }
};

void frame_case(benchmark::State& state, Index n, RenderMode mode) {
  HeadlessContext& gl = context();
  state.SetLabel(gl.software() ? "mesa-llvmpipe" : "gpu");
  Scene scene(n);
  Renderer renderer(make_crowd_rigs(blend_space().skeleton()));
  OffscreenTarget target(1280, 720, 4);
  target.bind();
  RenderOptions look;
  look.mode = mode;
  const CharacterPoses poses = poses_of(scene.crowd);
  double t = 0.0;
  Index visible = 0, triangles = 0;
  for (auto _ : state) {
    const RenderStats s = renderer.render(scene.path.at(t), poses, look);
    glFinish();
    visible += s.visible;
    triangles += s.triangles;
    t += 1.0 / 30.0;
  }
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["visible"] = static_cast<double>(visible) / iterations;
  state.counters["triangles"] = static_cast<double>(triangles) / iterations;
  state.SetItemsProcessed(state.iterations() * n);
}

void register_render(const Options& options) {
  const std::vector<Index> sizes = {1000, 10000, 100000};

  add(options, {"render/joints_frame", sizes,
                [](benchmark::State& state, Index n) { frame_case(state, n, RenderMode::Joints); }});
  add(options, {"render/skinned_frame", sizes,
                [](benchmark::State& state, Index n) { frame_case(state, n, RenderMode::Skinned); }});

  // The CPU stages alone (cull, slots, pack into host arrays), no OpenGL.
  add(options, {"render/joints_prepare", sizes,
                [](benchmark::State& state, Index n) {
                  Scene scene(n);
                  const JointRig rig = make_joint_rig(blend_space().skeleton());
                  const Buffer<RigPoint> points(std::span<const RigPoint>(rig.points), current_memory());
                  Buffer<std::uint32_t> flags(kDrawTiers * n, current_memory()),
                      slots(kDrawTiers * n, current_memory());
                  Buffer<glm::vec4> packed(n * rig.point_count(), current_memory());
                  const CharacterPoses poses = poses_of(scene.crowd);
                  double t = 0.0;
                  for (auto _ : state) {
                    CullJob cull;
                    cull.camera = make_camera_view(scene.path.at(t));
                    cull.rigs.rig[0] = {rig.bounding_radius, glm::vec3(0.0f), rig.joint_count};
                    cull.joint_count = rig.joint_count;
                    cull.joint_positions = poses.joint_positions;
                    cull.group_flags = flags.span();
                    cull.run();
                    const Index visible = scan_draw_slots(flags.span(), slots.span());
                    PackJob pack;
                    pack.joint_count = rig.joint_count;
                    pack.points = points.span();
                    pack.joint_positions = poses.joint_positions;
                    pack.joint_rotations = poses.joint_rotations;
                    pack.lod_levels = poses.lod_levels;
                    pack.group_flags = flags.span();
                    pack.slots = slots.span();
                    pack.out_points = packed.span().subspan(0, visible * rig.point_count());
                    pack.run();
                    finish_device_work();
                    t += 1.0 / 30.0;
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});

  add(options,
      {"render/skinned_prepare", sizes,
       [](benchmark::State& state, Index n) {
         Scene scene(n);
         const CrowdRigs rigs = make_crowd_rigs(blend_space().skeleton());
         const SkinRig& skin = rigs.skins.front();
         const Buffer<anim::Mat3x4> inverse_bind(std::span<const anim::Mat3x4>(skin.inverse_bind), current_memory());
         Buffer<std::uint32_t> flags(kDrawTiers * n, current_memory()), slots(kDrawTiers * n, current_memory());
         Buffer<anim::Mat3x4> palettes(n * skin.joint_count, current_memory());
         Buffer<glm::uvec2> tags(n, current_memory());
         const CharacterPoses poses = poses_of(scene.crowd);
         double t = 0.0;
         for (auto _ : state) {
           CullJob cull;
           cull.camera = make_camera_view(scene.path.at(t));
           cull.rigs.rig[0] = {skin.bounding_radius, skin.bind_positions.front(), skin.joint_count};
           cull.joint_count = poses.joint_count;
           cull.joint_positions = poses.joint_positions;
           cull.scales = poses.scales;
           cull.group_flags = flags.span();
           cull.run();
           const Index visible = scan_draw_slots(flags.span(), slots.span());
           PalettePackJob pack;
           pack.groups = draw_groups(cull, slots.span(), visible);
           pack.joint_count = poses.joint_count;
           pack.joint_positions = poses.joint_positions;
           pack.joint_rotations = poses.joint_rotations;
           pack.scales = poses.scales;
           pack.inverse_bind = inverse_bind.span();
           pack.lod_levels = poses.lod_levels;
           pack.group_flags = flags.span();
           pack.slots = slots.span();
           pack.out_palettes = palettes.span().subspan(0, pack.groups.matrices());
           pack.out_tags = tags.span().subspan(0, pack.groups.visible());
           pack.run();
           finish_device_work();
           t += 1.0 / 30.0;
         }
         state.SetItemsProcessed(state.iterations() * n);
       },
       true});
}

const bool registered = register_suite("render", &register_render);

}  // namespace
}  // namespace throng::bench
