// GLSL 4.30 sources of the renderer's programs.
#pragma once

namespace throng::render::shaders {

// Joint mode: a unit sphere per (slot, bone) instance, stretched between two
// packed points read from a shader storage buffer.
extern const char* const kJointsVertex;
extern const char* const kLitFragment;
// Joint mode for the smallest characters: one line per (slot, bone) from
// gl_VertexID alone, no vertex attributes.
extern const char* const kJointLinesVertex;
// Skinned mode: a mesh instanced per visible character, skinned from its
// palette (shader storage, three vec4 rows per joint); lit by kLitFragment.
extern const char* const kSkinnedVertex;
// Obstacle walls: positions and normals from vertex attributes.
extern const char* const kStaticVertex;
// Ground plane with a metre grid (analytic, antialiased lines).
extern const char* const kGroundVertex;
extern const char* const kGroundFragment;
// Bins heat map on the ground from an integer texture of counts.
extern const char* const kBinsFragment;
// Flat-coloured lines and stencil passes.
extern const char* const kFlatVertex;
extern const char* const kFlatFragment;

}  // namespace throng::render::shaders
