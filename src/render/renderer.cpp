#include "render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <chrono>
#include <cmath>
#include <glm/gtc/type_precision.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/buffer.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/reduce.h"
#include "core/timing.h"
#include "render/cull.h"
#include "render/framebuffer.h"
#include "render/gl.h"
#include "render/meshes.h"
#include "render/shaders.h"

namespace throng::render {

namespace {

constexpr std::int32_t kFineSlices = 10, kFineStacks = 6;
constexpr std::int32_t kCoarseSlices = 4, kCoarseStacks = 2;

// Colours of joint-LOD levels 0.. (finest first), after the spirit of the
// 2019 paper's Figure 8: warm near, cool far.
constexpr float kLodPalette[16][3] = {
    {0.85f, 0.22f, 0.18f}, {0.95f, 0.62f, 0.12f}, {0.32f, 0.70f, 0.28f}, {0.22f, 0.50f, 0.88f},
    {0.55f, 0.35f, 0.80f}, {0.15f, 0.70f, 0.72f}, {0.85f, 0.40f, 0.65f}, {0.55f, 0.55f, 0.55f},
    {0.40f, 0.25f, 0.15f}, {0.90f, 0.85f, 0.30f}, {0.20f, 0.35f, 0.35f}, {0.65f, 0.80f, 0.40f},
    {0.30f, 0.30f, 0.60f}, {0.75f, 0.55f, 0.45f}, {0.45f, 0.60f, 0.75f}, {0.35f, 0.35f, 0.35f}};
// Clothing colours when not colouring by LOD (skinned mode: shirts).
constexpr float kClothes[8][3] = {{0.80f, 0.30f, 0.25f}, {0.25f, 0.45f, 0.75f}, {0.90f, 0.75f, 0.35f},
                                  {0.35f, 0.60f, 0.40f}, {0.55f, 0.40f, 0.65f}, {0.85f, 0.55f, 0.40f},
                                  {0.30f, 0.30f, 0.35f}, {0.85f, 0.85f, 0.80f}};
constexpr float kTrouserColours[4][3] = {
    {0.20f, 0.22f, 0.30f}, {0.35f, 0.30f, 0.25f}, {0.15f, 0.15f, 0.17f}, {0.45f, 0.42f, 0.35f}};
constexpr float kSkinTones[4][3] = {
    {0.93f, 0.76f, 0.63f}, {0.78f, 0.57f, 0.42f}, {0.55f, 0.38f, 0.26f}, {0.36f, 0.24f, 0.17f}};

struct GpuMesh {
  GlVertexArray vao;
  GlBuffer vertices, indices;
  GLsizei index_count = 0;
  GLsizei vertex_count = 0;
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
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(interleaved.size() * sizeof(float)), interleaved.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<const void*>(3 * sizeof(float)));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.indices.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(m.indices.size() * sizeof(std::uint32_t)),
               m.indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  g.index_count = static_cast<GLsizei>(m.indices.size());
  return g;
}

// A skinned mesh with its per-vertex style (body part, material).
GpuMesh upload_skinned_mesh(const anim::SkinnedMesh& m, const std::vector<std::uint8_t>& parts,
                            const std::vector<std::uint8_t>& materials) {
  struct Vertex {
    glm::vec3 position, normal;
    glm::u16vec4 joints;
    glm::vec4 weights;
    std::uint8_t style[4];
  };
  std::vector<Vertex> vertices;
  vertices.reserve(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    vertices.push_back({m.positions[i], m.normals[i], m.joints[i], m.weights[i], {parts[i], materials[i], 0, 0}});
  GpuMesh g;
  g.vao = make_vertex_array();
  g.vertices = make_buffer();
  g.indices = make_buffer();
  glBindVertexArray(g.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, g.vertices.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
               GL_STATIC_DRAW);
  const auto at = [](std::size_t offset) { return reinterpret_cast<const void*>(offset); };
  constexpr auto stride = static_cast<GLsizei>(sizeof(Vertex));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, at(offsetof(Vertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, at(offsetof(Vertex, normal)));
  glEnableVertexAttribArray(2);
  glVertexAttribIPointer(2, 4, GL_UNSIGNED_SHORT, stride, at(offsetof(Vertex, joints)));
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, stride, at(offsetof(Vertex, weights)));
  glEnableVertexAttribArray(4);
  glVertexAttribIPointer(4, 2, GL_UNSIGNED_BYTE, stride, at(offsetof(Vertex, style)));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.indices.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(m.indices.size() * sizeof(std::uint32_t)),
               m.indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  g.index_count = static_cast<GLsizei>(m.indices.size());
  g.vertex_count = static_cast<GLsizei>(m.positions.size());
  return g;
}

GLint uniform(const GlProgram& p, const char* name) { return glGetUniformLocation(p.get(), name); }

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// What the programs of one frame share: the camera's view-projection, the
// background, the eye (world, m), the fog distance (m) and the ground square
// under the eye (centre, half size in m) that the ground and the bins cover.
struct FrameView {
  glm::mat4 view_projection;
  glm::vec3 background;
  glm::vec3 eye;
  float fog;
  glm::vec3 ground_centre;
  float ground_half;
};

FrameView frame_view(const Camera& camera, const RenderOptions& options) {
  FrameView v;
  v.view_projection = projection_matrix(camera) * view_matrix(camera);
  v.background = options.background;
  v.eye = camera.position;
  v.fog = options.fog_distance > 0.0f ? options.fog_distance : camera.far_plane;
  // The ground: a square under the camera reaching the far plane.
  v.ground_centre = glm::vec3(camera.position.x, 0.0f, camera.position.z);
  v.ground_half = std::min(camera.far_plane, 5000.0f);
  return v;
}

// Clears the bound framebuffer (colour to options.background, depth, stencil)
// over camera.width x camera.height pixels and sets the opaque pass's state.
void clear_frame(const Camera& camera, const RenderOptions& options) {
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
}

// Uses program p with the frame's view-projection, background, eye and fog.
void set_lighting(const GlProgram& p, const FrameView& view) {
  glUseProgram(p.get());
  glUniformMatrix4fv(uniform(p, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view.view_projection));
  glUniform3fv(uniform(p, "u_background"), 1, glm::value_ptr(view.background));
  glUniform3fv(uniform(p, "u_camera"), 1, glm::value_ptr(view.eye));
  glUniform1f(uniform(p, "u_fog_distance"), view.fog);
}

// Uses joint program p (ellipsoids or lines): lighting, the rig's bone and
// point counts, and the colours (by joint-LOD level when lod_colours).
void use_joint_program(const GlProgram& p, const FrameView& view, const JointRig& rig, bool lod_colours) {
  set_lighting(p, view);
  glUniform1i(uniform(p, "u_bone_count"), rig.bone_count());
  glUniform1i(uniform(p, "u_point_count"), static_cast<GLint>(rig.point_count()));
  glUniform1i(uniform(p, "u_colour_by_lod"), lod_colours ? 1 : 0);
  glUniform3fv(uniform(p, "u_lod_palette"), 16, &kLodPalette[0][0]);
  glUniform3fv(uniform(p, "u_clothes"), 8, &kClothes[0][0]);
}

}  // namespace

glm::vec3 lod_level_colour(std::int32_t level) {
  const auto* c = kLodPalette[static_cast<std::size_t>(std::clamp(level, 0, 15))];
  return {c[0], c[1], c[2]};
}

void RenderOptions::validate() const {
  if (!(fine_min_pixels >= 0.0f) || !std::isfinite(fine_min_pixels))
    throw Error("must be finite and >= 0", at_field("render.fine_min_pixels"));
  if (!(lines_max_pixels >= 0.0f) || !std::isfinite(lines_max_pixels))
    throw Error("must be finite and >= 0", at_field("render.lines_max_pixels"));
  if (!(fog_distance >= 0.0f) || !std::isfinite(fog_distance))
    throw Error("must be finite and >= 0", at_field("render.fog_distance"));
  for (int c = 0; c < 3; ++c)
    if (!(background[c] >= 0.0f && background[c] <= 1.0f))
      throw Error("channels must be within 0..1", at_field("render.background"));
}

struct Renderer::State {
  CrowdRigs rigs;
  GlProgram joints, joint_lines, skinned, skin_capture, walls, ground, bins, flat;
  GpuMesh fine_sphere, coarse_sphere;
  std::vector<std::array<GpuMesh, kDrawTiers>> skin_meshes;  // per skin rig, per tier
  GlBuffer bones_ssbo, points_ssbo, palettes_ssbo, tags_ssbo;
  std::size_t points_capacity = 0, palettes_capacity = 0, tags_capacity = 0;
  GLint64 max_block_bytes = 1 << 27;  // GL_MAX_SHADER_STORAGE_BLOCK_SIZE
  GLint block_alignment = 256;        // GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT
  GlVertexArray empty_vao;            // attribute-less draws (ground, bins)
  Memory tables_memory = Memory::Host;
  Buffer<RigPoint> rig_points;
  Buffer<anim::Mat3x4> inverse_bind;  // skin rig 0: palettes from joint frames
  Buffer<std::uint32_t> group_flags, slots;
  Buffer<glm::vec4> device_points;  // packing targets when kernels run on the GPU
  Buffer<anim::Mat3x4> device_palettes;
  Buffer<glm::uvec2> device_tags;

