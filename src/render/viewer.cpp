#include "render/viewer.h"

// GL entry points from render/gl.h; GLFW must not pull in its own GL header.
#include "render/gl.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "anim/crowd_animator.h"
#include "anim/lod.h"
#include "core/buffer.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/timing.h"
#include "render/gl.h"
#include "render/image.h"
#include "render/renderer.h"

namespace throng::render {

void ViewerOptions::validate() const {
  if (width < 64 || width > 8192) throw Error(fmt::format("{} is outside 64..8192", width), at_field("--width"));
  if (height < 64 || height > 8192) throw Error(fmt::format("{} is outside 64..8192", height), at_field("--height"));
  if (frames < 0) throw Error("must be >= 0", at_field("--frames"));
  if (!(speed >= 0.0 && speed <= 100.0)) throw Error("must be within 0..100", at_field("--speed"));
}

namespace {

struct GlfwSession {
  GlfwSession() {
    glfwSetErrorCallback([](int code, const char* text) { spdlog::debug("glfw {}: {}", code, text); });
    if (glfwInit() != GLFW_TRUE) {
      const char* why = nullptr;
      glfwGetError(&why);
      throw Error(fmt::format("cannot open a window ({}): run it on a desktop, or under xvfb-run",
                              why != nullptr ? why : "no display"));
    }
  }
  ~GlfwSession() { glfwTerminate(); }
};

// Mouse-driven orbit about a target on the ground.
struct OrbitControl {
  glm::vec3 target{0.0f, 1.0f, 0.0f};
  float distance = 30.0f;
  float yaw = 0.6f;     // about +Y
  float pitch = 0.55f;  // above the horizon
  Camera camera(const Camera& lens) const {
    Camera c = lens;
    c.target = target;
    c.position = target + distance * glm::vec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                                               std::cos(pitch) * std::cos(yaw));
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
  }
};

struct InputState {
  OrbitControl* orbit = nullptr;
  bool paused = false;
  bool step = false;
  double speed = 1.0;
  bool lod_colours = false;
  RenderMode mode = RenderMode::Skinned;
  double last_x = 0.0, last_y = 0.0;
  bool dragging_orbit = false, dragging_pan = false;
};

InputState* input_of(GLFWwindow* w) { return static_cast<InputState*>(glfwGetWindowUserPointer(w)); }

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  InputState& in = *input_of(w);
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(w, GLFW_TRUE); break;
    case GLFW_KEY_SPACE: in.paused = !in.paused; break;
    case GLFW_KEY_PERIOD: in.step = true; break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: in.speed = std::min(in.speed * 1.5, 100.0); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: in.speed = std::max(in.speed / 1.5, 0.01); break;
    case GLFW_KEY_L: in.lod_colours = !in.lod_colours; break;
    case GLFW_KEY_M: in.mode = in.mode == RenderMode::Joints ? RenderMode::Skinned : RenderMode::Joints; break;
    default: break;
  }
}

void on_mouse_button(GLFWwindow* w, int button, int action, int) {
  InputState& in = *input_of(w);
  const bool down = action == GLFW_PRESS && !ImGui::GetIO().WantCaptureMouse;
  glfwGetCursorPos(w, &in.last_x, &in.last_y);
  if (button == GLFW_MOUSE_BUTTON_LEFT) in.dragging_orbit = down;
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) in.dragging_pan = down;
}

void on_cursor(GLFWwindow* w, double x, double y) {
  InputState& in = *input_of(w);
  const auto dx = static_cast<float>(x - in.last_x), dy = static_cast<float>(y - in.last_y);
  in.last_x = x;
  in.last_y = y;
  OrbitControl& o = *in.orbit;
  if (in.dragging_orbit) {
    o.yaw -= 0.006f * dx;
    o.pitch = std::clamp(o.pitch + 0.006f * dy, 0.05f, 1.5f);
  } else if (in.dragging_pan) {
    // Move the target in the ground plane, along the view's right and forward.
    const glm::vec3 right(std::cos(o.yaw), 0.0f, -std::sin(o.yaw));
    const glm::vec3 forward(-std::sin(o.yaw), 0.0f, -std::cos(o.yaw));
    const float scale = 0.0015f * o.distance;
    o.target += scale * (-dx * right + dy * forward);
  }
}

