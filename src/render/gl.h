// OpenGL 4.3 core for the renderer: the entry points (linked from libglvnd's
// libOpenGL, which dispatches to whichever context is current, EGL or GLX)
// and small owning handles for GL objects.
//
// Every GL call needs a current context of version 4.3 or later
// (HeadlessContext, or the viewer's window); check_gl_version() says why not.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

namespace throng::render {

// "llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 (Core Profile) Mesa 22.3.6".
std::string gl_description();
// Throws Error unless the current context is OpenGL 4.3 or later.
void check_gl_version();
// Throws Error naming `what` when glGetError() reports an error.
void check_gl(std::string_view what);

// Sanitizer builds only (a no-op otherwise): keeps the GL driver libraries
// loaded until exit so LeakSanitizer can name, and suppress, what they keep.
void pin_gl_libraries();

// An owned GL name, deleted with `Delete` when it goes.
template <void (*Delete)(GLuint)>
class GlHandle {
 public:
  GlHandle() = default;
  explicit GlHandle(GLuint id) : id_(id) {}
  GlHandle(GlHandle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlHandle& operator=(GlHandle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;
  ~GlHandle() { reset(); }
  GLuint get() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_ != 0) Delete(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace detail {
void delete_buffer(GLuint id);
void delete_vertex_array(GLuint id);
void delete_program(GLuint id);
void delete_framebuffer(GLuint id);
void delete_renderbuffer(GLuint id);
void delete_texture(GLuint id);
}  // namespace detail

using GlBuffer = GlHandle<detail::delete_buffer>;
using GlVertexArray = GlHandle<detail::delete_vertex_array>;
using GlProgram = GlHandle<detail::delete_program>;
using GlFramebuffer = GlHandle<detail::delete_framebuffer>;
using GlRenderbuffer = GlHandle<detail::delete_renderbuffer>;
using GlTexture = GlHandle<detail::delete_texture>;

GlBuffer make_buffer();
GlVertexArray make_vertex_array();
GlTexture make_texture();

// Compiles and links a vertex + fragment program; a compile or link error
// throws Error with the driver's log, naming the program ("render.joints").
// `feedback`: vertex outputs captured by transform feedback (interleaved).
GlProgram make_program(std::string_view name, std::string_view vertex_source, std::string_view fragment_source,
                       std::initializer_list<const char*> feedback = {});

// Grows `buffer` (GL_DYNAMIC_DRAW) to at least `bytes`; capacity in bytes is
// kept in `capacity`. Contents are not kept when it grows.
void reserve_buffer(GLenum target, const GlBuffer& buffer, std::size_t bytes, std::size_t& capacity);

}  // namespace throng::render