  GpuMesh obstacle_walls;
  GlVertexArray caps_vao;
  GlBuffer caps_vbo;
  GLsizei cap_vertices = 0;
  bool has_obstacles = false;

  // Line strips just above the ground: the map's paths (the walkable
  // boundary, planned paths) and the routes of sampled agents.
  struct Polylines {
    GlVertexArray vao;
    GlBuffer vbo;
    std::vector<GLint> first;
    std::vector<GLsizei> count;
    void upload(const std::vector<MapPolyline>& lines, const char* field);
    void draw(const GlProgram& flat, const FrameView& view, glm::vec4 colour) const;
  };
  Polylines paths, routes, field_lines;

  GlTexture bins_texture;
  BinsOverlay bins_meta;
  bool has_bins = false;

  void ensure_tables(Memory memory);
  // Cull, slots: the draw groups of this frame (force_tier >= 0: everyone
  // visible, in that tier).
  DrawGroups cull(const Camera* camera, const CharacterPoses& poses, const RenderOptions& options, RenderMode mode,
                  std::int32_t force_tier);
  void pack_points(const CharacterPoses& poses, const DrawGroups& groups);
  void pack_palettes(const CharacterPoses& poses, const DrawGroups& groups);
  // Binds the palette rows and tags of slots [first, first + count) of a
  // group and sets the program's bases; the rest of the group goes in later calls.
  void bind_slot_range(const GlProgram& program, const DrawGroups& groups, std::int32_t group, Index first,
                       Index count);
  Index slots_per_draw(std::int32_t joints) const;

