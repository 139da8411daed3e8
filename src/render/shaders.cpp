#include "render/shaders.h"

namespace throng::render::shaders {

// Lighting shared by every lit program: a sun, a sky/ground hemisphere and
// a little fog towards the background colour.
#define THRONG_LIGHTING                                         \
  "uniform vec3 u_background;\n"                                \
  "uniform vec3 u_camera;\n"                                    \
  "uniform float u_fog_distance;\n"                             \
  "vec3 shade(vec3 albedo, vec3 n, vec3 world) {\n"             \
  "  vec3 sun = normalize(vec3(0.45, 0.8, 0.35));\n"            \
  "  float diffuse = max(dot(n, sun), 0.0);\n"                  \
  "  float sky = 0.5 + 0.5 * n.y;\n"                            \
  "  vec3 c = albedo * (0.62 * diffuse + 0.22 + 0.22 * sky);\n" \
  "  float d = length(world - u_camera) / u_fog_distance;\n"    \
  "  return mix(c, u_background, clamp(d * d, 0.0, 1.0));\n"    \
  "}\n"

// What both joint programs read: packed points, the bone table, colours.
#define THRONG_JOINT_INPUTS                                                   \
  "layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };\n"  \
  "struct Bone { int from_point; int to_point; float radius; float pad; };\n" \
  "layout(std430, binding = 1) readonly buffer Bones { Bone bones[]; };\n"    \
  "uniform mat4 u_view_projection;\n"                                         \
  "uniform int u_bone_count;\n"                                               \
  "uniform int u_point_count;\n"                                              \
  "uniform int u_slot_base;\n"                                                \
  "uniform int u_colour_by_lod;\n"                                            \
  "uniform vec3 u_lod_palette[16];\n"                                         \
  "uniform vec3 u_clothes[8];\n"                                              \
  "out vec3 v_world;\n"                                                       \
  "out vec3 v_normal;\n"                                                      \
  "flat out vec3 v_albedo;\n"                                                 \
  "// A packed point's w: LOD level in the low 4 bits, character id above.\n" \
  "vec3 albedo_of(float tag_w) {\n"                                           \
  "  int tag = int(tag_w);\n"                                                 \
  "  if (u_colour_by_lod != 0) return u_lod_palette[tag & 15];\n"             \
  "  int id = tag >> 4;\n"                                                    \
  "  return u_clothes[(id * 5 + (id >> 3)) & 7];\n"                           \
  "}\n"

const char* const kJointsVertex =
    "#version 430 core\n"
    "layout(location = 0) in vec3 a_position;  // unit sphere\n" THRONG_JOINT_INPUTS R"(
void main() {
  int slot = u_slot_base + gl_InstanceID / u_bone_count;
  Bone bone = bones[gl_InstanceID % u_bone_count];
  vec4 a = points[slot * u_point_count + bone.from_point];
  vec4 b = points[slot * u_point_count + bone.to_point];
  vec3 axis = b.xyz - a.xyz;
  float len = length(axis);
  vec3 u = len > 1e-6 ? axis / len : vec3(0.0, 1.0, 0.0);
  vec3 helper = abs(u.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  vec3 v = normalize(cross(helper, u));
  vec3 w = cross(u, v);
  // Squashed sphere: half the bone plus a little overlap along it, the
  // bone's radius across.
  float along = max(0.5 * len + 0.35 * bone.radius, bone.radius);
  float across = bone.radius;
  vec3 centre = 0.5 * (a.xyz + b.xyz);
  v_world = centre + u * (a_position.y * along) + v * (a_position.x * across) + w * (a_position.z * across);
  v_normal = normalize(u * (a_position.y / along) + v * (a_position.x / across) + w * (a_position.z / across));
  v_albedo = albedo_of(b.w);
  gl_Position = u_view_projection * vec4(v_world, 1.0);
}
)";

const char* const kJointLinesVertex = "#version 430 core\n" THRONG_JOINT_INPUTS R"(
void main() {
  int segment = gl_VertexID / 2;
  int slot = u_slot_base + segment / u_bone_count;
  Bone bone = bones[segment % u_bone_count];
  vec4 a = points[slot * u_point_count + bone.from_point];
  vec4 b = points[slot * u_point_count + bone.to_point];
  v_world = (gl_VertexID & 1) == 0 ? a.xyz : b.xyz;
  v_normal = vec3(0.0, 1.0, 0.0);
  v_albedo = albedo_of(b.w);
  gl_Position = u_view_projection * vec4(v_world, 1.0);
}
)";

