// Animation streams configured by YAML: rigs (the default humanoid or a
// skeleton from a BVH file), clips, shared streams with their controllers,
// and unique animations. The format is documented in docs/streams.md.
//
//   std::unique_ptr<anim::StreamCrowd> crowd = io::load_stream_crowd("crowd.yaml");
//   crowd->streams().find("walk_a");  crowd->uniques().find_animation("bow");
//
// Every error is a throng::Error at file:line:column, saying what was
// expected (unknown keys, wrong types, unknown names, values out of range).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "anim/stream_crowd.h"

namespace throng::io {

// Bounds on what a file may ask for, checked before allocating.
struct StreamsYamlLimits {
  std::size_t max_file_bytes = 4u << 20;
  std::size_t max_pose_bytes = 1u << 30;   // stream histories plus unique slots
  std::int32_t max_controller_depth = 16;  // nested layers and state machines
  std::int32_t max_items = 4096;           // rigs, clips, streams, states... each
};

struct StreamsYamlOptions {
  StreamsYamlLimits limits;
  // Relative BVH paths are resolved against this folder (load_stream_crowd:
  // the YAML file's folder).
  std::string base_dir = ".";
  bool allow_files = true;  // false: 'bvh:' is an error (fuzzing)
};

std::unique_ptr<anim::StreamCrowd> parse_stream_crowd(std::string_view text, const std::string& name,
                                                      const StreamsYamlOptions& options = {});
std::unique_ptr<anim::StreamCrowd> load_stream_crowd(const std::string& path, StreamsYamlLimits limits = {});

}  // namespace throng::io