  // Stages of Renderer::render. prepare: cull, slots, packing; the visible,
  // fine, lines and instance counts into stats; returns the frame's draw groups.
  DrawGroups prepare(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options,
                     RenderStats& stats);
  // The ground square (a metre grid when grid), the bins heat map, the paths.
  void draw_ground(const FrameView& view, bool grid);
  void draw_bins(const FrameView& view);
  void draw_paths(const FrameView& view);
  // Characters of the visible groups; triangles submitted added to stats.
  void draw_joint_characters(const FrameView& view, const DrawGroups& groups, bool lod_colours, RenderStats& stats);
  void draw_skinned_characters(const FrameView& view, const DrawGroups& groups, bool lod_colours, RenderStats& stats);
  // Obstacle walls, then their tops filled even-odd through the stencil.
  void draw_obstacles(const FrameView& view);
};

Renderer::Renderer(const JointRig& rig) : Renderer(CrowdRigs{rig, {}}) {}

Renderer::Renderer(const CrowdRigs& rigs) : s_(std::make_unique<State>()) {
  if (rigs.joints.joint_count == 0 && rigs.skins.empty())
    throw Error("neither a joint rig nor a skinned mesh", at_field("rigs"));
  if (rigs.joints.joint_count != 0) rigs.joints.validate();
  if (rigs.skins.size() > static_cast<std::size_t>(kMaxRenderRigs))
    throw Error(fmt::format("{} skin rigs, at most {}", rigs.skins.size(), kMaxRenderRigs), at_field("rigs.skins"));
  for (const SkinRig& skin : rigs.skins) skin.validate();
  check_gl_version();
  s_->rigs = rigs;
  s_->joints = make_program("render.joints", shaders::kJointsVertex, shaders::kLitFragment);
  s_->joint_lines = make_program("render.joint_lines", shaders::kJointLinesVertex, shaders::kLitFragment);
  s_->skinned = make_program("render.skinned", shaders::kSkinnedVertex, shaders::kLitFragment);
  s_->skin_capture =
      make_program("render.skin_capture", shaders::kSkinnedVertex, shaders::kLitFragment, {"v_world", "v_normal"});
  s_->walls = make_program("render.obstacles", shaders::kStaticVertex, shaders::kLitFragment);
  s_->ground = make_program("render.ground", shaders::kGroundVertex, shaders::kGroundFragment);
  s_->bins = make_program("render.bins", shaders::kGroundVertex, shaders::kBinsFragment);
  s_->flat = make_program("render.flat", shaders::kFlatVertex, shaders::kFlatFragment);
  s_->fine_sphere = upload_mesh(unit_sphere(kFineSlices, kFineStacks));
  s_->coarse_sphere = upload_mesh(unit_sphere(kCoarseSlices, kCoarseStacks));
  for (const SkinRig& skin : rigs.skins) {
    std::array<GpuMesh, kDrawTiers> meshes;
    for (std::size_t t = 0; t < meshes.size(); ++t)
      meshes[t] = upload_skinned_mesh(skin.meshes[t], skin.parts[t], skin.materials[t]);
    s_->skin_meshes.push_back(std::move(meshes));
  }
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &s_->max_block_bytes);
  glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &s_->block_alignment);
  s_->block_alignment = std::max(s_->block_alignment, 1);

  struct GpuBone {
    std::int32_t from, to;
    float radius, pad;
  };
  std::vector<GpuBone> bones;
  for (const RigBone& b : rigs.joints.bones) bones.push_back({b.from, b.to, b.radius, 0.0f});
  s_->bones_ssbo = make_buffer();
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, s_->bones_ssbo.get());
  glBufferData(GL_SHADER_STORAGE_BUFFER,
               static_cast<GLsizeiptr>(std::max<std::size_t>(1, bones.size()) * sizeof(GpuBone)),
               bones.empty() ? nullptr : bones.data(), GL_STATIC_DRAW);
  s_->points_ssbo = make_buffer();
  s_->palettes_ssbo = make_buffer();
  s_->tags_ssbo = make_buffer();
  s_->empty_vao = make_vertex_array();
  check_gl("render.renderer");
}

