#include <gtest/gtest.h>

#include "core/camera.h"
#include "render/demo_crowd.h"
#include "render/framebuffer.h"
#include "render/headless.h"
#include "render/image.h"
#include "render/renderer.h"

namespace throng::render {
namespace {

TEST(Renderer, Smoke) {
  HeadlessContext gl;
  std::printf("%s\n", gl.description().c_str());
  DemoCrowdSpec spec;
  spec.characters = 30;
  DemoCrowd crowd(spec);
  Renderer renderer(make_joint_rig(crowd.skeleton()));
  std::vector<sim::Polygon> polys(1);
  polys[0].outer = {{8, 8}, {12, 8}, {12, 12}, {8, 12}};
  polys[0].holes = {{{9, 9}, {11, 9}, {11, 11}, {9, 11}}};
  std::vector<sim::Circle> circles = {{{-9, 5}, 1.5f}};
  renderer.set_obstacles(polys, circles);
  Camera cam;
  cam.width = 640;
  cam.height = 360;
  cam.position = {0, 8, 20};
  cam.target = {0, 0.5f, 0};
  OffscreenTarget target(cam.width, cam.height);
  target.bind();
  RenderOptions o;
  const RenderStats s = renderer.render(cam, crowd.poses(), o);
  std::printf("visible %ld fine %ld tris %ld\n", long(s.visible), long(s.fine), long(s.triangles));
  write_png("/tmp/render_smoke.png", target.read());
}

}  // namespace
}  // namespace throng::render