void on_scroll(GLFWwindow* w, double, double dy) {
  if (ImGui::GetIO().WantCaptureMouse) return;
  OrbitControl& o = *input_of(w)->orbit;
  o.distance = std::clamp(o.distance * std::pow(0.88f, static_cast<float>(dy)), 1.5f, 5000.0f);
}

Image read_window(std::int32_t width, std::int32_t height) {
  Image image(width, height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  const std::size_t row = static_cast<std::size_t>(width) * 4u;
  std::vector<std::uint8_t> flipped(image.rgba.size());
  for (std::int32_t y = 0; y < height; ++y)
    std::copy_n(image.rgba.data() + static_cast<std::size_t>(height - 1 - y) * row, row,
                flipped.data() + static_cast<std::size_t>(y) * row);
  image.rgba.swap(flipped);
  for (std::size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
  return image;
}

using WindowPtr = std::unique_ptr<GLFWwindow, void (*)(GLFWwindow*)>;

// Window: an OpenGL 4.3 core window of options.width x options.height
// pixels (4x multisampling, 24-bit depth, 8-bit stencil), its context current.
WindowPtr open_window(const ViewerOptions& options) {
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  glfwWindowHint(GLFW_DEPTH_BITS, 24);
  glfwWindowHint(GLFW_STENCIL_BITS, 8);
  WindowPtr window(glfwCreateWindow(options.width, options.height, "throng", nullptr, nullptr), glfwDestroyWindow);
  if (!window) {
    const char* why = nullptr;
    glfwGetError(&why);
    throw Error(fmt::format("cannot open an OpenGL 4.3 core window: {}", why != nullptr ? why : "unknown reason"));
  }
  glfwMakeContextCurrent(window.get());
  glfwSwapInterval(options.vsync && options.frames == 0 ? 1 : 0);
  check_gl_version();
  pin_gl_libraries();
  return window;
}

// ImGui on a window (its GLFW and OpenGL 3 backends, GLSL 430, no
// imgui.ini next to the user's files), shut down when this goes.
struct ImGuiSession {
  explicit ImGuiSession(GLFWwindow* window) {
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 430");
  }
  ~ImGuiSession() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiSession(const ImGuiSession&) = delete;
  ImGuiSession& operator=(const ImGuiSession&) = delete;
};

// The starting orbit: over the scene's centre, far enough to see `extent`
// metres around it, or where the scene's own camera stands.
OrbitControl initial_orbit(const ViewerScene& scene, float extent) {
  OrbitControl orbit;
  orbit.target = scene.centre() + glm::vec3(0.0f, 1.0f, 0.0f);
  orbit.distance = std::max(8.0f, 1.05f * extent / std::tan(0.5f * Camera{}.fov_y));
  if (const std::optional<Camera> own = scene.camera()) {
    // Start where the scene's camera stands.
    const glm::vec3 d = own->position - own->target;
    orbit.target = own->target;
    orbit.distance = std::clamp(glm::length(d), 1.5f, 5000.0f);
    orbit.pitch = std::clamp(std::asin(d.y / glm::length(d)), 0.05f, 1.5f);
    orbit.yaw = std::atan2(d.x, d.z);
  }
  return orbit;
}

// Input: `input` (which must outlive the window) becomes the window's user
// pointer and receives its keys, buttons, cursor and scroll.
void install_input(GLFWwindow* window, InputState& input) {
  glfwSetWindowUserPointer(window, &input);
  // ImGui's GLFW backend chains to callbacks installed before it; ours
  // are installed after, so they call it themselves via ImGui's handlers.
  glfwSetKeyCallback(window, [](GLFWwindow* w, int k, int s, int a, int m) {
    ImGui_ImplGlfw_KeyCallback(w, k, s, a, m);
    on_key(w, k, s, a, m);
  });
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int b, int a, int m) {
    ImGui_ImplGlfw_MouseButtonCallback(w, b, a, m);
    on_mouse_button(w, b, a, m);
  });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
    // ImGui 1.86 polls the cursor position itself in NewFrame.
    on_cursor(w, x, y);
  });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double x, double y) {
    ImGui_ImplGlfw_ScrollCallback(w, x, y);
    on_scroll(w, x, y);
  });
}

