#include "render/gl.h"

#include <fmt/format.h>

#include <string>

#include "core/error.h"

namespace throng::render {

namespace {
const char* gl_string(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s != nullptr ? s : "?";
}

const char* gl_error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "unknown GL error";
  }
}

GLuint compile_shader(std::string_view program, GLenum stage, std::string_view source) {
  const GLuint s = glCreateShader(stage);
  const GLchar* text = source.data();
  const auto length = static_cast<GLint>(source.size());
  glShaderSource(s, 1, &text, &length);
  glCompileShader(s);
  GLint ok = GL_FALSE;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint log_length = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &log_length);
    std::string log(static_cast<std::size_t>(log_length > 0 ? log_length : 1), '\0');
    glGetShaderInfoLog(s, log_length, nullptr, log.data());
    glDeleteShader(s);
    throw Error(
        fmt::format("{} shader does not compile: {}", stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log.c_str()),
        at_field(std::string(program)));
  }
  return s;
}
}  // namespace

std::string gl_description() { return fmt::format("{} | {}", gl_string(GL_RENDERER), gl_string(GL_VERSION)); }

void check_gl_version() {
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major * 10 + minor < 43)
    throw Error(fmt::format("the renderer needs OpenGL 4.3 or later; this context is {}.{} ({})", major, minor,
                            gl_description()));
}

void check_gl(std::string_view what) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  while (glGetError() != GL_NO_ERROR) {
  }
  throw Error(fmt::format("OpenGL error {} (0x{:04x})", gl_error_name(e), e), at_field(std::string(what)));
}

namespace detail {
void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
void delete_program(GLuint id) { glDeleteProgram(id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_renderbuffer(GLuint id) { glDeleteRenderbuffers(1, &id); }
void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
}  // namespace detail

GlBuffer make_buffer() {
  GLuint id = 0;
  glGenBuffers(1, &id);
  return GlBuffer(id);
}
GlVertexArray make_vertex_array() {
  GLuint id = 0;
  glGenVertexArrays(1, &id);
  return GlVertexArray(id);
}
GlTexture make_texture() {
  GLuint id = 0;
  glGenTextures(1, &id);
  return GlTexture(id);
}

GlProgram make_program(std::string_view name, std::string_view vertex_source, std::string_view fragment_source,
                       std::initializer_list<const char*> feedback) {
  const GLuint vs = compile_shader(name, GL_VERTEX_SHADER, vertex_source);
  GLuint fs = 0;
  try {
    fs = compile_shader(name, GL_FRAGMENT_SHADER, fragment_source);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  GlProgram program(glCreateProgram());
  glAttachShader(program.get(), vs);
  glAttachShader(program.get(), fs);
  if (feedback.size() > 0)
    glTransformFeedbackVaryings(program.get(), static_cast<GLsizei>(feedback.size()), feedback.begin(),
                                GL_INTERLEAVED_ATTRIBS);
  glLinkProgram(program.get());
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint log_length = 0;
    glGetProgramiv(program.get(), GL_INFO_LOG_LENGTH, &log_length);
    std::string log(static_cast<std::size_t>(log_length > 0 ? log_length : 1), '\0');
    glGetProgramInfoLog(program.get(), log_length, nullptr, log.data());
    throw Error(fmt::format("program does not link: {}", log.c_str()), at_field(std::string(name)));
  }
  return program;
}

void reserve_buffer(GLenum target, const GlBuffer& buffer, std::size_t bytes, std::size_t& capacity) {
  if (bytes <= capacity && capacity > 0) return;
  std::size_t grown = capacity > 0 ? capacity : 4096;
  while (grown < bytes) grown += grown / 2;
  glBindBuffer(target, buffer.get());
  glBufferData(target, static_cast<GLsizeiptr>(grown), nullptr, GL_DYNAMIC_DRAW);
  capacity = grown;
}

}  // namespace throng::render

// ---- sanitizer builds ---------------------------------------------------------
// OpenGL drivers (Mesa's EGL/GLX/DRI libraries and the LLVM they JIT with)
// keep a few allocations for the life of the process and are unloaded
// before LeakSanitizer looks, so it can no longer name them. In sanitizer
// builds, pin_gl_libraries() keeps every loaded library mapped (the
// renderer calls it once a context exists), and these suppressions name
// the drivers; leaks in throng's own code are still reported.
#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>

extern "C" const char* __lsan_default_suppressions() {
  return "leak:libEGL_mesa.so\nleak:libGLX_mesa.so\nleak:libGLdispatch.so\nleak:_dri.so\nleak:libLLVM\n"
         "leak:libglfw.so\nleak:libX11.so\nleak:libxcb\nleak:libdrm\nleak:libglapi.so\nleak:libubsan.so\n";
}

namespace throng::render {
void pin_gl_libraries() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void*) {
        if (info->dlpi_name != nullptr && info->dlpi_name[0] != '\0')
          dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
}
}  // namespace throng::render
#else
namespace throng::render {
void pin_gl_libraries() {}
}  // namespace throng::render
#endif