void Renderer::State::ensure_tables(Memory memory) {
  if (rig_points.size() > 0 || inverse_bind.size() > 0) {
    if (tables_memory == memory) return;
  }
  if (rigs.joints.joint_count > 0) rig_points = Buffer<RigPoint>(std::span<const RigPoint>(rigs.joints.points), memory);
  if (!rigs.skins.empty())
    inverse_bind = Buffer<anim::Mat3x4>(std::span<const anim::Mat3x4>(rigs.skins.front().inverse_bind), memory);
  tables_memory = memory;
}

DrawGroups Renderer::State::cull(const Camera* camera, const CharacterPoses& poses, const RenderOptions& options,
                                 RenderMode mode, std::int32_t force_tier) {
  const Index n = poses.character_count();
  const Memory memory = current_memory();
  ensure_tables(memory);
  CullJob job;
  if (mode == RenderMode::Joints) {
    job.rigs.rig[0] = {rigs.joints.bounding_radius, glm::vec3(0.0f), rigs.joints.joint_count};
  } else {
    job.rigs.count = static_cast<std::int32_t>(rigs.skins.size());
    for (std::int32_t r = 0; r < job.rigs.count; ++r) {
      const SkinRig& skin = rigs.skins[static_cast<std::size_t>(r)];
      job.rigs.rig[r] = {skin.bounding_radius, skin.bind_positions.front(), skin.joint_count};
    }
  }
  const Index flags = job.group_count() * n;
  for (Buffer<std::uint32_t>* b : {&group_flags, &slots})
    if (b->size() != flags || b->memory() != memory) *b = Buffer<std::uint32_t>(flags, memory);
  if (camera != nullptr) job.camera = make_camera_view(*camera);
  job.fine_min_pixels = options.fine_min_pixels;
  job.lines_max_pixels = options.lines_max_pixels;
  job.cull = camera != nullptr && options.cull;
  job.force_tier = force_tier;
  job.joint_count = poses.joint_count;
  job.joint_positions = poses.joint_positions;
  job.scales = poses.scales;
  job.palettes = poses.palettes;
  job.palette_offsets = poses.palette_offsets;
  job.character_rigs = poses.rigs;
  job.palette_refs = poses.palette_refs;
  job.root_positions = poses.root_positions;
  job.root_yaws = poses.root_yaws;
  job.flags = poses.flags;
  job.visible_bits = poses.visible_bits;
  job.group_flags = group_flags.span().subspan(0, flags);
  Index visible = 0;
  if (n > 0) {
    job.run();
    visible = scan_draw_slots(job.group_flags, slots.span());
  }
  return draw_groups(job, slots.span(), visible);
}

void Renderer::State::pack_points(const CharacterPoses& poses, const DrawGroups& groups) {
  const Index visible = groups.visible();
  if (visible == 0) return;
  const Index P = rigs.joints.point_count();
  PackJob pack;
  pack.joint_count = rigs.joints.joint_count;
  pack.points = rig_points.span();
  pack.joint_positions = poses.joint_positions;
  pack.joint_rotations = poses.joint_rotations;
  pack.lod_levels = poses.lod_levels;
  pack.group_flags = group_flags.span();
  pack.slots = slots.span();
  const std::size_t bytes = static_cast<std::size_t>(visible * P) * sizeof(glm::vec4);
  reserve_buffer(GL_SHADER_STORAGE_BUFFER, points_ssbo, bytes, points_capacity);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, points_ssbo.get());
  ScopedTimer upload("render.upload");
  if (current_memory() == Memory::Host) {
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
    if (device_points.size() < visible * P) device_points = Buffer<glm::vec4>(visible * P, current_memory());
    pack.out_points = device_points.span().subspan(0, visible * P);
    pack.run();
    const std::vector<glm::vec4> staging = device_points.to_vector();
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), staging.data());
  }
}