// Skinned mode: one instance per visible character of a draw group; its
// palette is three vec4 rows per joint (anim::Mat3x4), as
// anim::skin_vertex computes it on the CPU.
const char* const kSkinnedVertex = R"(#version 430 core
layout(location = 0) in vec3 a_position;  // bind pose, model space
layout(location = 1) in vec3 a_normal;
layout(location = 2) in uvec4 a_joints;
layout(location = 3) in vec4 a_weights;
layout(location = 4) in uvec2 a_style;    // body part, material (shirt, trousers, skin)
layout(std430, binding = 0) readonly buffer Palettes { vec4 palette_rows[]; };
layout(std430, binding = 1) readonly buffer Tags { uvec2 tags[]; };  // character id, 4 bits of LOD level per part
uniform mat4 u_view_projection;
uniform int u_slot_base;    // the group's first slot
uniform int u_row_base;     // the first palette row (vec4) of the draw's first instance
uniform int u_joint_count;
uniform int u_colour_by_lod;
uniform vec3 u_lod_palette[16];
uniform vec3 u_clothes[8];
uniform vec3 u_trousers[4];
uniform vec3 u_skin[4];
out vec3 v_world;
out vec3 v_normal;
flat out vec3 v_albedo;
void main() {
  int base = u_row_base + 3 * gl_InstanceID * u_joint_count;
  vec4 p = vec4(a_position, 1.0);
  vec4 n = vec4(a_normal, 0.0);
  vec3 sp = vec3(0.0);
  vec3 sn = vec3(0.0);
  for (int k = 0; k < 4; ++k) {
    float w = a_weights[k];
    if (w == 0.0) continue;
    int m = base + 3 * int(a_joints[k]);
    vec4 r0 = palette_rows[m];
    vec4 r1 = palette_rows[m + 1];
    vec4 r2 = palette_rows[m + 2];
    sp += w * vec3(dot(r0, p), dot(r1, p), dot(r2, p));
    sn += w * vec3(dot(r0, n), dot(r1, n), dot(r2, n));
  }
  float len = length(sn);
  v_world = sp;
  v_normal = len > 0.0 ? sn / len : vec3(0.0, 1.0, 0.0);
  uvec2 tag = tags[u_slot_base + gl_InstanceID];
  if (u_colour_by_lod != 0) {
    v_albedo = u_lod_palette[(tag.y >> (4u * a_style.x)) & 15u];
  } else {
    uint h = tag.x;  // the character id, hashed (lowbias32) into its outfit
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    if (a_style.y == 0u) v_albedo = u_clothes[h & 7u];
    else if (a_style.y == 1u) v_albedo = u_trousers[(h >> 8) & 3u];
    else v_albedo = u_skin[(h >> 16) & 3u];
  }
  gl_Position = u_view_projection * vec4(v_world, 1.0);
}
)";

const char* const kLitFragment =
    "#version 430 core\n"
    "in vec3 v_world;\n"
    "in vec3 v_normal;\n"
    "flat in vec3 v_albedo;\n"
    "out vec4 o_colour;\n" THRONG_LIGHTING
    "void main() { o_colour = vec4(shade(v_albedo, normalize(v_normal), v_world), 1.0); }\n";

