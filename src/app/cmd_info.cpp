#include <fmt/format.h>
#include <oneapi/tbb/version.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/version.h"
#include "core/cuda_runtime.h"
#include "core/error.h"
#include "core/exec.h"
#include "io/bvh_info.h"
#include "io/bvh_reader.h"
#include "motion/cycle.h"

namespace throng::app {

namespace {

// "--units auto|m|cm|mm|in|cmu" -> the reader's option (nullopt = detect).
std::optional<motion::LengthUnit> units_option(const std::string& text, const char* option) {
  if (text == "auto") return std::nullopt;
  const auto u = motion::parse_length_unit(text);
  if (!u) throw Error("unknown unit '" + text + "' (auto, m, cm, mm, in, cmu)", at_field(option));
  return u;
}

// "--role left_knee=lShin" -> an override.
std::vector<motion::RoleOverride> role_options(const std::vector<std::string>& items) {
  std::vector<motion::RoleOverride> out;
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    const auto role = motion::parse_role(item.substr(0, eq));
    if (eq == std::string::npos || !role || eq + 1 == item.size())
      throw Error(
          "expected ROLE=JOINT with ROLE one of hips, neck, head, left_shoulder, ..., right_toe; got '" + item + "'",
          at_field("--role"));
    out.push_back({*role, item.substr(eq + 1)});
  }
  return out;
}

// The best loop of a locomotion clip (motion/cycle.h); null when the clip
// has no cycle in range, {"error": ...} when it cannot be analysed.
nlohmann::json cycle_info(const io::BvhFile& bvh) {
  motion::CycleReport c;
  try {
    c = motion::analyze_cycle(bvh.skeleton, bvh.clip);
  } catch (const Error& e) {
    return {{"error", e.message()}};
  }
  if (!c.found) return nullptr;
  nlohmann::json contacts = nlohmann::json::array();
  for (const auto& foot : c.contacts.feet) {
    nlohmann::json intervals = nlohmann::json::array();
    for (const auto& i : foot.intervals) intervals.push_back({i.begin, i.end});
    contacts.push_back(intervals);
  }
  return {{"start_frame", c.start_frame},
          {"end_frame", c.end_frame},
          {"period_frames", c.period_frames},
          {"period_s", c.period_s},
          {"steps", c.steps},
          {"cadence_steps_per_min", c.cadence},
          {"stride_length_m", c.stride_length},
          {"mean_speed_m_s", c.mean_speed},
          {"turn_rate_rad_s", c.turn_rate},
          {"pose_rms_m", c.pose_rms_m},
          {"input_is_loop", c.input_is_loop},
          {"contacts_left_right", contacts}};
}

bool has_bvh_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>((c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c);
  return ext == ".bvh";
}

void print_text(const nlohmann::json& j) {
  std::printf("%-12s %s\n", "file", j["file"].get<std::string>().c_str());
  std::printf("%-12s %d (%d end sites), %d channels\n", "joints", j["joints"].get<int>(), j["end_sites"].get<int>(),
              j["channels"].get<int>());
  std::printf("%-12s %d at %.9g s (%.4g fps), %.3f s\n", "frames", j["frames"].get<int>(),
              j["frame_time"].get<double>(), j["frame_rate"].get<double>(), j["duration"].get<double>());
  const auto& u = j["units"];
  std::printf("%-12s %s (%s), %.9g m per unit; rest pose %.3f m across\n", "units",
              u["unit"].get<std::string>().c_str(), u["detected"].get<bool>() ? "detected" : "given",
              u["metres_per_unit"].get<double>(), j["rest_extent_m"].get<double>());
  std::string orders;
  for (auto& [order, count] : j["rotation_orders"].items())
    orders += fmt::format("{}{} x{}", orders.empty() ? "" : ", ", order, count.get<int>());
  std::printf("%-12s %s\n", "rotations", orders.c_str());
  std::string found, missing;
  for (std::size_t r = 0; r < motion::kRoleCount; ++r) {  // in Role order, not the JSON's sorted keys
    const std::string role = motion::to_string(static_cast<motion::Role>(r));
    const auto& joint = j["roles"][role];
    if (joint.is_null()) {
      missing += (missing.empty() ? "" : " ") + role;
    } else {
      found += fmt::format("{}{}={}", found.empty() ? "" : " ", role, joint.get<std::string>());
    }
  }
  std::printf("%-12s %s\n", "roles", found.c_str());
  if (!missing.empty()) std::printf("%-12s %s\n", "not found", missing.c_str());
  std::string spine;
  for (const auto& s : j["spine_chain"]) spine += (spine.empty() ? "" : " ") + s.get<std::string>();
  std::printf("%-12s %s\n", "spine", spine.c_str());
  const auto& c = j["cycle"];
  if (c.is_null()) {
    std::printf("%-12s none found\n", "cycle");
  } else if (c.contains("error")) {
    std::printf("%-12s not analysed: %s\n", "cycle", c["error"].get<std::string>().c_str());
  } else {
    std::printf(
        "%-12s frames %d..%d (%.3f s), %d steps, cadence %.1f steps/min, stride %.2f m, mean speed %.2f m/s, turn %.1f "
        "deg/s\n",
        "cycle", c["start_frame"].get<int>(), c["end_frame"].get<int>(), c["period_s"].get<double>(),
        c["steps"].get<int>(), c["cadence_steps_per_min"].get<double>(), c["stride_length_m"].get<double>(),
        c["mean_speed_m_s"].get<double>(), c["turn_rate_rad_s"].get<double>() * 57.29577951308232);
  }
}

}  // namespace

void add_info_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("info", "Describe this build and machine, or a motion file (FILE.bvh)");
  static bool as_json = false;
  static std::string file;
  static std::string units = "auto";
  static std::vector<std::string> roles;
  cmd->add_option("file", file, "A BVH file to describe");
  cmd->add_flag("--json", as_json, "Print JSON instead of text");
  cmd->add_option("--units", units, "Length unit of FILE: auto, m, cm, mm, in or cmu (CMU ASF units)");
  cmd->add_option("--role", roles, "Role override ROLE=JOINT (e.g. left_knee=lShin); repeatable");
  cmd->callback([&g] {
    apply_global_options(g);
    if (!file.empty()) {
      if (!has_bvh_extension(file))
        throw Error("cannot describe this file type (expected a .bvh file)", at_line(file, 0));
      io::BvhReadOptions options;
      options.unit = units_option(units, "--units");
      options.role_overrides = role_options(roles);
      const io::BvhFile bvh = io::read_bvh(file, options);
      nlohmann::json j = io::bvh_info(bvh);
      j["cycle"] = cycle_info(bvh);
      if (as_json) {
        std::printf("%s\n", j.dump(2).c_str());
      } else {
        print_text(j);
      }
      return;
    }
    nlohmann::json j = {{"version", kVersion},
                        {"build_type", kBuildType},
                        {"compiler", kCompiler},
                        {"tbb", TBB_VERSION_STRING},
                        {"hardware_threads", hardware_threads()},
                        {"threads", current_threads()},
                        {"backend", to_string(current_backend())},
                        {"cuda", cuda_status()}};
    if (as_json) {
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    for (auto& [k, v] : j.items())
      std::printf("%-17s %s\n", k.c_str(), v.is_string() ? v.get<std::string>().c_str() : v.dump().c_str());
  });
}

}  // namespace throng::app
