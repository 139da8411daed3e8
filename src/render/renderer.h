// The crowd renderer (OpenGL 4.3 core): instanced joint ellipsoids or
// skinned meshes fed from shader storage buffers, the ground with a metre
// grid, extruded obstacles, and optional overlays (planned paths, simulation
// bins as a heat map).
//
// It draws into whatever framebuffer is bound (an OffscreenTarget or the
// viewer's window) with the viewport camera.width x camera.height; the
// camera is core/camera.h's, the same one that drives the joint LOD.
//
//   HeadlessContext gl;                          // or a window's context
//   OffscreenTarget target(640, 360);
//   Renderer renderer(make_crowd_rigs(skeleton)); // joint rig + mannequin
//   renderer.set_obstacles(world.polygons(), world.circles());
//   target.bind();
//   RenderStats s = renderer.render(camera, poses, options);
//   write_png("frame.png", target.read());
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <memory>
#include <vector>

#include "core/camera.h"
#include "render/cull.h"
#include "render/scene.h"
#include "sim/geometry.h"

namespace throng::render {

// The colours of the map's paths (the walkable boundary), of agents'
// routes (`--routes`) and of the navigation fields' lines of equal walking
// distance (`--field-lines`), drawn just above the ground.
inline const glm::vec4 kPathColour(0.95f, 0.95f, 0.25f, 1.0f);
inline const glm::vec4 kRouteColour(0.2f, 0.85f, 0.95f, 1.0f);
inline const glm::vec4 kFieldColour(0.85f, 0.45f, 0.9f, 1.0f);

struct RenderOptions {
  RenderMode mode = RenderMode::Joints;
  bool lod_colours = false;  // colour by joint-LOD level (paper Fig. 8, a debug view); else by character
  bool ground = true;
  bool grid = true;
  bool obstacles = true;
  bool paths = true;  // when set_paths or set_routes gave any
  bool bins = false;  // when set_bins gave any
  bool cull = true;   // skip characters whose bounding sphere is outside the view
  // Characters whose bounding sphere is at least this many pixels in
  // radius get the finer sphere mesh (joint mode) or the rig's own mesh
  // (skinned mode).
  float fine_min_pixels = 16.0f;
  // Characters whose bounding sphere is below this many pixels in radius
  // (a person under about 6 pixels tall) are drawn as one line per bone.
  float lines_max_pixels = 3.0f;
  glm::vec3 background{0.70f, 0.78f, 0.86f};
  // Distance (metres) at which everything has faded into the background;
  // 0 = the camera's far plane.
  float fog_distance = 0.0f;
  void validate() const;  // Error naming the field
};

struct RenderStats {
  Index characters = 0;
  Index visible = 0;      // after culling
  Index fine = 0;         // of them with the fine mesh
  Index lines = 0;        // of them as lines
  Index instances = 0;    // ellipsoids (joint mode) or meshes (skinned mode) drawn
  Index triangles = 0;    // character triangles submitted (lines not counted)
  double prepare_ms = 0;  // cull + pack + upload (CPU)
  double submit_ms = 0;   // issuing draws (the GPU may still be working)
};

// Colour of joint-LOD level `level` (0 = finest), shared with the viewer's legend.
glm::vec3 lod_level_colour(std::int32_t level);

// Skinned vertices read back from the GPU (transform feedback): the same
// vertex shader as drawing, for testing against anim::skin_reference.
struct SkinCapture {
  std::int32_t vertices = 0;         // per character (the tier's mesh)
  std::vector<glm::vec3> positions;  // characters * vertices, character-major, world
  std::vector<glm::vec3> normals;
};

class Renderer {
 public:
  // Needs a current OpenGL 4.3 context (throws Error otherwise); compiles
  // the programs and uploads the rigs and meshes.
  explicit Renderer(const CrowdRigs& rigs);
  explicit Renderer(const JointRig& rig);  // joint mode only
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const CrowdRigs& rigs() const;
  const JointRig& rig() const;  // rigs().joints
  // Static scene: obstacles of the simulation's map, uploaded once.
  void set_obstacles(Span<const sim::Polygon> polygons, Span<const sim::Circle> circles,
                     const ObstacleStyle& style = {});
  // Paths (kPathColour) and agents' routes (kRouteColour) drawn when
  // options.paths; an empty list clears them.
  void set_paths(const std::vector<MapPolyline>& paths);
  void set_routes(const std::vector<MapPolyline>& routes);
  void set_field_lines(const std::vector<MapPolyline>& lines);  // kFieldColour, with the paths
  // Bins drawn when options.bins (counts copied; call again to update).
  void set_bins(const BinsOverlay& bins);

  // Draws one frame into the bound framebuffer. The pose spans are in
  // current_memory(): culling and packing run as parallel_for stages there
  // ("render.cull", "render.pack") and only visible characters are uploaded.
  // Skinned mode packs palettes ("render.pack_palettes") instead.
  RenderStats render(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options);

  // Skins every character (no culling) with the mesh of `tier` through the
  // skinned vertex shader and reads the results back. Characters must all be
  // of one rig.
  SkinCapture capture_skinned(const CharacterPoses& poses, DrawTier tier = DrawTier::Fine);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace throng::render