// What the frame loop keeps from one frame to the next; the panel shows it
// and its controls edit it.
struct LoopState {
  InputState input;
  RenderOptions render_options;
  std::vector<float> thresholds;               // joint LOD, square pixels, as the panel's sliders set them
  double t = 0.0;                              // animation seconds shown
  std::chrono::steady_clock::time_point last;  // when the previous frame began
  double frame_ms = 0.0;                       // wall time per frame, smoothed
  RenderStats stats;                           // of the last frame drawn
  anim::LodHistogram histogram;                // of the last frame that measured one
  std::vector<std::int32_t> bin_counts;        // agents per cell, row-major
};

// Clock: wall time since the previous frame smoothed into state.frame_ms;
// returns the animation step in seconds (1/30 s per frame when scripted, the
// wall time up to 0.1 s otherwise, times the speed; 0 while paused and not
// stepping), added to state.t.
double tick(LoopState& state, bool scripted) {
  InputState& input = state.input;
  const auto now = std::chrono::steady_clock::now();
  const double wall = std::chrono::duration<double>(now - state.last).count();
  state.last = now;
  state.frame_ms = 0.9 * state.frame_ms + 0.1 * wall * 1000.0;
  const double dt = !input.paused || input.step ? (scripted ? 1.0 / 30.0 : std::min(wall, 0.1)) * input.speed : 0.0;
  state.t += dt;
  input.step = false;
  return dt;
}

// The camera of this frame: the orbit's, for a framebuffer of width x height
// pixels, its far plane (m) at least 1000 m and four times the orbit's distance.
Camera frame_camera(const OrbitControl& orbit, std::int32_t width, std::int32_t height) {
  Camera lens;
  lens.width = width;
  lens.height = height;
  lens.far_plane = std::max(1000.0f, 4.0f * orbit.distance);
  return orbit.camera(lens);
}

// Bins overlay: counts the visible agents (ground positions, m) per cell of
// the simulation's bin size around the scene's centre into state.bin_counts
// and hands the grid to the renderer.
void show_bins(const ViewerScene& scene, const anim::CrowdAnimator& animator, const CharacterPoses& poses, float extent,
               Index n, std::vector<std::int32_t>& bin_counts, Renderer& renderer) {
  // Agents per cell (the simulation's bin size), cells aligned with its bins.
  const float cell = scene.bin_size();
  const glm::vec2 corner = glm::floor((ground_from_world(scene.centre()) - glm::vec2(extent)) / cell) * cell;
  const auto side = std::min<std::int32_t>(4096, static_cast<std::int32_t>(std::ceil(2.0f * extent / cell)) + 1);
  std::vector<glm::vec3> ground(static_cast<std::size_t>(n));
  std::vector<std::uint8_t> flags(static_cast<std::size_t>(poses.flags.size()));
  copy_to_host(animator.positions(), std::span<glm::vec3>(ground));
  copy_to_host(poses.flags, std::span<std::uint8_t>(flags));
  bin_counts.assign(static_cast<std::size_t>(side) * static_cast<std::size_t>(side), 0);
  for (std::size_t i = 0; i < ground.size(); ++i) {
    if (!flags.empty() && (flags[i] & poses.visible_bits) != poses.visible_bits) continue;
    const glm::vec2 m = (ground_from_world(ground[i]) - corner) / cell;
    const auto x = static_cast<std::int32_t>(std::floor(m.x)), y = static_cast<std::int32_t>(std::floor(m.y));
    if (x >= 0 && x < side && y >= 0 && y < side) ++bin_counts[static_cast<std::size_t>(y * side + x)];
  }
  BinsOverlay bins;
  bins.min = corner;
  bins.cell_size = cell;
  bins.columns = side;
  bins.rows = side;
  bins.counts = bin_counts;
  bins.saturate_at = 12;
  renderer.set_bins(bins);
}

