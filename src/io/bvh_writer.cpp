#include "io/bvh_writer.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <glm/vec3.hpp>
#include <vector>

#include "core/error.h"
#include "core/output_file.h"

namespace throng::io {

namespace {

constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

// Shortest text that reads back to the same float.
void append_number(std::string& out, float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}
void append_number(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void indent(std::string& out, std::size_t depth) { out.append(depth, '\t'); }

// A name the reader gives back unchanged: one line, no braces, not empty.
std::string clean_name(const std::string& name, std::size_t index) {
  std::string s;
  for (char c : name) s.push_back((static_cast<unsigned char>(c) < 32 || c == '{' || c == '}') ? '_' : c);
  while (!s.empty() && s.back() == ' ') s.pop_back();
  while (!s.empty() && s.front() == ' ') s.erase(s.begin());
  return s.empty() ? "joint_" + std::to_string(index) : s;
}

void check_finite(double v, const char* what, std::int32_t frame, const std::string& joint) {
  if (!std::isfinite(v))
    throw Error(std::string("non-finite ") + what + " in frame " + std::to_string(frame) + ", joint '" + joint + "'",
                at_field("clip"));
}

// Frame time written (s): options.frame_time when > 0, else the clip's.
// Throws Error when the skeleton is invalid, the clip does not match it or
// its own arrays, or the frame time is not positive and finite.
double check_clip(const motion::Skeleton& sk, const motion::Clip& clip, const BvhWriteOptions& options) {
  sk.validate();
  const std::size_t J = static_cast<std::size_t>(sk.joint_count());
  const auto frames = static_cast<std::size_t>(std::max(clip.frame_count, 0));
  if (clip.joint_count != sk.joint_count() || clip.rotations.size() != frames * J ||
      clip.root_positions.size() != frames || (!clip.translations.empty() && clip.translations.size() != frames * J))
    throw Error("clip (" + std::to_string(clip.joint_count) + " joints, " + std::to_string(clip.frame_count) +
                    " frames) does not match the skeleton (" + std::to_string(J) + " joints) or its own arrays",
                at_field("clip"));
  const double frame_time = options.frame_time > 0.0 ? options.frame_time : static_cast<double>(clip.frame_time);
  if (!std::isfinite(frame_time) || !(frame_time > 0.0))
    throw Error("must be positive and finite", at_field("clip.frame_time"));
  return frame_time;
}

// What the hierarchy and the motion both need, per joint: children (index
// order), whether the clip animates its translation, its written name.
struct JointLayout {
  std::vector<std::vector<std::int32_t>> children;
  std::vector<std::uint8_t> animated;
  std::vector<std::string> names;
  std::vector<std::int32_t> order;  // depth first, as written
};

JointLayout joint_layout(const motion::Skeleton& sk, const motion::Clip& clip, std::size_t frames) {
  const std::size_t J = static_cast<std::size_t>(sk.joint_count());
  JointLayout l;
  l.children.resize(J);
  for (std::size_t j = 1; j < J; ++j)
    l.children[static_cast<std::size_t>(sk.parents[j])].push_back(static_cast<std::int32_t>(j));
  l.animated.assign(J, 0);
  if (!clip.translations.empty())
    for (std::size_t f = 0; f < frames; ++f)
      for (std::size_t j = 1; j < J; ++j)
        if (clip.translations[f * J + j] != sk.offsets[j]) l.animated[j] = 1;
  l.names.resize(J);
  for (std::size_t j = 0; j < J; ++j) l.names[j] = clean_name(sk.names[j], j);
  return l;
}

// An "OFFSET x y z" line at `depth` tabs: v (m) times per_metre, as floats.
void append_offset(std::string& out, std::size_t depth, const glm::vec3& v, double per_metre) {
  indent(out, depth);
  out.append("OFFSET");
  for (int i = 0; i < 3; ++i) {
    out.push_back(' ');
    append_number(out, static_cast<float>(v[i] * per_metre));
  }
  out.append("\n");
}

// The opening of joint j's block at `depth`: name, offset, channels; j
// joins l.order.
void open_joint(std::string& out, const motion::Skeleton& sk, JointLayout& l, std::int32_t j, std::size_t depth,
                const std::string& rotation_channels, double per_metre) {
  const auto u = static_cast<std::size_t>(j);
  l.order.push_back(j);
  indent(out, depth);
  out.append(j == 0 ? "ROOT " : "JOINT ").append(l.names[u]).append("\n");
  indent(out, depth);
  out.append("{\n");
  append_offset(out, depth + 1, sk.offsets[u], per_metre);
  indent(out, depth + 1);
  const bool positions = j == 0 || l.animated[u];
  out.append("CHANNELS ")
      .append(positions ? "6 Xposition Yposition Zposition" : "3")
      .append(rotation_channels)
      .append("\n");
}

// The HIERARCHY section: joints depth first from the root, children in
// index order, end sites where the skeleton has them; fills l.order.
void write_hierarchy(std::string& out, const motion::Skeleton& sk, JointLayout& l, const std::string& rotation_channels,
                     double per_metre) {
  out.append("HIERARCHY\n");
  l.order.reserve(l.names.size());
  std::vector<std::pair<std::int32_t, std::size_t>> stack = {{0, 0}};
  open_joint(out, sk, l, 0, 0, rotation_channels, per_metre);
  while (!stack.empty()) {
    auto& [j, next_child] = stack.back();
    const auto u = static_cast<std::size_t>(j);
    if (next_child < l.children[u].size()) {
      const std::int32_t c = l.children[u][next_child++];
      open_joint(out, sk, l, c, stack.size(), rotation_channels, per_metre);
      stack.emplace_back(c, 0);
      continue;
    }
    const std::size_t depth = stack.size() - 1;
    if (sk.has_end_site[u]) {
      indent(out, depth + 1);
      out.append("End Site\n");
      indent(out, depth + 1);
      out.append("{\n");
      append_offset(out, depth + 2, sk.end_sites[u], per_metre);
      indent(out, depth + 1);
      out.append("}\n");
    }
    indent(out, depth);
    out.append("}\n");
    stack.pop_back();
  }
}

// One MOTION line: frame f's channels for the joints in l.order, positions
// (m times per_metre) then rotations (degrees, Euler angles in options.order
// written in the order of `axes`).
void write_frame(std::string& out, const motion::Clip& clip, const JointLayout& l, std::size_t f,
                 const BvhWriteOptions& options, const std::array<int, 3>& axes, double per_metre) {
  const std::size_t J = l.names.size();
  bool first = true;
  auto value = [&](float v) {
    if (!first) out.push_back(' ');
    first = false;
    append_number(out, v);
  };
  for (std::int32_t j : l.order) {
    const auto u = static_cast<std::size_t>(j);
    const std::size_t k = f * J + u;
    if (j == 0 || l.animated[u]) {
      const glm::vec3 p = j == 0 ? clip.root_positions[f] : clip.translations[k];
      for (int i = 0; i < 3; ++i) {
        check_finite(p[i], "position", static_cast<std::int32_t>(f), l.names[u]);
        value(static_cast<float>(p[i] * per_metre));
      }
    }
    const glm::quat& q = clip.rotations[k];
    check_finite(static_cast<double>(glm::dot(q, q)), "rotation", static_cast<std::int32_t>(f), l.names[u]);
    if (!(glm::dot(q, q) > 0.0f))
      check_finite(NAN, "rotation (zero quaternion)", static_cast<std::int32_t>(f), l.names[u]);
    const glm::dvec3 e = motion::quat_to_euler(options.order, glm::dquat(q));
    for (int a : axes) value(static_cast<float>(e[a] * kDegreesPerRadian));
  }
  out.append("\n");
}

}  // namespace

// Stages: checks, joint layout, HIERARCHY, then MOTION (frame count, frame
// time, one line per frame).
std::string write_bvh_string(const motion::Skeleton& sk, const motion::Clip& clip, const BvhWriteOptions& options) {
  const double frame_time = check_clip(sk, clip, options);
  const std::size_t J = static_cast<std::size_t>(sk.joint_count());
  const auto frames = static_cast<std::size_t>(std::max(clip.frame_count, 0));
  const double per_metre = 1.0 / motion::metres_per_unit(options.unit);
  JointLayout l = joint_layout(sk, clip, frames);

  const auto axes = motion::euler_axes(options.order);
  std::string rotation_channels;
  for (int a : axes) rotation_channels.append(" ").append(1, static_cast<char>('X' + a)).append("rotation");
  std::string out;
  write_hierarchy(out, sk, l, rotation_channels, per_metre);

  out.append("MOTION\nFrames: ").append(std::to_string(frames)).append("\nFrame Time: ");
  if (options.frame_time > 0.0) {
    append_number(out, frame_time);
  } else {
    append_number(out, clip.frame_time);
  }
  out.append("\n");
  out.reserve(out.size() + frames * J * 40);
  for (std::size_t f = 0; f < frames; ++f) write_frame(out, clip, l, f, options, axes, per_metre);
  return out;
}

void write_bvh(const std::string& path, const motion::Skeleton& skeleton, const motion::Clip& clip,
               const BvhWriteOptions& options) {
  const std::string text = write_bvh_string(skeleton, clip, options);
  OutputFile file(path);
  {
    std::ofstream f(file.writing_path(), std::ios::binary | std::ios::trunc);
    if (!f) throw Error("cannot open for writing", at_line(path, 0));
    f.write(text.data(), static_cast<std::streamsize>(text.size()));
    f.close();
    if (!f) throw Error("write failed", at_line(path, 0));
  }
  file.commit();
}

}  // namespace throng::io
