// Where an overlay changed a picture: the pixels that differ between two
// drawings of one scene, with and without it, and how many of them turned
// towards the overlay's colour (line edges blend it with what is below).
#pragma once

#include <cstdint>

#include <glm/vec4.hpp>

#include "render/image.h"

namespace throng::render::testing {

struct OverlayPixels {
  std::int64_t differing = 0;  // channels apart by more than 16
  std::int64_t towards = 0;    // of them, at least 16 nearer `colour` than before
};

inline OverlayPixels overlay_pixels(const Image& with, const Image& without, glm::vec4 colour) {
  const std::uint8_t rgb[3] = {static_cast<std::uint8_t>(255 * colour.r), static_cast<std::uint8_t>(255 * colour.g),
                               static_cast<std::uint8_t>(255 * colour.b)};
  OverlayPixels o;
  for (std::int32_t y = 0; y < with.height; ++y)
    for (std::int32_t x = 0; x < with.width; ++x) {
      if (colour_distance(with, x, y, without.pixel(x, y)) <= 16) continue;
      ++o.differing;
      o.towards += colour_distance(with, x, y, rgb) + 16 <= colour_distance(without, x, y, rgb) ? 1 : 0;
    }
  return o;
}

}  // namespace throng::render::testing
