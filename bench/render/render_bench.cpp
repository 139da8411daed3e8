// The renderer: one frame of N characters in joint mode, at 1280x720 with
// 4x multisampling, under an orbiting camera that frames the whole crowd:
// cull, pack, upload, draw and wait for the picture (glFinish), on whatever
// OpenGL the headless context finds (Mesa llvmpipe on a CPU-only machine,
// the GPU's driver where there is one). And the CPU stages alone.
#include <memory>

#include "bench/registry.h"
#include "core/buffer.h"
#include "core/reduce.h"
#include "render/cull.h"
#include "render/camera_path.h"
#include "render/demo_crowd.h"
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

struct Scene {
  DemoCrowd crowd;
  CameraPath path;
  explicit Scene(Index n) : crowd(spec(n)) {
    Camera lens;
    lens.width = 1280;
    lens.height = 720;
    lens.far_plane = 5000.0f;
    path = framing_orbit(crowd.centre(), crowd.extent(), lens, 60.0f);
  }
  static DemoCrowdSpec spec(Index n) {
    DemoCrowdSpec s;
    s.characters = n;
    s.layout = DemoLayout::Grid;
    return s;
  }
};

void register_render(const Options& options) {
  const std::vector<Index> sizes = {1000, 10000, 100000};

  add(options, {"render/joints_frame", sizes, [](benchmark::State& state, Index n) {
                  HeadlessContext& gl = context();
                  state.SetLabel(gl.software() ? "mesa-llvmpipe" : "gpu");
                  Scene scene(n);
                  Renderer renderer(make_joint_rig(scene.crowd.skeleton()));
                  OffscreenTarget target(1280, 720, 4);
                  target.bind();
                  const RenderOptions look;
                  double t = 0.0;
                  Index visible = 0;
                  for (auto _ : state) {
                    const RenderStats s = renderer.render(scene.path.at(t), scene.crowd.poses(), look);
                    glFinish();
                    visible += s.visible;
                    t += 1.0 / 30.0;
                  }
                  state.counters["visible"] = static_cast<double>(visible) / static_cast<double>(state.iterations());
                  state.SetItemsProcessed(state.iterations() * n);
                }});

  // The CPU stages alone (cull, slots, pack into a host array), no OpenGL.
  add(options, {"render/joints_prepare", sizes, [](benchmark::State& state, Index n) {
                  Scene scene(n);
                  const JointRig rig = make_joint_rig(scene.crowd.skeleton());
                  const Buffer<RigPoint> points(std::span<const RigPoint>(rig.points), current_memory());
                  Buffer<std::uint32_t> flags(kDrawTiers * n, current_memory()), slots(kDrawTiers * n, current_memory());
                  Buffer<glm::vec4> packed(n * rig.point_count(), current_memory());
                  const CharacterPoses poses = scene.crowd.poses();
                  double t = 0.0;
                  for (auto _ : state) {
                    CullJob cull;
                    cull.camera = make_camera_view(scene.path.at(t));
                    cull.joint_count = rig.joint_count;
                    cull.bounding_radius = rig.bounding_radius;
                    cull.joint_positions = poses.joint_positions;
                    cull.tier_flags = flags.span();
                    cull.run();
                    const Index visible = exclusive_scan<std::uint32_t>("render.slots", flags.span(), slots.span());
                    PackJob pack;
                    pack.joint_count = rig.joint_count;
                    pack.points = points.span();
                    pack.joint_positions = poses.joint_positions;
                    pack.joint_rotations = poses.joint_rotations;
                    pack.tier_flags = flags.span();
                    pack.slots = slots.span();
                    pack.out_points = packed.span().subspan(0, visible * rig.point_count());
                    pack.run();
                    t += 1.0 / 30.0;
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});
}

const bool registered = register_suite("render", &register_render);

}  // namespace
}  // namespace throng::bench
