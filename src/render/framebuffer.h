// An offscreen render target: colour (RGBA8) + depth/stencil, optionally
// multisampled and resolved on read-back. Headless rendering draws here.
#pragma once

#include <cstdint>

#include "render/gl.h"
#include "render/image.h"

namespace throng::render {

class OffscreenTarget {
 public:
  // Needs a current context. samples 0 or 1: no multisampling. Throws
  // Error for sizes outside 1..16384 or an incomplete framebuffer.
  OffscreenTarget(std::int32_t width, std::int32_t height, std::int32_t samples = 4);

  std::int32_t width() const { return width_; }
  std::int32_t height() const { return height_; }
  // Binds it for drawing and sets the viewport to the whole target.
  void bind() const;
  // Resolves (when multisampled) and reads the picture back, top row first.
  Image read() const;
  // The same into `image`, reusing its storage (video frames).
  void read_into(Image& image) const;

 private:
  std::int32_t width_ = 0, height_ = 0, samples_ = 0;
  GlFramebuffer draw_fbo_, resolve_fbo_;
  GlRenderbuffer colour_, depth_, resolve_colour_;
};

}  // namespace throng::render