void Renderer::State::pack_palettes(const CharacterPoses& poses, const DrawGroups& groups) {
  const Index visible = groups.visible(), matrices = groups.matrices();
  if (visible == 0) return;
  PalettePackJob pack;
  pack.joint_count = poses.joint_count;
  pack.joint_positions = poses.joint_positions;
  pack.joint_rotations = poses.joint_rotations;
  pack.scales = poses.scales;
  if (poses.joint_count > 0) pack.inverse_bind = inverse_bind.span();
  pack.palettes = poses.palettes;
  pack.palette_offsets = poses.palette_offsets;
  pack.palette_refs = poses.palette_refs;
  pack.root_positions = poses.root_positions;
  pack.root_yaws = poses.root_yaws;
  pack.lod_levels = poses.lod_levels;
  pack.group_flags = group_flags.span();
  pack.slots = slots.span();
  pack.groups = groups;
  const std::size_t palette_bytes = static_cast<std::size_t>(matrices) * sizeof(anim::Mat3x4);
  const std::size_t tag_bytes = static_cast<std::size_t>(visible) * sizeof(glm::uvec2);
  reserve_buffer(GL_SHADER_STORAGE_BUFFER, palettes_ssbo, palette_bytes, palettes_capacity);
  reserve_buffer(GL_SHADER_STORAGE_BUFFER, tags_ssbo, tag_bytes, tags_capacity);
  ScopedTimer upload("render.upload");
  if (current_memory() == Memory::Host) {
    // Pack straight into the GL buffers.
    const auto map = [](const GlBuffer& b, std::size_t bytes) {
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, b.get());
      return glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes),
                              GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
    };
    const auto unmap = [](const GlBuffer& b) {
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, b.get());
      glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
    };
    void* palettes = map(palettes_ssbo, palette_bytes);
    void* tags = map(tags_ssbo, tag_bytes);
    if (palettes == nullptr || tags == nullptr) {
      if (palettes != nullptr) unmap(palettes_ssbo);
      if (tags != nullptr) unmap(tags_ssbo);
      throw Error("cannot map the palette buffers", at_field("render.upload"));
    }
    pack.out_palettes = Span<anim::Mat3x4>(static_cast<anim::Mat3x4*>(palettes), matrices);
    pack.out_tags = Span<glm::uvec2>(static_cast<glm::uvec2*>(tags), visible);
    try {
      pack.run();
    } catch (...) {
      unmap(palettes_ssbo);
      unmap(tags_ssbo);
      throw;
    }
    unmap(palettes_ssbo);
    unmap(tags_ssbo);
  } else {
    if (device_palettes.size() < matrices) device_palettes = Buffer<anim::Mat3x4>(matrices, current_memory());
    if (device_tags.size() < visible) device_tags = Buffer<glm::uvec2>(visible, current_memory());
    pack.out_palettes = device_palettes.span().subspan(0, matrices);
    pack.out_tags = device_tags.span().subspan(0, visible);
    pack.run();
    const std::vector<anim::Mat3x4> palettes = device_palettes.to_vector();
    const std::vector<glm::uvec2> tags = device_tags.to_vector();
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, palettes_ssbo.get());
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(palette_bytes), palettes.data());
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, tags_ssbo.get());
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(tag_bytes), tags.data());
  }
}

Index Renderer::State::slots_per_draw(std::int32_t joint_count) const {
  // One binding of the palette buffer must fit the largest block the
  // driver allows (128 MiB on llvmpipe: 2.4 million joints).
  const auto usable = static_cast<Index>(max_block_bytes) - block_alignment;
  return std::max<Index>(1, usable / (static_cast<Index>(joint_count) * static_cast<Index>(sizeof(anim::Mat3x4))));
}

void Renderer::State::bind_slot_range(const GlProgram& program, const DrawGroups& groups, std::int32_t group,
                                      Index first, Index count) {
  const auto align = static_cast<Index>(block_alignment);
  const Index per_slot = groups.joints[group];
  const Index palette_byte = (groups.first_matrix[group] + first * per_slot) * static_cast<Index>(sizeof(anim::Mat3x4));
  const Index palette_start = palette_byte - palette_byte % align;
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, palettes_ssbo.get(), static_cast<GLintptr>(palette_start),
                    static_cast<GLsizeiptr>(palette_byte - palette_start +
                                            count * per_slot * static_cast<Index>(sizeof(anim::Mat3x4))));
  const Index tag_byte = (groups.first_slot[group] + first) * static_cast<Index>(sizeof(glm::uvec2));
  const Index tag_start = tag_byte - tag_byte % align;
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, tags_ssbo.get(), static_cast<GLintptr>(tag_start),
                    static_cast<GLsizeiptr>(tag_byte - tag_start + count * static_cast<Index>(sizeof(glm::uvec2))));
  glUniform1i(uniform(program, "u_row_base"),
              static_cast<GLint>((palette_byte - palette_start) / static_cast<Index>(sizeof(glm::vec4))));
  glUniform1i(uniform(program, "u_slot_base"),
              static_cast<GLint>((tag_byte - tag_start) / static_cast<Index>(sizeof(glm::uvec2))));
  glUniform1i(uniform(program, "u_joint_count"), static_cast<GLint>(per_slot));
}

Renderer::~Renderer() = default;

const CrowdRigs& Renderer::rigs() const { return s_->rigs; }
const JointRig& Renderer::rig() const { return s_->rigs.joints; }

void Renderer::set_obstacles(Span<const sim::Polygon> polygons, Span<const sim::Circle> circles,
                             const ObstacleStyle& style) {
  const ObstacleMesh mesh = extrude_obstacles(polygons, circles, style);
  s_->has_obstacles = !mesh.walls.indices.empty();
  s_->obstacle_walls = upload_mesh(mesh.walls);
  s_->caps_vao = make_vertex_array();
  s_->caps_vbo = make_buffer();
  glBindVertexArray(s_->caps_vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, s_->caps_vbo.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.cap_triangles.size() * sizeof(glm::vec3)),
               mesh.cap_triangles.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glBindVertexArray(0);
  s_->cap_vertices = static_cast<GLsizei>(mesh.cap_triangles.size());
  check_gl("render.obstacles");
}

