#include "render/framebuffer.h"

#include <fmt/format.h>

#include <cstring>

#include "core/error.h"

namespace throng::render {

namespace {
GlRenderbuffer make_renderbuffer(GLenum format, std::int32_t w, std::int32_t h, std::int32_t samples) {
  GLuint id = 0;
  glGenRenderbuffers(1, &id);
  glBindRenderbuffer(GL_RENDERBUFFER, id);
  if (samples > 1)
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
  else
    glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
  return GlRenderbuffer(id);
}
GlFramebuffer make_framebuffer() {
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  return GlFramebuffer(id);
}
void check_complete(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error(fmt::format("framebuffer incomplete (0x{:04x})", status), at_field(what));
}
}  // namespace

OffscreenTarget::OffscreenTarget(std::int32_t width, std::int32_t height, std::int32_t samples)
    : width_(width), height_(height), samples_(samples) {
  if (width < 1 || width > 16384)
    throw Error(fmt::format("width {} is outside 1..16384", width), at_field("render.width"));
  if (height < 1 || height > 16384)
    throw Error(fmt::format("height {} is outside 1..16384", height), at_field("render.height"));
  if (samples < 0 || samples > 16)
    throw Error(fmt::format("{} samples is outside 0..16", samples), at_field("render.samples"));
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (samples_ > max_samples) samples_ = max_samples;

  colour_ = make_renderbuffer(GL_RGBA8, width, height, samples_);
  depth_ = make_renderbuffer(GL_DEPTH24_STENCIL8, width, height, samples_);
  draw_fbo_ = make_framebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
  check_complete("render.framebuffer");
  if (samples_ > 1) {
    resolve_colour_ = make_renderbuffer(GL_RGBA8, width, height, 0);
    resolve_fbo_ = make_framebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_.get());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_colour_.get());
    check_complete("render.resolve_framebuffer");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("render.framebuffer");
}

void OffscreenTarget::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_.get());
  glViewport(0, 0, width_, height_);
}

Image OffscreenTarget::read() const {
  Image image;
  read_into(image);
  return image;
}

void OffscreenTarget::read_into(Image& image) const {
  GLuint source = draw_fbo_.get();
  if (samples_ > 1) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_.get());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_.get());
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = resolve_fbo_.get();
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  const std::size_t row = static_cast<std::size_t>(width_) * 4u;
  if (image.width != width_ || image.height != height_) image = Image(width_, height_);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  // OpenGL's rows run bottom to top; images run top to bottom.
  std::vector<std::uint8_t> tmp(row);
  for (std::int32_t y = 0; y < height_ / 2; ++y) {
    std::uint8_t* a = image.rgba.data() + static_cast<std::size_t>(y) * row;
    std::uint8_t* b = image.rgba.data() + static_cast<std::size_t>(height_ - 1 - y) * row;
    std::memcpy(tmp.data(), a, row);
    std::memcpy(a, b, row);
    std::memcpy(b, tmp.data(), row);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_.get());
  check_gl("render.read_pixels");
}

}  // namespace throng::render
