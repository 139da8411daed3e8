#include "io/bvh_reader.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/vec3.hpp>
#include <tuple>

#include "core/error.h"
#include "motion/rotation.h"

namespace throng::io {

const char* to_string(BvhChannel c) {
  switch (c) {
    case BvhChannel::Xposition: return "Xposition";
    case BvhChannel::Yposition: return "Yposition";
    case BvhChannel::Zposition: return "Zposition";
    case BvhChannel::Xrotation: return "Xrotation";
    case BvhChannel::Yrotation: return "Yrotation";
    case BvhChannel::Zrotation: return "Zrotation";
  }
  return "?";
}

std::int32_t BvhFile::channel_count() const {
  std::int32_t n = 0;
  for (const auto& c : channels) n += static_cast<std::int32_t>(c.size());
  return n;
}

std::string BvhFile::channel_list(std::int32_t joint) const {
  std::string s;
  for (BvhChannel c : channels.at(static_cast<std::size_t>(joint))) s.append(s.empty() ? "" : " ").append(to_string(c));
  return s;
}

std::string BvhFile::rotation_order(std::int32_t joint) const {
  std::string s;
  for (BvhChannel c : channels.at(static_cast<std::size_t>(joint)))
    if (is_rotation(c)) s.push_back(static_cast<char>('X' + axis_of(c)));
  return s;
}

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;
constexpr double kMaxMagnitude = 1e9;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }
bool is_space(char c) { return is_blank(c) || c == '\n' || c == '\r'; }

char upper(char c) { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c; }
bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (upper(a[i]) != upper(b[i])) return false;
  return true;
}
bool istarts_with(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && iequals(s.substr(0, prefix.size()), prefix);
}

// A token as shown in an error: quoted, shortened, control bytes escaped.
std::string shown(std::string_view t) {
  if (t.empty()) return "end of file";
  std::string s = "'";
  std::size_t n = 0;
  for (char ch : t) {
    if (n++ == 40) {
      s += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 32 && c < 127) {
      s.push_back(ch);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    }
  }
  return s + "'";
}

struct Token {
  std::string_view text;
  int line = 0;
  int col = 0;
};

// Whitespace-separated tokens over the whole text, with line and column.
class Scanner {
 public:
  Scanner(std::string_view text, const std::string& name) : text_(text), name_(name) {
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = line_start_ = 3;  // a UTF-8 byte order mark
  }

  [[noreturn]] void fail(int line, int col, const std::string& message) const {
    throw Error(message, at_line(name_, line, col));
  }
  [[noreturn]] void fail(const Token& t, const std::string& message) const { fail(t.line, t.col, message); }
  [[noreturn]] void expected(const std::string& what, const Token& found) const {
    fail(found, "expected " + what + ", found " + shown(found.text));
  }

  bool at_end() const { return pos_ >= text_.size(); }
  bool at_line_end() const { return at_end() || text_[pos_] == '\n' || text_[pos_] == '\r'; }
  int line() const { return line_; }
  std::size_t remaining() const { return text_.size() - pos_; }