void Renderer::State::Polylines::upload(const std::vector<MapPolyline>& lines, const char* field) {
  // Checked whole before anything drawn is replaced.
  std::vector<glm::vec3> vertices;
  std::vector<GLint> new_first;
  std::vector<GLsizei> new_count;
  for (const MapPolyline& p : lines) {
    if (p.size() < 2) continue;
    new_first.push_back(static_cast<GLint>(vertices.size()));
    new_count.push_back(static_cast<GLsizei>(p.size()));
    for (const glm::vec2& q : p) {
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) throw Error("path points must be finite", at_field(field));
      vertices.push_back(world_from_ground(q, 0.03f));
    }
  }
  first = std::move(new_first);
  count = std::move(new_count);
  vao = make_vertex_array();
  vbo = make_buffer();
  glBindVertexArray(vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, vbo.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(glm::vec3)), vertices.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glBindVertexArray(0);
  check_gl(field);
}

void Renderer::set_paths(const std::vector<MapPolyline>& paths) { s_->paths.upload(paths, "render.paths"); }

void Renderer::set_routes(const std::vector<MapPolyline>& routes) { s_->routes.upload(routes, "render.routes"); }

void Renderer::set_field_lines(const std::vector<MapPolyline>& lines) {
  s_->field_lines.upload(lines, "render.field_lines");
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
    throw Error(fmt::format("{} x {} bins exceed the GPU's texture size {}", bins.columns, bins.rows, max_size),
                at_field("bins.columns"));
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(bins.counts.size()));
  for (Index i = 0; i < bins.counts.size(); ++i)
    counts[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(std::max(bins.counts[i], 0));
  if (!s_->bins_texture) s_->bins_texture = make_texture();
  glBindTexture(GL_TEXTURE_2D, s_->bins_texture.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32UI, bins.columns, bins.rows, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, counts.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  check_gl("render.bins");
}

DrawGroups Renderer::State::prepare(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options,
                                    RenderStats& stats) {
  const bool skinned_mode = options.mode == RenderMode::Skinned;
  // Cull, give every visible character a slot, pack its points or palette.
  const DrawGroups groups = cull(&camera, poses, options, options.mode, -1);
  if (skinned_mode)
    pack_palettes(poses, groups);
  else
    pack_points(poses, groups);
  for (std::int32_t g = 0; g < groups.count; ++g) {
    if (g % kDrawTiers == static_cast<int>(DrawTier::Fine)) stats.fine += groups.slots[g];
    if (g % kDrawTiers == static_cast<int>(DrawTier::Lines)) stats.lines += groups.slots[g];
  }
  stats.visible = groups.visible();
  stats.instances = skinned_mode ? stats.visible : stats.visible * rigs.joints.bone_count();
  return groups;
}

void Renderer::State::draw_ground(const FrameView& view, bool grid) {
  set_lighting(ground, view);
  glUniform3f(uniform(ground, "u_centre"), view.ground_centre.x, 0.0f, view.ground_centre.z);
  glUniform1f(uniform(ground, "u_half_size"), view.ground_half);
  glUniform3f(uniform(ground, "u_ground"), 0.58f, 0.60f, 0.56f);
  glUniform3f(uniform(ground, "u_line"), 0.36f, 0.38f, 0.36f);
  glUniform1i(uniform(ground, "u_grid"), grid ? 1 : 0);
  glBindVertexArray(empty_vao.get());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

void Renderer::State::draw_bins(const FrameView& view) {
  glUseProgram(bins.get());
  glUniformMatrix4fv(uniform(bins, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view.view_projection));
  glUniform3f(uniform(bins, "u_centre"), view.ground_centre.x, 0.01f, view.ground_centre.z);
  glUniform1f(uniform(bins, "u_half_size"), view.ground_half);
  glUniform2f(uniform(bins, "u_min"), bins_meta.min.x, bins_meta.min.y);
  glUniform1f(uniform(bins, "u_cell"), bins_meta.cell_size);
  glUniform2i(uniform(bins, "u_cells"), bins_meta.columns, bins_meta.rows);
  glUniform1f(uniform(bins, "u_saturate"), static_cast<float>(bins_meta.saturate_at));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, bins_texture.get());
  glUniform1i(uniform(bins, "u_counts"), 0);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glBindVertexArray(empty_vao.get());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

void Renderer::State::Polylines::draw(const GlProgram& flat, const FrameView& view, glm::vec4 colour) const {
  if (first.empty()) return;
  glUseProgram(flat.get());
  glUniformMatrix4fv(uniform(flat, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view.view_projection));
  glUniform4f(uniform(flat, "u_colour"), colour.r, colour.g, colour.b, colour.a);
  glBindVertexArray(vao.get());
  glMultiDrawArrays(GL_LINE_STRIP, first.data(), count.data(), static_cast<GLsizei>(first.size()));
}

void Renderer::State::draw_paths(const FrameView& view) {
  paths.draw(flat, view, kPathColour);
  field_lines.draw(flat, view, kFieldColour);
  routes.draw(flat, view, kRouteColour);
}

void Renderer::State::draw_joint_characters(const FrameView& view, const DrawGroups& groups, bool lod_colours,
                                            RenderStats& stats) {
  // One instance per (visible character, bone); fine slots first. Both joint
  // programs read the same storage buffers and colour uniforms.
  const JointRig& rig = rigs.joints;
  const Index fine_total = groups.slots[0], coarse_total = groups.slots[1], lines_total = groups.slots[2];
  use_joint_program(joints, view, rig, lod_colours);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, points_ssbo.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bones_ssbo.get());
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  const auto draw = [&](const GpuMesh& mesh, Index slot_base, Index slot_count) {
    if (slot_count <= 0) return;
    glUniform1i(uniform(joints, "u_slot_base"), static_cast<GLint>(slot_base));
    glBindVertexArray(mesh.vao.get());
    glDrawElementsInstanced(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr,
                            static_cast<GLsizei>(slot_count * rig.bone_count()));
    stats.triangles += slot_count * rig.bone_count() * (mesh.index_count / 3);
  };
  draw(fine_sphere, 0, fine_total);
  draw(coarse_sphere, fine_total, coarse_total);
  glDisable(GL_CULL_FACE);
  if (lines_total > 0) {
    // The smallest: one line per bone, two vertices, no instancing.
    use_joint_program(joint_lines, view, rig, lod_colours);
    glUniform1i(uniform(joint_lines, "u_slot_base"), static_cast<GLint>(fine_total + coarse_total));
    glBindVertexArray(empty_vao.get());
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines_total * rig.bone_count() * 2));
  }
}