const char* const kStaticVertex = R"(#version 430 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_view_projection;
uniform vec3 u_colour;
out vec3 v_world;
out vec3 v_normal;
flat out vec3 v_albedo;
void main() {
  v_world = a_position;
  v_normal = a_normal;
  v_albedo = u_colour;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

const char* const kGroundVertex = R"(#version 430 core
// A square on y = 0 centred at u_centre, from a 4-vertex strip.
uniform mat4 u_view_projection;
uniform vec3 u_centre;
uniform float u_half_size;
out vec3 v_world;
void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  v_world = vec3(u_centre.x + corner.x * u_half_size, u_centre.y, u_centre.z + corner.y * u_half_size);
  gl_Position = u_view_projection * vec4(v_world, 1.0);
}
)";

const char* const kGroundFragment =
    "#version 430 core\n"
    "in vec3 v_world;\n"
    "out vec4 o_colour;\n"
    "uniform vec3 u_ground;\n"
    "uniform vec3 u_line;\n"
    "uniform int u_grid;\n" THRONG_LIGHTING R"(
// Coverage of grid lines of the given spacing, about one pixel wide,
// fading out where the lines are closer than a few pixels apart.
float grid(vec2 p, float spacing) {
  vec2 q = p / spacing;
  vec2 width = fwidth(q);
  vec2 d = abs(fract(q - 0.5) - 0.5) / max(width, vec2(1e-6));
  float line = 1.0 - min(min(d.x, d.y), 1.0);
  float fade = clamp(1.0 - 4.0 * max(width.x, width.y), 0.0, 1.0);
  return line * fade;
}
void main() {
  vec3 c = u_ground;
  if (u_grid != 0) {
    float minor = grid(v_world.xz, 1.0);
    float major = grid(v_world.xz, 10.0);
    c = mix(c, u_line, max(0.35 * minor, 0.8 * major));
  }
  o_colour = vec4(shade(c, vec3(0.0, 1.0, 0.0), v_world), 1.0);
}
)";

const char* const kBinsFragment = R"(#version 430 core
in vec3 v_world;
out vec4 o_colour;
uniform usampler2D u_counts;
uniform vec2 u_min;        // map corner of cell (0, 0)
uniform float u_cell;
uniform ivec2 u_cells;     // columns, rows
uniform float u_saturate;
void main() {
  vec2 map = vec2(v_world.x, -v_world.z);  // core/ground.h
  vec2 q = (map - u_min) / u_cell;
  ivec2 cell = ivec2(floor(q));
  if (any(lessThan(cell, ivec2(0))) || any(greaterThanEqual(cell, u_cells))) discard;
  float n = float(texelFetch(u_counts, cell, 0).r);
  vec2 edge = abs(fract(q) - 0.5) * 2.0;
  float border = smoothstep(0.92, 0.98, max(edge.x, edge.y));
  if (n <= 0.0 && border <= 0.0) discard;
  float t = clamp(n / u_saturate, 0.0, 1.0);
  vec3 heat = mix(vec3(0.1, 0.3, 0.9), vec3(1.0, 0.9, 0.1), smoothstep(0.0, 0.5, t));
  heat = mix(heat, vec3(0.95, 0.15, 0.1), smoothstep(0.5, 1.0, t));
  float alpha = n > 0.0 ? 0.25 + 0.35 * t : 0.0;
  o_colour = vec4(mix(heat, vec3(0.15), border), max(alpha, 0.35 * border));
}
)";

const char* const kFlatVertex = R"(#version 430 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
void main() { gl_Position = u_view_projection * vec4(a_position, 1.0); }
)";

const char* const kFlatFragment = R"(#version 430 core
uniform vec4 u_colour;
out vec4 o_colour;
void main() { o_colour = u_colour; }
)";

#undef THRONG_LIGHTING
#undef THRONG_JOINT_INPUTS

}  // namespace throng::render::shaders
