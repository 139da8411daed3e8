#include "motion/roles.h"

#include <algorithm>
#include <array>

#include "core/error.h"

namespace throng::motion {

namespace {

bool is_separator(char c) { return c == '_' || c == ' ' || c == '.' || c == '-' || c == '\t'; }
char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

std::string lower_copy(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = lower(c);
  return out;
}

// Lower case, separators dropped, trailing digits dropped ("Toe_0" -> "toe").
std::string body_part(std::string_view s) {
  std::string out;
  for (char c : s)
    if (!is_separator(c)) out.push_back(lower(c));
  while (!out.empty() && out.back() >= '0' && out.back() <= '9') out.pop_back();
  return out;
}

// Words that may follow a one-letter side prefix ("lhand", "rShin"). They
// keep "lowerback" or "leg" from being read as left + "owerback" / "eg".
constexpr std::array<std::string_view, 52> kLimbWords = {
    "hipjoint", "hip",      "upleg",    "upperleg", "thigh",    "femur",    "leg",    "knee",     "shin",
    "calf",     "tibia",    "lowleg",   "lowerleg", "foot",     "ankle",    "toe",    "ball",     "heel",
    "arm",      "uparm",    "upperarm", "humerus",  "shoulder", "shldr",    "collar", "clavicle", "forearm",
    "elbow",    "lowerarm", "lowarm",   "radius",   "wrist",    "hand",     "finger", "thumb",    "index",
    "mid",      "middle",   "ring",     "pinky",    "pinkie",   "eye",      "ear",    "buttock",  "breast",
    "brow",     "cheek",    "lid",      "lip",      "mouth",    "pectoral", "scapula"};

bool starts_with_limb_word(std::string_view part) {
  for (std::string_view w : kLimbWords)
    if (part.substr(0, w.size()) == w) return true;
  return false;
}

bool one_of(std::string_view part, std::initializer_list<std::string_view> words) {
  return std::find(words.begin(), words.end(), part) != words.end();
}

bool is_ancestor(const Skeleton& s, std::int32_t ancestor, std::int32_t j) {
  for (std::int32_t p = j; p >= 0; p = s.parents[static_cast<std::size_t>(p)])
    if (p == ancestor) return true;
  return false;
}

std::int32_t first_child(const Skeleton& s, std::int32_t j) {
  for (std::int32_t i = j + 1; i < s.joint_count(); ++i)
    if (s.parents[static_cast<std::size_t>(i)] == j) return i;
  return -1;
}

struct Finder {
  const Skeleton& s;
  std::vector<JointName> names;

