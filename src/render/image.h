// RGBA8 images: what the renderer reads back, PNG files, comparisons.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace throng::render {

// Rows top to bottom (row 0 is the top of the picture), 4 bytes a pixel.
struct Image {
  std::int32_t width = 0;
  std::int32_t height = 0;
  std::vector<std::uint8_t> rgba;

  Image() = default;
  Image(std::int32_t w, std::int32_t h)
      : width(w), height(h), rgba(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4u, 0) {}
  bool empty() const { return width <= 0 || height <= 0; }
  const std::uint8_t* pixel(std::int32_t x, std::int32_t y) const {
    return rgba.data() +
           (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4u;
  }
};

// Writes a PNG (RGB when every alpha is 255, else RGBA); throws Error naming
// the path when it cannot.
void write_png(const std::string& path, const Image& image);
// Reads a PNG as RGBA8; throws Error naming the path.
Image read_png(const std::string& path);

struct ImageDifference {
  double mean_abs = 0.0;          // mean over every channel of |a - b|, in 0..255
  std::int32_t max_abs = 0;       // largest channel difference
  double fraction_differing = 0;  // pixels with any channel differing by more than `threshold`
};
// Throws Error when the sizes differ. Alpha is ignored.
ImageDifference compare_images(const Image& a, const Image& b, std::int32_t threshold = 16);

// Largest channel difference between the pixel at (x, y) and `rgb`.
std::int32_t colour_distance(const Image& image, std::int32_t x, std::int32_t y, const std::uint8_t rgb[3]);

}  // namespace throng::render