// Panel section "Joint LOD": sliders for state.thresholds (square pixels,
// handed to the animator when moved), the share of n agents' body parts per
// level, joints synthesised and the motion cache of the last frame.
void draw_lod_section(LoopState& state, anim::CrowdAnimator& animator, const anim::FrameStats& animated, Index n) {
  std::vector<float>& thresholds = state.thresholds;
  const anim::LodHistogram& histogram = state.histogram;
  bool changed = false;
  for (std::size_t l = 0; l < thresholds.size(); ++l) {
    const float lo = l + 1 < thresholds.size() ? thresholds[l + 1] + 1.0f : 1.0f;
    const float hi = l > 0 ? thresholds[l - 1] - 1.0f : 50000.0f;
    changed |= ImGui::SliderFloat(fmt::format("L{} from px^2", l).c_str(), &thresholds[l], lo, std::max(lo, hi), "%.0f",
                                  ImGuiSliderFlags_Logarithmic);
  }
  if (changed) animator.set_lod_thresholds(thresholds);
  for (std::int32_t l = 0; l < histogram.level_count; ++l) {
    Index count = 0;
    for (int p = 0; p < anim::kBodyPartCount; ++p) count += histogram.at_level(static_cast<anim::BodyPart>(p), l);
    const glm::vec3 c = lod_level_colour(l);
    ImGui::ColorButton(fmt::format("##level{}", l).c_str(), ImVec4(c.r, c.g, c.b, 1.0f), 0, ImVec2(12, 12));
    ImGui::SameLine();
    const float share = n > 0 ? static_cast<float>(count) / static_cast<float>(n * anim::kBodyPartCount) : 0.0f;
    ImGui::ProgressBar(share, ImVec2(-1, 0), fmt::format("level {}: {:.0f}% of body parts", l, 100.0f * share).c_str());
  }
  ImGui::Text("joints synthesised: %.1f of %d per agent", histogram.mean_joints_synthesised(), animator.joint_count());
  if (animator.cache() != nullptr)
    ImGui::Text("motion cache: %.1f%% hits, %lld cycles, %lld read it this frame", 100.0 * animated.cache.hit_rate(),
                static_cast<long long>(animated.cache.entries), static_cast<long long>(animated.from_cache));
  else
    ImGui::TextDisabled("motion cache off");
}