  explicit Finder(const Skeleton& sk) : s(sk) {
    names.reserve(sk.names.size());
    for (const auto& n : sk.names) names.push_back(split_joint_name(n));
  }
  // First joint (in parent-before-child order) on `side` whose part is one
  // of `words`, optionally below `under`.
  std::int32_t find(Side side, std::initializer_list<std::string_view> words, std::int32_t under = -1) const {
    for (std::int32_t j = 0; j < s.joint_count(); ++j) {
      const auto& n = names[static_cast<std::size_t>(j)];
      if (n.side != side || !one_of(n.part, words)) continue;
      if (under >= 0 && (j == under || !is_ancestor(s, under, j))) continue;
      return j;
    }
    return -1;
  }
};

struct Limb {
  std::int32_t root = -1, middle = -1, end = -1, tip = -1;
};

// A limb from its middle joint (knee, elbow): root = parent, end = first
// joint below it named like an end, else its first child.
Limb find_limb(const Finder& f, Side side, std::initializer_list<std::string_view> middle_words,
               std::initializer_list<std::string_view> root_words, std::initializer_list<std::string_view> end_words,
               std::initializer_list<std::string_view> tip_words) {
  Limb l;
  l.middle = f.find(side, middle_words);
  if (l.middle >= 0) {
    l.root = f.s.parents[static_cast<std::size_t>(l.middle)];
  } else {
    l.root = f.find(side, root_words);
    if (l.root >= 0) l.middle = first_child(f.s, l.root);
  }
  if (l.middle < 0) return l;
  l.end = f.find(side, end_words, l.middle);
  if (l.end < 0) l.end = first_child(f.s, l.middle);
  if (l.end < 0) return l;
  l.tip = f.find(side, tip_words, l.end);
  if (l.tip < 0) l.tip = first_child(f.s, l.end);
  return l;
}

}  // namespace

JointName split_joint_name(std::string_view name) {
  // Namespaces ("mixamorig:Hips", "rig|Hips") and Biped prefixes ("Bip01 ").
  if (const auto cut = name.find_last_of(":|"); cut != std::string_view::npos) name.remove_prefix(cut + 1);
  {
    const std::string l = lower_copy(name.substr(0, 3));
    if (l == "bip") {
      std::size_t i = 3;
      while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i;
      while (i < name.size() && is_separator(name[i])) ++i;
      name.remove_prefix(i);
    }
  }
  const std::string l = lower_copy(name);
  JointName out;
  auto try_side = [&](Side side, std::string_view rest, bool need_limb_word) {
    const std::string part = body_part(rest);
    if (part.empty() || (need_limb_word && !starts_with_limb_word(part))) return false;
    out.side = side;
    out.part = part;
    return true;
  };
  // Full words: "LeftUpLeg", "left_knee", "KneeLeft", "knee_left".
  if (l.rfind("left", 0) == 0 && try_side(Side::Left, name.substr(4), false)) return out;
  if (l.rfind("right", 0) == 0 && try_side(Side::Right, name.substr(5), false)) return out;
  if (l.size() > 4 && l.compare(l.size() - 4, 4, "left") == 0 &&
      try_side(Side::Left, name.substr(0, l.size() - 4), false))
    return out;
  if (l.size() > 5 && l.compare(l.size() - 5, 5, "right") == 0 &&
      try_side(Side::Right, name.substr(0, l.size() - 5), false))
    return out;
  // One letter: "lShldr", "L_Knee", "lhumerus", "knee_l", "ThighL".
  if (l.size() > 1 && (l[0] == 'l' || l[0] == 'r')) {
    const Side side = l[0] == 'l' ? Side::Left : Side::Right;
    if (try_side(side, name.substr(1), true)) return out;
  }
  if (l.size() > 1 && (l.back() == 'l' || l.back() == 'r')) {
    const Side side = l.back() == 'l' ? Side::Left : Side::Right;
    const std::string_view rest = name.substr(0, name.size() - 1);
    // Only with a separator or a case change before it ("knee_l", "ThighL").
    const char before = name[name.size() - 2];
    const bool marked =
        is_separator(before) || (name.back() >= 'A' && name.back() <= 'Z' && before >= 'a' && before <= 'z');
    if (marked && try_side(side, rest, true)) return out;
  }
  out.side = Side::Center;
  out.part = body_part(name);
  return out;
}

std::optional<Role> parse_role(std::string_view name) {
  const std::string l = lower_copy(name);
  for (std::size_t i = 0; i < kRoleCount; ++i)
    if (l == to_string(static_cast<Role>(i))) return static_cast<Role>(i);
  return std::nullopt;
}

std::vector<std::int32_t> chain_between(const Skeleton& skeleton, std::int32_t from, std::int32_t to) {
  std::vector<std::int32_t> chain;
  if (from < 0 || to < 0 || to == from) return chain;
  for (std::int32_t p = skeleton.parents[static_cast<std::size_t>(to)]; p != from;
       p = skeleton.parents[static_cast<std::size_t>(p)]) {
    if (p < 0) return {};
    chain.push_back(p);
  }
  std::reverse(chain.begin(), chain.end());
  return chain;
}

void assign_roles(Skeleton& s, const std::vector<RoleOverride>& overrides) {
  s.roles.fill(-1);
  s.spine_chain.clear();
  if (s.joint_count() == 0) return;
  const Finder f(s);
  auto set = [&](Role r, std::int32_t j) { s.roles[static_cast<std::size_t>(r)] = j; };

  std::int32_t hips = f.find(Side::Center, {"hips", "hip", "pelvis"});
  set(Role::Hips, hips >= 0 ? hips : 0);
  const std::int32_t head = f.find(Side::Center, {"head"});
  set(Role::Head, head);
  if (head >= 0) {
    // The neck is the lowest neck-named joint above the head ("lowerneck"
    // before "Neck", "Neck" before "Neck1"), else the head's parent.
    std::int32_t neck = -1;
    for (std::int32_t p = s.parents[static_cast<std::size_t>(head)]; p >= 0; p = s.parents[static_cast<std::size_t>(p)])
      if (f.names[static_cast<std::size_t>(p)].part.find("neck") != std::string::npos) neck = p;
    if (neck < 0) {
      const std::int32_t p = s.parents[static_cast<std::size_t>(head)];
      if (p >= 0 && p != s.role(Role::Hips)) neck = p;
    }
    set(Role::Neck, neck);
  }

  for (Side side : {Side::Left, Side::Right}) {
    const bool left = side == Side::Left;
    const Limb leg =
        find_limb(f, side, {"leg", "knee", "shin", "calf", "tibia", "lowerleg", "leglower", "lowleg", "loleg"},
                  {"upleg", "upperleg", "legupper", "thigh", "femur", "hip"}, {"ankle", "foot"},
                  {"toe", "toes", "toebase", "ball"});
    set(left ? Role::LeftThigh : Role::RightThigh, leg.root);
    set(left ? Role::LeftKnee : Role::RightKnee, leg.middle);
    set(left ? Role::LeftAnkle : Role::RightAnkle, leg.end);
    set(left ? Role::LeftToe : Role::RightToe, leg.tip);
    const Limb arm = find_limb(f, side, {"forearm", "elbow", "lowerarm", "armlower", "lowarm", "loarm", "radius"},
                               {"upperarm", "armupper", "uparm", "arm", "humerus", "shldr"}, {"wrist", "hand"}, {});
    set(left ? Role::LeftShoulder : Role::RightShoulder, arm.root);
    set(left ? Role::LeftElbow : Role::RightElbow, arm.middle);
    set(left ? Role::LeftWrist : Role::RightWrist, arm.end);
  }

  for (const auto& o : overrides) {
    const std::int32_t j = s.find(o.joint);
    if (j < 0) throw Error("no joint named '" + o.joint + "'", at_field(std::string("roles.") + to_string(o.role)));
    set(o.role, j);
  }

  const std::int32_t top = s.role(Role::Neck) >= 0 ? s.role(Role::Neck) : s.role(Role::Head);
  s.spine_chain = chain_between(s, s.role(Role::Hips), top);
}

}  // namespace throng::motion
