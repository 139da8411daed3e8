#include "render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>

#include "core/buffer.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/reduce.h"
#include "core/timing.h"
#include "render/cull.h"
#include "render/gl.h"
#include "render/meshes.h"
#include "render/shaders.h"

namespace throng::render {

namespace {

constexpr std::int32_t kFineSlices = 10, kFineStacks = 6;
constexpr std::int32_t kCoarseSlices = 4, kCoarseStacks = 2;

// Colours of joint-LOD levels 0.. (finest first), after the spirit of the
// 2019 paper's Figure 8: warm near, cool far.
constexpr float kLodPalette[16][3] = {{0.85f, 0.22f, 0.18f}, {0.95f, 0.62f, 0.12f}, {0.32f, 0.70f, 0.28f}, {0.22f, 0.50f, 0.88f},
                                      {0.55f, 0.35f, 0.80f}, {0.15f, 0.70f, 0.72f}, {0.85f, 0.40f, 0.65f}, {0.55f, 0.55f, 0.55f},
                                      {0.40f, 0.25f, 0.15f}, {0.90f, 0.85f, 0.30f}, {0.20f, 0.35f, 0.35f}, {0.65f, 0.80f, 0.40f},
                                      {0.30f, 0.30f, 0.60f}, {0.75f, 0.55f, 0.45f}, {0.45f, 0.60f, 0.75f}, {0.35f, 0.35f, 0.35f}};
// Clothing colours when not colouring by LOD.
constexpr float kClothes[8][3] = {{0.80f, 0.30f, 0.25f}, {0.25f, 0.45f, 0.75f}, {0.90f, 0.75f, 0.35f}, {0.35f, 0.60f, 0.40f},
                                  {0.55f, 0.40f, 0.65f}, {0.85f, 0.55f, 0.40f}, {0.30f, 0.30f, 0.35f}, {0.85f, 0.85f, 0.80f}};

struct GpuMesh {
  GlVertexArray vao;
  GlBuffer vertices, indices;
  GLsizei index_count = 0;
};

GpuMesh upload_mesh(const Mesh& m) {
  GpuMesh g;
  g.vao = make_vertex_array();
  g.vertices = make_buffer();
  g.indices = make_buffer();
  std::vector<float> interleaved;
  interleaved.reserve(m.positions.size() * 6);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::vec3 p = m.positions[i], n = i < m.normals.size() ? m.normals[i] : glm::vec3(0, 1, 0);
    interleaved.insert(interleaved.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
  }
  glBindVertexArray(g.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, g.vertices.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(interleaved.size() * sizeof(float)), interleaved.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<const void*>(3 * sizeof(float)));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.indices.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(m.indices.size() * sizeof(std::uint32_t)), m.indices.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  g.index_count = static_cast<GLsizei>(m.indices.size());
  return g;
}

GLint uniform(const GlProgram& p, const char* name) { return glGetUniformLocation(p.get(), name); }

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

glm::vec3 lod_level_colour(std::int32_t level) {
  const auto* c = kLodPalette[static_cast<std::size_t>(std::clamp(level, 0, 15))];
  return {c[0], c[1], c[2]};
}

void RenderOptions::validate() const {
  if (mode == RenderMode::Skinned)
    throw Error("skinned mode needs the mannequin mesh, which is not built yet; use joints", at_field("render.mode"));
  if (!(fine_min_pixels >= 0.0f) || !std::isfinite(fine_min_pixels))
    throw Error("must be finite and >= 0", at_field("render.fine_min_pixels"));
  if (!(lines_max_pixels >= 0.0f) || !std::isfinite(lines_max_pixels))
    throw Error("must be finite and >= 0", at_field("render.lines_max_pixels"));
  if (!(fog_distance >= 0.0f) || !std::isfinite(fog_distance)) throw Error("must be finite and >= 0", at_field("render.fog_distance"));
  for (int c = 0; c < 3; ++c)
    if (!(background[c] >= 0.0f && background[c] <= 1.0f)) throw Error("channels must be within 0..1", at_field("render.background"));
}

struct Renderer::State {
  JointRig rig;
  GlProgram joints, joint_lines, walls, ground, bins, flat;
  GpuMesh fine_sphere, coarse_sphere;
  GlBuffer bones_ssbo, points_ssbo;
  std::size_t points_capacity = 0;
  GlVertexArray empty_vao;  // attribute-less draws (ground, bins)
  Buffer<RigPoint> rig_points;
  Memory rig_memory = Memory::Host;
  Buffer<std::uint32_t> tier_flags, slots;
  Buffer<glm::vec4> device_points;  // packing target when kernels run on the GPU
  std::vector<glm::vec4> staging;

