// An OpenGL 4.3+ core context with no window and no display server: EGL on
// a GPU's device platform (the NVIDIA driver, or Mesa's hardware drivers)
// or Mesa's surfaceless platform (llvmpipe, software rendering on the CPU).
// It renders into framebuffer objects only (see framebuffer.h).
#pragma once

#include <memory>
#include <string>

namespace throng::render {

struct HeadlessOptions {
  // Try a hardware EGL device first; with false, or when none gives a
  // context, Mesa's surfaceless platform (software on a CPU-only machine).
  bool prefer_hardware = true;
  int gl_major = 4;  // at least 4.3
  int gl_minor = 3;
};

class HeadlessContext {
 public:
  // Creates the context and makes it current on this thread. Throws Error
  // saying what was tried and why it failed (no EGL, no 4.3 context, ...).
  explicit HeadlessContext(const HeadlessOptions& options = {});
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  // Makes it current again (e.g. after another context was used).
  void make_current() const;
  // "EGL device: NVIDIA H100 ... | 4.6.0 NVIDIA" or "EGL surfaceless: llvmpipe ...".
  const std::string& description() const { return description_; }
  // True when rendering happens on the CPU (llvmpipe, softpipe, swrast).
  bool software() const { return software_; }

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::string description_;
  bool software_ = false;
};

}  // namespace throng::render
