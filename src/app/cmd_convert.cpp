// throng convert IN.bvh OUT.bvh: rewrites a file through the reader and the
// writer, with one rotation order for every joint and the chosen unit. The
// writer is chosen by OUT's extension; BVH is the only one so far.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/error.h"
#include "io/bvh_reader.h"
#include "io/bvh_writer.h"
#include "motion/rotation.h"
#include "motion/units.h"

namespace throng::app {

namespace {

// A writer of motion files, chosen by the output's extension.
struct MotionWriter {
  const char* extension;  // lower case, with the dot
  std::function<void(const std::string& path, const io::BvhFile& in, const io::BvhWriteOptions& options)> write;
};

const std::vector<MotionWriter>& motion_writers() {
  static const std::vector<MotionWriter> writers = {
      {".bvh", [](const std::string& path, const io::BvhFile& in, const io::BvhWriteOptions& options) {
         io::write_bvh(path, in.skeleton, in.clip, options);
       }}};
  return writers;
}

// The writer for `path`, or an Error listing the extensions there are writers for.
const MotionWriter& writer_for(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::vector<std::string> extensions;
  for (const MotionWriter& w : motion_writers()) {
    if (ext == w.extension) return w;
    extensions.emplace_back(w.extension);
  }
  const std::string supported = fmt::format("{}", fmt::join(extensions, ", "));
  Location where;
  where.file = path;
  if (ext.empty()) throw Error("no extension to choose the output format by (supported: " + supported + ")", where);
  throw Error("unknown output extension '" + ext + "' (supported: " + supported + ")", where);
}

}  // namespace

void add_convert_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("convert", "Rewrite a BVH file with one rotation order and unit");
  static std::string input, output;
  static std::string order = "ZXY";
  static std::string units = "cm";
  static std::string in_units = "auto";
  cmd->add_option("input", input, "BVH file to read")->required();
  cmd->add_option("output", output, "BVH file to write")->required();
  cmd->add_option("--order", order, "Rotation order of every joint: XYZ, XZY, YXZ, YZX, ZXY or ZYX (default ZXY)");
  cmd->add_option("--units", units, "Unit of the written file: m, cm, mm, in or cmu (default cm)");
  cmd->add_option("--in-units", in_units, "Unit of the input: auto (detect), m, cm, mm, in or cmu");
  cmd->callback([&g] {
    const MotionWriter& writer = writer_for(output);  // before reading: nothing is written under a wrong name
    apply_global_options(g);
    io::BvhWriteOptions w = bvh_write_options(order, units);
    io::BvhReadOptions r;
    if (in_units != "auto") {
      r.unit = motion::parse_length_unit(in_units);
      if (!r.unit) throw Error("unknown unit '" + in_units + "' (auto, m, cm, mm, in, cmu)", at_field("--in-units"));
    }
    const io::BvhFile bvh = io::read_bvh(input, r);
    w.frame_time = bvh.frame_time;
    writer.write(output, bvh, w);
    spdlog::info("{}: {} joints, {} frames, read as {} ({}), written as {} with order {}", output,
                 bvh.skeleton.joint_count(), bvh.clip.frame_count, motion::to_string(bvh.unit),
                 bvh.unit_detected ? "detected" : "given", motion::to_string(w.unit), motion::to_string(w.order));
  });
}

}  // namespace throng::app
