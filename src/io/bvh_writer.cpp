#include "io/bvh_writer.h"

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
    throw Error(std::string("non-finite ") + what + " in frame " + std::to_string(frame) + ", joint '" + joint + "'", at_field("clip"));
}

}  // namespace

std::string write_bvh_string(const motion::Skeleton& sk, const motion::Clip& clip, const BvhWriteOptions& options) {
  sk.validate();
  const std::size_t J = static_cast<std::size_t>(sk.joint_count());
  const auto frames = static_cast<std::size_t>(std::max(clip.frame_count, 0));
  if (clip.joint_count != sk.joint_count() || clip.rotations.size() != frames * J || clip.root_positions.size() != frames ||
      (!clip.translations.empty() && clip.translations.size() != frames * J))
    throw Error("clip (" + std::to_string(clip.joint_count) + " joints, " + std::to_string(clip.frame_count) +
                    " frames) does not match the skeleton (" + std::to_string(J) + " joints) or its own arrays",
                at_field("clip"));
  const double frame_time = options.frame_time > 0.0 ? options.frame_time : static_cast<double>(clip.frame_time);
  if (!std::isfinite(frame_time) || !(frame_time > 0.0)) throw Error("must be positive and finite", at_field("clip.frame_time"));
  const double per_metre = 1.0 / motion::metres_per_unit(options.unit);

  std::vector<std::vector<std::int32_t>> children(J);
  for (std::size_t j = 1; j < J; ++j) children[static_cast<std::size_t>(sk.parents[j])].push_back(static_cast<std::int32_t>(j));
  std::vector<std::uint8_t> animated(J, 0);
  if (!clip.translations.empty())
    for (std::size_t f = 0; f < frames; ++f)
      for (std::size_t j = 1; j < J; ++j)
        if (clip.translations[f * J + j] != sk.offsets[j]) animated[j] = 1;
  std::vector<std::string> names(J);
  for (std::size_t j = 0; j < J; ++j) names[j] = clean_name(sk.names[j], j);

  const auto axes = motion::euler_axes(options.order);
  std::string rotation_channels;
  for (int a : axes) rotation_channels.append(" ").append(1, static_cast<char>('X' + a)).append("rotation");

  std::string out = "HIERARCHY\n";
  std::vector<std::int32_t> order;  // depth first, as written
  order.reserve(J);
  auto open = [&](std::int32_t j, std::size_t depth) {
    const auto u = static_cast<std::size_t>(j);
    order.push_back(j);
    indent(out, depth);
    out.append(j == 0 ? "ROOT " : "JOINT ").append(names[u]).append("\n");
    indent(out, depth);
    out.append("{\n");
    indent(out, depth + 1);
    out.append("OFFSET");
    for (int i = 0; i < 3; ++i) {
      out.push_back(' ');
      append_number(out, static_cast<float>(sk.offsets[u][i] * per_metre));
    }
    out.append("\n");
    indent(out, depth + 1);
    const bool positions = j == 0 || animated[u];
    out.append("CHANNELS ").append(positions ? "6 Xposition Yposition Zposition" : "3").append(rotation_channels).append("\n");
  };
  std::vector<std::pair<std::int32_t, std::size_t>> stack = {{0, 0}};
  open(0, 0);
  while (!stack.empty()) {
    auto& [j, next_child] = stack.back();
    const auto u = static_cast<std::size_t>(j);
    if (next_child < children[u].size()) {
      const std::int32_t c = children[u][next_child++];
      open(c, stack.size());
      stack.emplace_back(c, 0);
      continue;
    }
    const std::size_t depth = stack.size() - 1;
    if (sk.has_end_site[u]) {
      indent(out, depth + 1);
      out.append("End Site\n");
      indent(out, depth + 1);
      out.append("{\n");
      indent(out, depth + 2);
      out.append("OFFSET");
      for (int i = 0; i < 3; ++i) {
        out.push_back(' ');
        append_number(out, static_cast<float>(sk.end_sites[u][i] * per_metre));
      }
      out.append("\n");
      indent(out, depth + 1);
      out.append("}\n");
    }
    indent(out, depth);
    out.append("}\n");
    stack.pop_back();
  }

  out.append("MOTION\nFrames: ").append(std::to_string(frames)).append("\nFrame Time: ");
  if (options.frame_time > 0.0) {
    append_number(out, frame_time);
  } else {
    append_number(out, clip.frame_time);
  }
  out.append("\n");
  out.reserve(out.size() + frames * J * 40);
  for (std::size_t f = 0; f < frames; ++f) {
    bool first = true;
    auto value = [&](float v) {
      if (!first) out.push_back(' ');
      first = false;
      append_number(out, v);
    };
    for (std::int32_t j : order) {
      const auto u = static_cast<std::size_t>(j);
      const std::size_t k = f * J + u;
      if (j == 0 || animated[u]) {
        const glm::vec3 p = j == 0 ? clip.root_positions[f] : clip.translations[k];
        for (int i = 0; i < 3; ++i) {
          check_finite(p[i], "position", static_cast<std::int32_t>(f), names[u]);
          value(static_cast<float>(p[i] * per_metre));
        }
      }
      const glm::quat& q = clip.rotations[k];
      check_finite(static_cast<double>(glm::dot(q, q)), "rotation", static_cast<std::int32_t>(f), names[u]);
      if (!(glm::dot(q, q) > 0.0f)) check_finite(NAN, "rotation (zero quaternion)", static_cast<std::int32_t>(f), names[u]);
      const glm::dvec3 e = motion::quat_to_euler(options.order, glm::dquat(q));
      for (int a : axes) value(static_cast<float>(e[a] * kDegreesPerRadian));
    }
    out.append("\n");
  }
  return out;
}

void write_bvh(const std::string& path, const motion::Skeleton& skeleton, const motion::Clip& clip, const BvhWriteOptions& options) {
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
