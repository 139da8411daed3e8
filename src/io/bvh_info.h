// A BVH file described as JSON (what `throng info FILE.bvh --json` prints).
#pragma once

#include <nlohmann/json.hpp>

#include "io/bvh_reader.h"

namespace throng::io {

// Keys: file, bytes, joints, end_sites, channels, frames, frame_time,
// frame_rate, duration, units {unit, detected, metres_per_unit},
// rest_extent_m, rotation_orders {order: joint count}, roles {role: joint
// name or null}, spine_chain [names], skeleton [{name, parent, channels}].
nlohmann::json bvh_info(const BvhFile& file);

}  // namespace throng::io