  GpuMesh obstacle_walls;
  GlVertexArray caps_vao;
  GlBuffer caps_vbo;
  GLsizei cap_vertices = 0;
  bool has_obstacles = false;

  GlVertexArray paths_vao;
  GlBuffer paths_vbo;
  std::vector<GLint> path_first;
  std::vector<GLsizei> path_count;

  GlTexture bins_texture;
  BinsOverlay bins_meta;
  bool has_bins = false;
};

Renderer::Renderer(const JointRig& rig) : s_(std::make_unique<State>()) {
  rig.validate();
  check_gl_version();
  s_->rig = rig;
  s_->joints = make_program("render.joints", shaders::kJointsVertex, shaders::kLitFragment);
  s_->joint_lines = make_program("render.joint_lines", shaders::kJointLinesVertex, shaders::kLitFragment);
  s_->walls = make_program("render.obstacles", shaders::kStaticVertex, shaders::kLitFragment);
  s_->ground = make_program("render.ground", shaders::kGroundVertex, shaders::kGroundFragment);
  s_->bins = make_program("render.bins", shaders::kGroundVertex, shaders::kBinsFragment);
  s_->flat = make_program("render.flat", shaders::kFlatVertex, shaders::kFlatFragment);
  s_->fine_sphere = upload_mesh(unit_sphere(kFineSlices, kFineStacks));
  s_->coarse_sphere = upload_mesh(unit_sphere(kCoarseSlices, kCoarseStacks));

  struct GpuBone {
    std::int32_t from, to;
    float radius, pad;
  };
  std::vector<GpuBone> bones;
  for (const RigBone& b : rig.bones) bones.push_back({b.from, b.to, b.radius, 0.0f});
  s_->bones_ssbo = make_buffer();
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, s_->bones_ssbo.get());
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bones.size() * sizeof(GpuBone)), bones.data(), GL_STATIC_DRAW);
  s_->points_ssbo = make_buffer();
  s_->empty_vao = make_vertex_array();
  check_gl("render.renderer");
}

Renderer::~Renderer() = default;

const JointRig& Renderer::rig() const { return s_->rig; }

void Renderer::set_obstacles(Span<const sim::Polygon> polygons, Span<const sim::Circle> circles, const ObstacleStyle& style) {
  const ObstacleMesh mesh = extrude_obstacles(polygons, circles, style);
  s_->has_obstacles = !mesh.walls.indices.empty();
  s_->obstacle_walls = upload_mesh(mesh.walls);
  s_->caps_vao = make_vertex_array();
  s_->caps_vbo = make_buffer();
  glBindVertexArray(s_->caps_vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, s_->caps_vbo.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.cap_triangles.size() * sizeof(glm::vec3)), mesh.cap_triangles.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glBindVertexArray(0);
  s_->cap_vertices = static_cast<GLsizei>(mesh.cap_triangles.size());
  check_gl("render.obstacles");
}

