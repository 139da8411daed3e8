#include "render/image.h"

#include <fmt/format.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cstdlib>

#include "core/error.h"
#include "core/output_file.h"

namespace throng::render {

void write_png(const std::string& path, const Image& image) {
  if (image.empty()) throw Error("cannot write an empty image", at_field(path));
  bool opaque = true;
  for (std::size_t i = 3; i < image.rgba.size() && opaque; i += 4) opaque = image.rgba[i] == 255;
  std::vector<std::uint8_t> rgb;
  const void* data = image.rgba.data();
  int channels = 4;
  if (opaque) {
    rgb.resize(image.rgba.size() / 4 * 3);
    for (std::size_t p = 0, n = image.rgba.size() / 4; p < n; ++p)
      for (std::size_t c = 0; c < 3; ++c) rgb[p * 3 + c] = image.rgba[p * 4 + c];
    data = rgb.data();
    channels = 3;
  }
  OutputFile file(path);
  if (stbi_write_png(file.writing_path().c_str(), image.width, image.height, channels, data, image.width * channels) ==
      0)
    throw Error("cannot write the PNG file (is its folder there, is the disk full?)", at_field(path));
  file.commit();
}

Image read_png(const std::string& path) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
  if (data == nullptr) throw Error(fmt::format("cannot read the image: {}", stbi_failure_reason()), at_field(path));
  Image image(w, h);
  std::copy(data, data + image.rgba.size(), image.rgba.begin());
  stbi_image_free(data);
  return image;
}

ImageDifference compare_images(const Image& a, const Image& b, std::int32_t threshold) {
  if (a.width != b.width || a.height != b.height)
    throw Error(fmt::format("images differ in size: {}x{} and {}x{}", a.width, a.height, b.width, b.height));
  ImageDifference d;
  std::int64_t sum = 0, differing = 0;
  const std::size_t pixels = a.rgba.size() / 4;
  for (std::size_t p = 0; p < pixels; ++p) {
    std::int32_t worst = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::int32_t diff =
          std::abs(static_cast<std::int32_t>(a.rgba[p * 4 + c]) - static_cast<std::int32_t>(b.rgba[p * 4 + c]));
      sum += diff;
      worst = std::max(worst, diff);
    }
    d.max_abs = std::max(d.max_abs, worst);
    if (worst > threshold) ++differing;
  }
  if (pixels > 0) {
    d.mean_abs = static_cast<double>(sum) / static_cast<double>(pixels * 3);
    d.fraction_differing = static_cast<double>(differing) / static_cast<double>(pixels);
  }
  return d;
}

std::int32_t colour_distance(const Image& image, std::int32_t x, std::int32_t y, const std::uint8_t rgb[3]) {
  const std::uint8_t* p = image.pixel(x, y);
  std::int32_t worst = 0;
  for (int c = 0; c < 3; ++c)
    worst = std::max(worst, std::abs(static_cast<std::int32_t>(p[c]) - static_cast<std::int32_t>(rgb[c])));
  return worst;
}

}  // namespace throng::render