void Renderer::State::draw_skinned_characters(const FrameView& view, const DrawGroups& groups, bool lod_colours,
                                              RenderStats& stats) {
  set_lighting(skinned, view);
  glUniform1i(uniform(skinned, "u_colour_by_lod"), lod_colours ? 1 : 0);
  glUniform3fv(uniform(skinned, "u_lod_palette"), 16, &kLodPalette[0][0]);
  glUniform3fv(uniform(skinned, "u_clothes"), 8, &kClothes[0][0]);
  glUniform3fv(uniform(skinned, "u_trousers"), 4, &kTrouserColours[0][0]);
  glUniform3fv(uniform(skinned, "u_skin"), 4, &kSkinTones[0][0]);
  for (std::int32_t g = 0; g < groups.count; ++g) {
    if (groups.slots[g] == 0) continue;
    const GpuMesh& mesh =
        skin_meshes[static_cast<std::size_t>(g / kDrawTiers)][static_cast<std::size_t>(g % kDrawTiers)];
    const bool lines = g % kDrawTiers == static_cast<int>(DrawTier::Lines);
    if (lines)
      glDisable(GL_CULL_FACE);
    else
      glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glBindVertexArray(mesh.vao.get());
    const Index per_draw = slots_per_draw(groups.joints[g]);
    for (Index first = 0; first < groups.slots[g]; first += per_draw) {
      const Index count = std::min(per_draw, groups.slots[g] - first);
      bind_slot_range(skinned, groups, g, first, count);
      glDrawElementsInstanced(lines ? GL_LINES : GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr,
                              static_cast<GLsizei>(count));
    }
    if (!lines) stats.triangles += groups.slots[g] * (mesh.index_count / 3);
  }
  glDisable(GL_CULL_FACE);
}

void Renderer::State::draw_obstacles(const FrameView& view) {
  set_lighting(walls, view);
  glUniform3f(uniform(walls, "u_colour"), 0.62f, 0.52f, 0.45f);
  glBindVertexArray(obstacle_walls.vao.get());
  glDrawElements(GL_TRIANGLES, obstacle_walls.index_count, GL_UNSIGNED_INT, nullptr);
  // Tops: even-odd fill through the stencil buffer (holes and concave
  // outlines need no triangulation), then one pass colours where odd.
  glUseProgram(flat.get());
  glUniformMatrix4fv(uniform(flat, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view.view_projection));
  glBindVertexArray(caps_vao.get());
  glEnable(GL_STENCIL_TEST);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glStencilFunc(GL_ALWAYS, 0, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INVERT);
  glStencilMask(0x01);
  glDrawArrays(GL_TRIANGLES, 0, cap_vertices);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glStencilFunc(GL_EQUAL, 1, 0x01);
  glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
  const glm::vec3 top = glm::vec3(0.72f, 0.64f, 0.56f) * 0.95f;
  glUniform4f(uniform(flat, "u_colour"), top.r, top.g, top.b, 1.0f);
  glDrawArrays(GL_TRIANGLES, 0, cap_vertices);
  glStencilMask(0xff);
  glDisable(GL_STENCIL_TEST);
}