  void skip_blanks() {
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
  }
  void skip_space() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (is_blank(c)) {
        ++pos_;
      } else if (c == '\n' || c == '\r') {
        newline();
      } else {
        break;
      }
    }
  }
  Token next() {
    skip_space();
    return word();
  }
  // The token starting here (no whitespace skipped across lines).
  Token word() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    return {text_.substr(start, pos_ - start), line_, column(start)};
  }
  Token peek() {
    const auto saved = std::make_tuple(pos_, line_, line_start_);
    const Token t = next();
    std::tie(pos_, line_, line_start_) = saved;
    return t;
  }
  // The rest of the current line without surrounding blanks.
  Token rest_of_line() {
    skip_blanks();
    const std::size_t start = pos_;
    while (!at_line_end()) ++pos_;
    std::string_view s = text_.substr(start, pos_ - start);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return {s, line_, column(start)};
  }

  void expect(std::string_view keyword) {
    const Token t = next();
    if (!iequals(t.text, keyword)) expected("'" + std::string(keyword) + "'", t);
  }

  // A finite number filling the whole token; `what` (a callable giving the
  // value's description) is only called to word an error.
  template <class What>
  double number(const Token& t, const What& what) const {
    std::string_view s = t.text;
    if (s.size() > 1 && s[0] == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    // Far beyond any length or angle in motion data, and keeps every value
    // finite once converted to float and scaled to metres.
    if (ec == std::errc() && end == s.data() + s.size() && std::abs(v) <= kMaxMagnitude)
      return v;  // also false for NaN
    if (ec == std::errc::result_out_of_range) fail(t, what() + " is out of range: " + shown(t.text));
    if (ec != std::errc() || end != s.data() + s.size()) expected("a number (" + what() + ")", t);
    if (!std::isfinite(v)) fail(t, what() + " is not a finite number: " + shown(t.text));
    fail(t, what() + " is out of range (magnitude above 1e9): " + shown(t.text));
  }
  double number(const Token& t, const char* what) const {
    return number(t, [what] { return std::string(what); });
  }
  std::int64_t integer(const Token& t, const std::string& what) const {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
    if (ec == std::errc::result_out_of_range) fail(t, what + " is out of range: " + shown(t.text));
    if (ec != std::errc() || end != t.text.data() + t.text.size()) expected("an integer (" + what + ")", t);
    return v;
  }

 private:
  int column(std::size_t at) const { return static_cast<int>(std::min<std::size_t>(at - line_start_ + 1, INT_MAX)); }
  void newline() {
    if (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
    ++pos_;
    ++line_;
    line_start_ = pos_;
  }

  std::string_view text_;
  const std::string& name_;
  std::size_t pos_ = 0;
  int line_ = 1;
  std::size_t line_start_ = 0;
};

struct RawJoint {
  std::string name;
  std::int32_t parent = -1;
  glm::dvec3 offset{0.0};
  std::vector<BvhChannel> channels;
  bool has_end_site = false;
  glm::dvec3 end_site{0.0};
};

class Parser {
 public:
  Parser(std::string_view text, const std::string& name, const BvhReadOptions& options)
      : s_(text, name), name_(name), options_(options) {}

  BvhFile parse() {
    s_.expect("HIERARCHY");
    parse_hierarchy();
    parse_motion_header();
    BvhFile out;
    out.name = name_;
    allocate_clip(out.clip);
    parse_frames(out.clip);
    finish(out);
    return out;
  }

 private:
  std::string joint_name(const Token& keyword, bool& brace_on_line) {
    const Token n = s_.rest_of_line();
    std::string_view name = n.text;
    brace_on_line = !name.empty() && name.back() == '{';
    if (brace_on_line) {
      name.remove_suffix(1);
      while (!name.empty() && is_blank(name.back())) name.remove_suffix(1);
    }
    if (name.empty()) s_.fail(n, "expected a joint name after " + shown(keyword.text));
    if (name.size() > options_.limits.max_name_length)
      s_.fail(n, "joint name is longer than " + std::to_string(options_.limits.max_name_length) + " characters");
    return std::string(name);
  }

  glm::dvec3 offset_values() {
    s_.expect("OFFSET");
    glm::dvec3 v;
    for (int i = 0; i < 3; ++i)
      v[i] = s_.number(s_.next(), [i] { return std::string("OFFSET ") + static_cast<char>('x' + i); });
    return v;
  }

  // '{', OFFSET, optional CHANNELS of a ROOT or JOINT block.
  void open_joint(const Token& keyword, std::int32_t parent) {
    bool brace = false;
    RawJoint j;
    j.name = joint_name(keyword, brace);
    j.parent = parent;
    if (static_cast<std::int32_t>(joints_.size()) >= options_.limits.max_joints)
      s_.fail(keyword, "more than " + std::to_string(options_.limits.max_joints) + " joints (limit)");
    if (!brace) s_.expect("{");
    j.offset = offset_values();
    if (iequals(s_.peek().text, "CHANNELS")) {
      s_.next();
      const Token count_token = s_.next();
      const std::int64_t count = s_.integer(count_token, "channel count");
      if (count < 0 || count > 6)
        s_.fail(count_token, "channel count must be 0 to 6, found " + shown(count_token.text));
      for (std::int64_t i = 0; i < count; ++i) {
        const Token c = s_.next();
        static constexpr BvhChannel kAll[] = {BvhChannel::Xposition, BvhChannel::Yposition, BvhChannel::Zposition,
                                              BvhChannel::Xrotation, BvhChannel::Yrotation, BvhChannel::Zrotation};
        const BvhChannel* found = nullptr;
        for (const BvhChannel& k : kAll)
          if (iequals(c.text, to_string(k))) found = &k;
        if (found == nullptr) s_.expected("a channel name (Xposition ... Zrotation)", c);
        if (std::find(j.channels.begin(), j.channels.end(), *found) != j.channels.end())
          s_.fail(c, "channel " + shown(c.text) + " listed twice for joint '" + j.name + "'");
        j.channels.push_back(*found);
      }
      channel_total_ += count;
    }
    joints_.push_back(std::move(j));
  }

  void parse_hierarchy() {
    const Token root = s_.next();
    if (!iequals(root.text, "ROOT")) s_.expected("'ROOT'", root);
    open_joint(root, -1);
    std::vector<std::int32_t> open = {0};
    std::vector<int> open_line = {root.line};
    while (!open.empty()) {
      const Token t = s_.next();
      const std::int32_t current = open.back();
      if (iequals(t.text, "JOINT")) {
        open_joint(t, current);
        open.push_back(static_cast<std::int32_t>(joints_.size()) - 1);
        open_line.push_back(t.line);
      } else if (iequals(t.text, "End")) {
        const Token rest = s_.rest_of_line();
        if (!istarts_with(rest.text, "Site")) s_.expected("'Site' after 'End'", rest);
        if (rest.text.back() != '{') s_.expect("{");
        RawJoint& j = joints_[static_cast<std::size_t>(current)];
        if (j.has_end_site) s_.fail(t, "joint '" + j.name + "' has a second End Site");
        j.end_site = offset_values();
        j.has_end_site = true;
        s_.expect("}");
      } else if (t.text == "}") {
        open.pop_back();
        open_line.pop_back();
      } else {
        const std::string where = "joint '" + joints_[static_cast<std::size_t>(current)].name + "' opened at line " +
                                  std::to_string(open_line.back());
        if (t.text.empty()) s_.fail(t, "file ends inside " + where);
        s_.expected("'JOINT', 'End Site' or '}' in " + where, t);
      }
    }
  }

  // The value glued to keyword token t after its first `length` characters
  // ("Frames:12"), else the next token ("Frames: 12").
  Token glued_value(Token t, int length) {
    t.text.remove_prefix(static_cast<std::size_t>(length));
    t.col += length;
    return t.text.empty() ? s_.next() : t;
  }

  void parse_motion_header() {
    const Token m = s_.next();
    if (iequals(m.text, "ROOT")) s_.fail(m, "a second ROOT hierarchy is not supported");
    if (!iequals(m.text, "MOTION")) s_.expected("'MOTION'", m);
    // "Frames: N" (also "Frames:N").
    const Token f = s_.next();
    if (!istarts_with(f.text, "Frames:")) s_.expected("'Frames:'", f);
    const Token count = glued_value(f, 7);
    frames_token_ = count;
    frames_ = s_.integer(count, "frame count");
    if (frames_ < 0) s_.fail(count, "frame count must not be negative");
    const std::int64_t max_frames = std::min<std::int64_t>(options_.limits.max_frames, INT32_MAX);
    if (frames_ > max_frames)
      s_.fail(count, "Frames: " + std::to_string(frames_) + " exceeds the limit of " + std::to_string(max_frames));
    // "Frame Time: t" (also "Time:t").
    s_.expect("Frame");
    const Token tt = s_.next();
    if (!istarts_with(tt.text, "Time:")) s_.expected("'Time:' after 'Frame'", tt);
    const Token value = glued_value(tt, 5);
    frame_time_ = s_.number(value, "frame time");
    if (!(frame_time_ > 0.0)) s_.fail(value, "frame time must be positive, found " + shown(value.text));
    s_.skip_blanks();
    if (!s_.at_line_end()) s_.expected("the end of the 'Frame Time' line", s_.word());
  }

  void allocate_clip(motion::Clip& clip) {
    const auto J = static_cast<std::int64_t>(joints_.size());
    const std::int64_t values = frames_ * channel_total_;
    const Token& at = frames_token_;
    if (frames_ > 0 && channel_total_ == 0) s_.fail(at, "the hierarchy has no channels, so there can be no frames");
    if (values > options_.limits.max_values)
      s_.fail(at, std::to_string(frames_) + " frames x " + std::to_string(channel_total_) +
                      " channels exceeds the limit of " + std::to_string(options_.limits.max_values) + " values");
    if (frames_ * J > options_.limits.max_poses)
      s_.fail(at, std::to_string(frames_) + " frames x " + std::to_string(J) + " joints exceeds the limit of " +
                      std::to_string(options_.limits.max_poses) + " joint poses");
    // Each value takes at least one character and one separator: a count the
    // rest of the file cannot hold is refused before allocating for it.
    if (values > 0 && static_cast<std::uint64_t>(2 * values - 1) > s_.remaining())
      s_.fail(at, "Frames: " + std::to_string(frames_) + " needs " + std::to_string(values) + " values but only " +
                      std::to_string(s_.remaining()) + " bytes follow (truncated file?)");
    clip.resize(static_cast<std::int32_t>(frames_), static_cast<std::int32_t>(J));
    clip.frame_time = static_cast<float>(frame_time_);
    for (std::size_t j = 1; j < joints_.size(); ++j)
      for (BvhChannel c : joints_[j].channels)
        if (!is_rotation(c)) has_translations_ = true;
    if (has_translations_) clip.translations.assign(static_cast<std::size_t>(frames_ * J), glm::vec3(0.0f));
  }

  void parse_frames(motion::Clip& clip) {
    std::vector<double> row(static_cast<std::size_t>(channel_total_));
    for (std::int64_t f = 0; f < frames_; ++f) {
      s_.skip_space();
      if (s_.at_end())
        s_.fail(s_.line(), 0,
                "file ends after " + std::to_string(f) + " frame rows; 'Frames:' says " + std::to_string(frames_));
      const int row_line = s_.line();
      std::int64_t k = 0;
      for (;;) {
        s_.skip_blanks();
        if (s_.at_line_end()) break;
        const Token t = s_.word();
        const double v =
            s_.number(t, [f, k] { return "frame row " + std::to_string(f + 1) + " value " + std::to_string(k + 1); });
        if (k < channel_total_) row[static_cast<std::size_t>(k)] = v;
        ++k;
      }
      if (k != channel_total_)
        s_.fail(row_line, 0,
                "frame row " + std::to_string(f + 1) + " has " + std::to_string(k) + " values, expected " +
                    std::to_string(channel_total_) + " (one per channel)");
      store_pose(clip, static_cast<std::int32_t>(f), row);
    }
    s_.skip_space();
    if (!s_.at_end()) {
      const Token extra = s_.word();
      s_.fail(extra,
              "more frame rows than 'Frames: " + std::to_string(frames_) + "' (found " + shown(extra.text) + ")");
    }
  }

  // One row of values -> local rotations and translations, in file units.
  void store_pose(motion::Clip& clip, std::int32_t frame, const std::vector<double>& row) {
    std::size_t v = 0;
    const std::size_t J = joints_.size();
    for (std::size_t j = 0; j < J; ++j) {
      const RawJoint& joint = joints_[j];
      glm::dvec3 t = joint.offset;
      glm::dquat q(1.0, 0.0, 0.0, 0.0);
      for (BvhChannel c : joint.channels) {
        const double value = row[v++];
        if (is_rotation(c)) {
          q = q * motion::axis_rotation(axis_of(c), value * kDegree);
        } else {
          t[axis_of(c)] = value;
        }
      }
      const std::size_t k = static_cast<std::size_t>(frame) * J + j;
      clip.rotations[k] = glm::quat(glm::normalize(q));
      if (j == 0) clip.root_positions[static_cast<std::size_t>(frame)] = glm::vec3(t);
      if (has_translations_) clip.translations[k] = glm::vec3(t);
    }
  }

  void finish(BvhFile& out) {
    const std::size_t J = joints_.size();
    out.frame_time = frame_time_;
    out.channels.reserve(J);
    for (const RawJoint& j : joints_) out.channels.push_back(j.channels);
    // The skeleton in file units first: roles, then the unit guess needs them.
    motion::Skeleton& sk = out.skeleton;
    for (const RawJoint& j : joints_) {
      sk.add_joint(j.name, j.parent, glm::vec3(j.offset));
      if (j.has_end_site) {
        sk.has_end_site.back() = 1;
        sk.end_sites.back() = glm::vec3(j.end_site);
        ++out.end_site_count;
      }
    }
    motion::assign_roles(sk, options_.role_overrides);
    if (options_.unit) {
      out.unit = *options_.unit;
    } else {
      out.unit = motion::guess_length_unit(sk).unit;
      out.unit_detected = true;
    }
    const double scale = motion::metres_per_unit(out.unit);
    for (std::size_t j = 0; j < J; ++j) {
      sk.offsets[j] = glm::vec3(joints_[j].offset * scale);
      sk.end_sites[j] = glm::vec3(joints_[j].end_site * scale);
    }
    if (scale != 1.0) {
      for (glm::vec3& p : out.clip.root_positions) p = glm::vec3(glm::dvec3(p) * scale);
      for (glm::vec3& p : out.clip.translations) p = glm::vec3(glm::dvec3(p) * scale);
    }
  }

  Scanner s_;
  const std::string& name_;
  const BvhReadOptions& options_;
  std::vector<RawJoint> joints_;
  std::int64_t channel_total_ = 0;
  std::int64_t frames_ = 0;
  Token frames_token_;
  double frame_time_ = 0.0;
  bool has_translations_ = false;
};

}  // namespace

BvhFile parse_bvh(std::string_view text, const std::string& name, const BvhReadOptions& options) {
  const std::uint64_t limit = std::min<std::uint64_t>(options.limits.max_file_bytes, INT_MAX);
  if (text.size() > limit)
    throw Error(std::to_string(text.size()) + " bytes exceeds the limit of " + std::to_string(limit) + " bytes",
                at_line(name, 0));
  Parser parser(text, name, options);
  BvhFile out = parser.parse();
  out.bytes = text.size();
  return out;
}

BvhFile read_bvh(const std::string& path, const BvhReadOptions& options) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw Error("cannot read: " + ec.message(), at_line(path, 0));
  const std::uint64_t limit = std::min<std::uint64_t>(options.limits.max_file_bytes, INT_MAX);
  if (size > limit)
    throw Error(std::to_string(size) + " bytes exceeds the limit of " + std::to_string(limit) + " bytes",
                at_line(path, 0));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open for reading", at_line(path, 0));
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uint64_t>(in.gcount()) != size) throw Error("could not read the whole file", at_line(path, 0));
  return parse_bvh(text, path, options);
}

}  // namespace throng::io