void Renderer::set_paths(const std::vector<MapPolyline>& paths) {
  std::vector<glm::vec3> vertices;
  s_->path_first.clear();
  s_->path_count.clear();
  for (const MapPolyline& p : paths) {
    if (p.size() < 2) continue;
    s_->path_first.push_back(static_cast<GLint>(vertices.size()));
    s_->path_count.push_back(static_cast<GLsizei>(p.size()));
    for (const glm::vec2& q : p) {
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) throw Error("path points must be finite", at_field("render.paths"));
      vertices.push_back(world_from_ground(q, 0.03f));
    }
  }
  s_->paths_vao = make_vertex_array();
  s_->paths_vbo = make_buffer();
  glBindVertexArray(s_->paths_vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, s_->paths_vbo.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(glm::vec3)), vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glBindVertexArray(0);
  check_gl("render.paths");
}

void Renderer::set_bins(const BinsOverlay& bins) {
  bins.validate();
  s_->bins_meta = bins;
  s_->bins_meta.counts = {};
  s_->has_bins = bins.columns > 0 && bins.rows > 0;
  if (!s_->has_bins) return;
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (bins.columns > max_size || bins.rows > max_size)
    throw Error(fmt::format("{} x {} bins exceed the GPU's texture size {}", bins.columns, bins.rows, max_size), at_field("bins.columns"));
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(bins.counts.size()));
  for (Index i = 0; i < bins.counts.size(); ++i) counts[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(std::max(bins.counts[i], 0));
  if (!s_->bins_texture) s_->bins_texture = make_texture();
  glBindTexture(GL_TEXTURE_2D, s_->bins_texture.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32UI, bins.columns, bins.rows, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, counts.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  check_gl("render.bins");
}

RenderStats Renderer::render(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options) {
  camera.validate();
  options.validate();
  poses.validate(s_->rig);
  State& s = *s_;
  const JointRig& rig = s.rig;
  RenderStats stats;
  stats.characters = poses.character_count();
  const auto t0 = std::chrono::steady_clock::now();

  // Cull, give every visible character a slot, pack its points.
  const Index n = stats.characters;
  const Index P = rig.point_count();
  Index tier_count[kDrawTiers] = {0, 0, 0};
  if (n > 0) {
    const Memory memory = current_memory();
    if (s.rig_points.size() == 0 || s.rig_memory != memory) {
      s.rig_points = Buffer<RigPoint>(std::span<const RigPoint>(rig.points), memory);
      s.rig_memory = memory;
    }
    for (Buffer<std::uint32_t>* b : {&s.tier_flags, &s.slots})
      if (b->size() != kDrawTiers * n || b->memory() != memory) *b = Buffer<std::uint32_t>(kDrawTiers * n, memory);
    CullJob cull;
    cull.camera = make_camera_view(camera);
    cull.joint_count = rig.joint_count;
    cull.bounding_radius = rig.bounding_radius;
    cull.fine_min_pixels = options.fine_min_pixels;
    cull.lines_max_pixels = options.lines_max_pixels;
    cull.cull = options.cull;
    cull.joint_positions = poses.joint_positions;
    cull.tier_flags = s.tier_flags.span();
    cull.run();
    const Index visible = exclusive_scan<std::uint32_t>("render.slots", s.tier_flags.span(), s.slots.span());
    // Where each tier's slots begin: the scan at the tier's first entry.
    std::uint32_t starts[kDrawTiers] = {0, 0, 0};
    for (int t = 1; t < kDrawTiers; ++t)
      throng::detail::copy_bytes(&starts[t], Memory::Host, s.slots.data() + t * n, memory, sizeof(std::uint32_t));
    for (int t = 0; t < kDrawTiers; ++t) tier_count[t] = (t + 1 < kDrawTiers ? starts[t + 1] : visible) - starts[t];

    if (visible > 0) {
      PackJob pack;
      pack.joint_count = rig.joint_count;
      pack.points = s.rig_points.span();
      pack.joint_positions = poses.joint_positions;
      pack.joint_rotations = poses.joint_rotations;
      pack.lod_levels = poses.lod_levels;
      pack.tier_flags = s.tier_flags.span();
      pack.slots = s.slots.span();
      const std::size_t bytes = static_cast<std::size_t>(visible * P) * sizeof(glm::vec4);
      reserve_buffer(GL_SHADER_STORAGE_BUFFER, s.points_ssbo, bytes, s.points_capacity);
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, s.points_ssbo.get());
      ScopedTimer upload("render.upload");
      if (memory == Memory::Host) {
        // Pack straight into the GL buffer.
        void* mapped = glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes),
                                        GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
        if (mapped == nullptr) throw Error("cannot map the points buffer", at_field("render.upload"));
        pack.out_points = Span<glm::vec4>(static_cast<glm::vec4*>(mapped), visible * P);
        try {
          pack.run();
        } catch (...) {
          glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
          throw;
        }
        glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
      } else {
        if (s.device_points.size() < visible * P) s.device_points = Buffer<glm::vec4>(visible * P, memory);
        pack.out_points = s.device_points.span().subspan(0, visible * P);
        pack.run();
        s.staging = s.device_points.to_vector();
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), s.staging.data());
      }
    }
  }
  const Index fine_total = tier_count[0], coarse_total = tier_count[1], lines_total = tier_count[2];
  stats.visible = fine_total + coarse_total + lines_total;
  stats.fine = fine_total;
  stats.lines = lines_total;
  stats.instances = stats.visible * rig.bone_count();
  stats.prepare_ms = ms_since(t0);

  // Draw.
  const auto t1 = std::chrono::steady_clock::now();
  ScopedTimer draw_timer("render.draw");
  const glm::mat4 view_projection = projection_matrix(camera) * view_matrix(camera);
  const float fog = options.fog_distance > 0.0f ? options.fog_distance : camera.far_plane;
  glViewport(0, 0, camera.width, camera.height);
  glClearColor(options.background.r, options.background.g, options.background.b, 1.0f);
  glClearDepth(1.0);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_CULL_FACE);
  glEnable(GL_MULTISAMPLE);

  const auto set_lighting = [&](const GlProgram& p) {
    glUseProgram(p.get());
    glUniformMatrix4fv(uniform(p, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    glUniform3fv(uniform(p, "u_background"), 1, glm::value_ptr(options.background));
    glUniform3fv(uniform(p, "u_camera"), 1, glm::value_ptr(camera.position));
    glUniform1f(uniform(p, "u_fog_distance"), fog);
  };
  // The ground: a square under the camera reaching the far plane.
  const glm::vec3 ground_centre(camera.position.x, 0.0f, camera.position.z);
  const float ground_half = std::min(camera.far_plane, 5000.0f);
  if (options.ground) {
    set_lighting(s.ground);
    glUniform3f(uniform(s.ground, "u_centre"), ground_centre.x, 0.0f, ground_centre.z);
    glUniform1f(uniform(s.ground, "u_half_size"), ground_half);
    glUniform3f(uniform(s.ground, "u_ground"), 0.58f, 0.60f, 0.56f);
    glUniform3f(uniform(s.ground, "u_line"), 0.36f, 0.38f, 0.36f);
    glUniform1i(uniform(s.ground, "u_grid"), options.grid ? 1 : 0);
    glBindVertexArray(s.empty_vao.get());
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  }
  if (options.bins && s.has_bins) {
    glUseProgram(s.bins.get());
    glUniformMatrix4fv(uniform(s.bins, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    glUniform3f(uniform(s.bins, "u_centre"), ground_centre.x, 0.01f, ground_centre.z);
    glUniform1f(uniform(s.bins, "u_half_size"), ground_half);
    glUniform2f(uniform(s.bins, "u_min"), s.bins_meta.min.x, s.bins_meta.min.y);
    glUniform1f(uniform(s.bins, "u_cell"), s.bins_meta.cell_size);
    glUniform2i(uniform(s.bins, "u_cells"), s.bins_meta.columns, s.bins_meta.rows);
    glUniform1f(uniform(s.bins, "u_saturate"), static_cast<float>(s.bins_meta.saturate_at));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, s.bins_texture.get());
    glUniform1i(uniform(s.bins, "u_counts"), 0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    glBindVertexArray(s.empty_vao.get());
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }
  if (options.paths && !s.path_first.empty()) {
    glUseProgram(s.flat.get());
    glUniformMatrix4fv(uniform(s.flat, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    glUniform4f(uniform(s.flat, "u_colour"), 0.95f, 0.95f, 0.25f, 1.0f);
    glBindVertexArray(s.paths_vao.get());
    glMultiDrawArrays(GL_LINE_STRIP, s.path_first.data(), s.path_count.data(), static_cast<GLsizei>(s.path_first.size()));
  }

  // Characters: one instance per (visible character, bone); fine slots first.
  // Both joint programs read the same storage buffers and colour uniforms.
  const auto use_joint_program = [&](const GlProgram& p) {
    set_lighting(p);
    glUniform1i(uniform(p, "u_bone_count"), rig.bone_count());
    glUniform1i(uniform(p, "u_point_count"), static_cast<GLint>(P));
    glUniform1i(uniform(p, "u_colour_by_lod"), options.lod_colours ? 1 : 0);
    glUniform3fv(uniform(p, "u_lod_palette"), 16, &kLodPalette[0][0]);
    glUniform3fv(uniform(p, "u_clothes"), 8, &kClothes[0][0]);
  };
  if (stats.visible > 0) {
    use_joint_program(s.joints);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s.points_ssbo.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s.bones_ssbo.get());
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    const auto draw = [&](const GpuMesh& mesh, Index slot_base, Index slots) {
      if (slots <= 0) return;
      glUniform1i(uniform(s.joints, "u_slot_base"), static_cast<GLint>(slot_base));
      glBindVertexArray(mesh.vao.get());
      glDrawElementsInstanced(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr, static_cast<GLsizei>(slots * rig.bone_count()));
      stats.triangles += slots * rig.bone_count() * (mesh.index_count / 3);
    };
    draw(s.fine_sphere, 0, fine_total);
    draw(s.coarse_sphere, fine_total, coarse_total);
    glDisable(GL_CULL_FACE);
    if (lines_total > 0) {
      // The smallest: one line per bone, two vertices, no instancing.
      use_joint_program(s.joint_lines);
      glUniform1i(uniform(s.joint_lines, "u_slot_base"), static_cast<GLint>(fine_total + coarse_total));
      glBindVertexArray(s.empty_vao.get());
      glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines_total * rig.bone_count() * 2));
    }
  }

  if (options.obstacles && s.has_obstacles) {
    set_lighting(s.walls);
    glUniform3f(uniform(s.walls, "u_colour"), 0.62f, 0.52f, 0.45f);
    glBindVertexArray(s.obstacle_walls.vao.get());
    glDrawElements(GL_TRIANGLES, s.obstacle_walls.index_count, GL_UNSIGNED_INT, nullptr);
    // Tops: even-odd fill through the stencil buffer (holes and concave
    // outlines need no triangulation), then one pass colours where odd.
    glUseProgram(s.flat.get());
    glUniformMatrix4fv(uniform(s.flat, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    glBindVertexArray(s.caps_vao.get());
    glEnable(GL_STENCIL_TEST);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_FALSE);
    glStencilFunc(GL_ALWAYS, 0, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INVERT);
    glStencilMask(0x01);
    glDrawArrays(GL_TRIANGLES, 0, s.cap_vertices);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glStencilFunc(GL_EQUAL, 1, 0x01);
    glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
    const glm::vec3 top = glm::vec3(0.72f, 0.64f, 0.56f) * 0.95f;
    glUniform4f(uniform(s.flat, "u_colour"), top.r, top.g, top.b, 1.0f);
    glDrawArrays(GL_TRIANGLES, 0, s.cap_vertices);
    glStencilMask(0xff);
    glDisable(GL_STENCIL_TEST);
  }
  glBindVertexArray(0);
  glUseProgram(0);
  check_gl("render.draw");
  stats.submit_ms = ms_since(t1);
  return stats;
}

}  // namespace throng::render
