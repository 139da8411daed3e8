#include "render/image.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.h"

namespace throng::render {
namespace {

Image gradient(std::int32_t w, std::int32_t h, std::uint8_t alpha) {
  Image im(w, h);
  for (std::int32_t y = 0; y < h; ++y)
    for (std::int32_t x = 0; x < w; ++x) {
      std::uint8_t* p = im.rgba.data() +
                        (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 4;
      p[0] = static_cast<std::uint8_t>(x * 255 / (w - 1));
      p[1] = static_cast<std::uint8_t>(y * 255 / (h - 1));
      p[2] = static_cast<std::uint8_t>((x * 7 + y * 13) & 255);
      p[3] = alpha;
    }
  return im;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("throng_image_test_" + name)).string();
}

TEST(Png, OpaqueRoundTripIsExact) {
  const Image a = gradient(37, 21, 255);
  const std::string path = temp_path("opaque.png");
  write_png(path, a);
  const Image b = read_png(path);
  EXPECT_EQ(b.width, 37);
  EXPECT_EQ(b.height, 21);
  EXPECT_EQ(a.rgba, b.rgba);
  std::filesystem::remove(path);
}

TEST(Png, TranslucentRoundTripKeepsAlpha) {
  const Image a = gradient(8, 5, 100);
  const std::string path = temp_path("alpha.png");
  write_png(path, a);
  EXPECT_EQ(read_png(path).rgba, a.rgba);
  std::filesystem::remove(path);
}

TEST(Png, TopRowComesFirst) {
  Image a(2, 2);
  for (std::size_t i = 0; i < a.rgba.size(); ++i) a.rgba[i] = 255;
  a.rgba[0] = 0;  // top-left pixel: no red
  const std::string path = temp_path("rows.png");
  write_png(path, a);
  const Image b = read_png(path);
  EXPECT_EQ(b.pixel(0, 0)[0], 0);
  EXPECT_EQ(b.pixel(0, 1)[0], 255);
  std::filesystem::remove(path);
}

TEST(Png, ErrorsNameThePath) {
  try {
    write_png("/nonexistent-folder/x.png", gradient(4, 4, 255));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/x.png"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_png("/nonexistent-folder/x.png"), Error);
  EXPECT_THROW(write_png(temp_path("empty.png"), Image()), Error);
}

TEST(CompareImages, CountsDifferingPixels) {
  Image a = gradient(10, 10, 255), b = a;
  EXPECT_EQ(compare_images(a, b).max_abs, 0);
  b.rgba[0] = static_cast<std::uint8_t>(a.rgba[0] + 100 > 255 ? a.rgba[0] - 100 : a.rgba[0] + 100);
  b.rgba[4 * 50 + 1] = static_cast<std::uint8_t>(a.rgba[4 * 50 + 1] ^ 4);  // a small difference
  const ImageDifference d = compare_images(a, b, 16);
  EXPECT_EQ(d.max_abs, 100);
  EXPECT_DOUBLE_EQ(d.fraction_differing, 0.01);
  EXPECT_NEAR(d.mean_abs, (100.0 + 4.0) / 300.0, 1e-9);
  EXPECT_THROW(compare_images(a, gradient(10, 11, 255)), Error);
}

}  // namespace
}  // namespace throng::render