// Panel: the scene's title and status, counts of the last frame, frame time
// (ms) and time shown (s); its controls edit state.input and state.render_options.
void draw_panel(LoopState& state, ViewerScene& scene, anim::CrowdAnimator& animator, const anim::FrameStats& animated,
                Index n) {
  InputState& input = state.input;
  RenderOptions& render_options = state.render_options;
  const RenderStats& stats = state.stats;
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(300, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin(scene.title().c_str());
  const std::string status = scene.status();
  if (!status.empty()) ImGui::TextUnformatted(status.c_str());
  ImGui::Text("agents %lld, visible %lld (%lld near)", static_cast<long long>(stats.characters),
              static_cast<long long>(stats.visible), static_cast<long long>(stats.fine));
  ImGui::Text("frame %.1f ms, time %.1f s, %.1fM triangles", state.frame_ms, state.t,
              static_cast<double>(stats.triangles) / 1e6);
  ImGui::Checkbox("paused", &input.paused);
  ImGui::SameLine();
  if (ImGui::Button("step")) input.step = true;
  float speed = static_cast<float>(input.speed);
  if (ImGui::SliderFloat("speed", &speed, 0.0f, 4.0f, "%.2fx")) input.speed = speed;
  const char* modes[] = {"joints", "skinned"};
  int mode_index = input.mode == RenderMode::Joints ? 0 : 1;
  if (ImGui::Combo("mode (M)", &mode_index, modes, 2))
    input.mode = mode_index == 0 ? RenderMode::Joints : RenderMode::Skinned;
  ImGui::Checkbox("LOD colours", &input.lod_colours);
  ImGui::SameLine();
  ImGui::Checkbox("grid", &render_options.grid);
  ImGui::SameLine();
  ImGui::Checkbox("cull", &render_options.cull);
  ImGui::Checkbox("obstacles", &render_options.obstacles);
  ImGui::SameLine();
  ImGui::Checkbox("paths", &render_options.paths);
  ImGui::SameLine();
  ImGui::Checkbox("bins", &render_options.bins);
  if (ImGui::CollapsingHeader("Joint LOD", ImGuiTreeNodeFlags_DefaultOpen))
    draw_lod_section(state, animator, animated, n);
  if (ImGui::CollapsingHeader("Stages (median ms)", ImGuiTreeNodeFlags_DefaultOpen)) {
    const std::vector<KernelStat> kernels = KernelTimings::global().stats();  // largest total first
    for (std::size_t k = 0; k < std::min<std::size_t>(kernels.size(), 10); ++k)
      ImGui::Text("%-20s %8.3f", kernels[k].name.c_str(), kernels[k].median_ms);
  }
  ImGui::TextDisabled("drag: orbit, right drag: pan, wheel: zoom");
  ImGui::End();
}

// Overlay: one ImGui frame (the panel when options.panel) drawn over the
// bound framebuffer.
void draw_overlay(const ViewerOptions& options, LoopState& state, ViewerScene& scene, anim::CrowdAnimator& animator,
                  const anim::FrameStats& animated, Index n) {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  if (options.panel) draw_panel(state, scene, animator, animated, n);
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

// Present: counts the frame in result.frames, swaps; on the last scripted
// frame saves options.screenshot (width x height pixels) first and closes the window after.
void present(GLFWwindow* window, const ViewerOptions& options, bool scripted, std::int32_t width, std::int32_t height,
             ViewerResult& result) {
  ++result.frames;
  const bool last_frame = scripted && result.frames >= options.frames;
  if (last_frame && !options.screenshot.empty()) write_png(options.screenshot, read_window(width, height));
  glfwSwapBuffers(window);
  if (last_frame) glfwSetWindowShouldClose(window, GLFW_TRUE);
}

}  // namespace

ViewerResult run_viewer(ViewerScene& scene, const ViewerOptions& options) {
  options.validate();
  GlfwSession glfw;
  const WindowPtr window = open_window(options);
  ViewerResult result;
  result.gl = gl_description();
  spdlog::info("viewer: {}", result.gl);

  anim::CrowdAnimator& animator = scene.animator();
  Renderer renderer(make_crowd_rigs(animator.blend_space().skeleton()));
  scene.decorate(renderer);
  const float extent = scene.extent();
  const Index n = animator.count();
  LoopState state;
  state.thresholds = animator.config().lod_thresholds;
  const ImGuiSession imgui(window.get());

  OrbitControl orbit = initial_orbit(scene, extent);
  state.input.orbit = &orbit;
  state.input.paused = options.paused;
  state.input.speed = options.speed;
  state.input.mode = options.mode;
  state.input.lod_colours = options.lod_colours;
  install_input(window.get(), state.input);

  state.render_options.bins = options.bins;
  state.last = std::chrono::steady_clock::now();
  const bool scripted = options.frames > 0;

  while (!glfwWindowShouldClose(window.get())) {
    glfwPollEvents();
    const double dt = tick(state, scripted);

    std::int32_t fb_width = 0, fb_height = 0;
    glfwGetFramebufferSize(window.get(), &fb_width, &fb_height);
    if (fb_width <= 0 || fb_height <= 0) continue;  // minimised
    const Camera camera = frame_camera(orbit, fb_width, fb_height);

    // Locomotion, LOD (for this camera), cache and pose.
    scene.advance(dt, camera);
    const anim::FrameStats& animated = animator.last_frame();
    if (animated.lod) state.histogram = *animated.lod;

    const CharacterPoses poses = scene.poses();
    if (state.render_options.bins) show_bins(scene, animator, poses, extent, n, state.bin_counts, renderer);
    state.render_options.lod_colours = state.input.lod_colours;
    state.render_options.mode = state.input.mode;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    state.stats = renderer.render(camera, poses, state.render_options);

    draw_overlay(options, state, scene, animator, animated, n);
    present(window.get(), options, scripted, fb_width, fb_height, result);
  }
  result.seconds_shown = state.t;
  return result;
}

}  // namespace throng::render