RenderStats Renderer::render(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options) {
  camera.validate();
  options.validate();
  poses.validate(s_->rigs, options.mode);
  State& s = *s_;
  const bool skinned = options.mode == RenderMode::Skinned;
  RenderStats stats;
  stats.characters = poses.character_count();
  const auto t0 = std::chrono::steady_clock::now();
  const DrawGroups groups = s.prepare(camera, poses, options, stats);
  stats.prepare_ms = ms_since(t0);

  // Draw: ground and overlays, characters, obstacles.
  const auto t1 = std::chrono::steady_clock::now();
  ScopedTimer draw_timer("render.draw");
  const FrameView view = frame_view(camera, options);
  clear_frame(camera, options);
  if (options.ground) s.draw_ground(view, options.grid);
  if (options.bins && s.has_bins) s.draw_bins(view);
  if (options.paths) s.draw_paths(view);
  if (!skinned && stats.visible > 0) s.draw_joint_characters(view, groups, options.lod_colours, stats);
  if (skinned && stats.visible > 0) s.draw_skinned_characters(view, groups, options.lod_colours, stats);
  if (options.obstacles && s.has_obstacles) s.draw_obstacles(view);
  glBindVertexArray(0);
  glUseProgram(0);
  check_gl("render.draw");
  stats.submit_ms = ms_since(t1);
  return stats;
}

SkinCapture Renderer::capture_skinned(const CharacterPoses& poses, DrawTier tier) {
  RenderOptions options;
  options.mode = RenderMode::Skinned;
  poses.validate(s_->rigs, options.mode);
  State& s = *s_;
  if (s.rigs.skins.size() != 1) throw Error("capture needs a renderer with one skin rig", at_field("rigs.skins"));
  const auto t = static_cast<std::int32_t>(tier);
  const DrawGroups groups = s.cull(nullptr, poses, options, options.mode, t);
  s.pack_palettes(poses, groups);
  const GpuMesh& mesh = s.skin_meshes.front()[static_cast<std::size_t>(t)];
  SkinCapture out;
  out.vertices = mesh.vertex_count;
  const Index n = groups.slots[t];
  if (n != poses.character_count())
    throw Error("characters with palettes out of range cannot be captured", at_field("poses.palette_offsets"));
  if (n == 0) return out;
  const std::size_t floats = static_cast<std::size_t>(n) * static_cast<std::size_t>(mesh.vertex_count) * 6u;
  // Draws need a complete framebuffer even with rasterisation off (a
  // surfaceless context has none): a 1 x 1 target, the caller's restored after.
  GLint previous_fbo = 0, previous_viewport[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous_fbo);
  glGetIntegerv(GL_VIEWPORT, previous_viewport);
  const OffscreenTarget scratch(1, 1, 0);
  scratch.bind();
  GlBuffer feedback = make_buffer();
  glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, feedback.get());
  glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLsizeiptr>(floats * sizeof(float)), nullptr, GL_STATIC_READ);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, feedback.get());
  glUseProgram(s.skin_capture.get());
  const glm::mat4 identity(1.0f);
  glUniformMatrix4fv(uniform(s.skin_capture, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(identity));
  glUniform1i(uniform(s.skin_capture, "u_colour_by_lod"), 1);
  glUniform3fv(uniform(s.skin_capture, "u_lod_palette"), 16, &kLodPalette[0][0]);
  glEnable(GL_RASTERIZER_DISCARD);
  glBindVertexArray(mesh.vao.get());
  glBeginTransformFeedback(GL_POINTS);
  const Index per_draw = s.slots_per_draw(groups.joints[t]);
  for (Index first = 0; first < n; first += per_draw) {
    const Index count = std::min(per_draw, n - first);
    s.bind_slot_range(s.skin_capture, groups, t, first, count);
    glDrawArraysInstanced(GL_POINTS, 0, mesh.vertex_count, static_cast<GLsizei>(count));
  }
  glEndTransformFeedback();
  glDisable(GL_RASTERIZER_DISCARD);
  std::vector<float> data(floats);
  glGetBufferSubData(GL_TRANSFORM_FEEDBACK_BUFFER, 0, static_cast<GLsizeiptr>(floats * sizeof(float)), data.data());
  glBindVertexArray(0);
  glUseProgram(0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(previous_fbo));
  glViewport(previous_viewport[0], previous_viewport[1], previous_viewport[2], previous_viewport[3]);
  check_gl("render.skin_capture");
  out.positions.resize(floats / 6);
  out.normals.resize(floats / 6);
  for (std::size_t i = 0; i < out.positions.size(); ++i) {
    out.positions[i] = glm::vec3(data[6 * i], data[6 * i + 1], data[6 * i + 2]);
    out.normals[i] = glm::vec3(data[6 * i + 3], data[6 * i + 4], data[6 * i + 5]);
  }
  return out;
}

}  // namespace throng::render
