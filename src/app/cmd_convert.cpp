// throng convert IN.bvh OUT.bvh: rewrites a file through the reader and the
// writer, with one rotation order for every joint and the chosen unit.
#include <spdlog/spdlog.h>

#include <string>

#include "app/commands.h"
#include "core/error.h"
#include "io/bvh_reader.h"
#include "io/bvh_writer.h"
#include "motion/rotation.h"
#include "motion/units.h"

namespace throng::app {

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
    apply_global_options(g);
    io::BvhWriteOptions w;
    const auto o = motion::parse_euler_order(order);
    if (!o) throw Error("unknown rotation order '" + order + "' (XYZ, XZY, YXZ, YZX, ZXY, ZYX)", at_field("--order"));
    w.order = *o;
    const auto u = motion::parse_length_unit(units);
    if (!u) throw Error("unknown unit '" + units + "' (m, cm, mm, in, cmu)", at_field("--units"));
    w.unit = *u;
    io::BvhReadOptions r;
    if (in_units != "auto") {
      r.unit = motion::parse_length_unit(in_units);
      if (!r.unit) throw Error("unknown unit '" + in_units + "' (auto, m, cm, mm, in, cmu)", at_field("--in-units"));
    }
    const io::BvhFile bvh = io::read_bvh(input, r);
    w.frame_time = bvh.frame_time;
    io::write_bvh(output, bvh.skeleton, bvh.clip, w);
    spdlog::info("{}: {} joints, {} frames, read as {} ({}), written as {} with order {}", output, bvh.skeleton.joint_count(),
                 bvh.clip.frame_count, motion::to_string(bvh.unit), bvh.unit_detected ? "detected" : "given",
                 motion::to_string(w.unit), motion::to_string(w.order));
  });
}

}  // namespace throng::app
