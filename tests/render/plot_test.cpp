#include "render/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace throng::render {
namespace {

constexpr Rgb kRed{200, 30, 40};
constexpr Rgb kBlue{20, 60, 210};
constexpr Rgb kWhite{255, 255, 255};

// Largest channel difference between pixel (x, y) and `c`.
std::int32_t distance(const Image& im, std::int32_t x, std::int32_t y, Rgb c) {
  const std::uint8_t rgb[3] = {c.r, c.g, c.b};
  return colour_distance(im, x, y, rgb);
}

// The pixel holding the data point (x, y).
std::pair<std::int32_t, std::int32_t> pixel_of(const ChartFrame& f, double x, double y) {
  const glm::vec2 p = f.to_pixel(x, y);
  return {static_cast<std::int32_t>(std::floor(p.x)), static_cast<std::int32_t>(std::floor(p.y))};
}

// The pixel nearest in colour to `c` within +-1 px of the data point.
std::int32_t nearest_distance(const Image& im, const ChartFrame& f, double x, double y, Rgb c) {
  const auto [px, py] = pixel_of(f, x, y);
  std::int32_t best = 255;
  for (std::int32_t dy = -1; dy <= 1; ++dy)
    for (std::int32_t dx = -1; dx <= 1; ++dx) best = std::min(best, distance(im, px + dx, py + dy, c));
  return best;
}

std::int32_t distance_at(const Image& im, const ChartFrame& f, double x, double y, Rgb c) {
  const auto [px, py] = pixel_of(f, x, y);
  return distance(im, px, py, c);
}

// Pixels with every channel below 100 in columns [x0, x1), rows [y0, y1).
int dark_pixels(const Image& im, std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1) {
  int n = 0;
  for (std::int32_t y = y0; y < y1; ++y)
    for (std::int32_t x = x0; x < x1; ++x) {
      const std::uint8_t* p = im.pixel(x, y);
      n += p[0] < 100 && p[1] < 100 && p[2] < 100 ? 1 : 0;
    }
  return n;
}

// A series (aggregate initialisation of a prefix would warn: -Wmissing-field-initializers).
PlotSeries series(std::string label, std::vector<double> x, std::vector<double> y,
                  PlotSeries::Style style = PlotSeries::Style::Line, std::optional<Rgb> colour = std::nullopt) {
  PlotSeries s;
  s.label = std::move(label), s.x = std::move(x), s.y = std::move(y), s.style = style, s.colour = colour;
  return s;
}

Chart unit_chart() {
  Chart c;
  c.x_min = 0, c.x_max = 1, c.y_min = 0, c.y_max = 1;
  return c;
}

void expect_ticks(const std::vector<double>& got, const std::vector<double>& want) {
  ASSERT_EQ(got.size(), want.size()) << "first " << (got.empty() ? NAN : got.front());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_DOUBLE_EQ(got[i], want[i]) << "tick " << i;
}

TEST(PlotTicks, UnitRangeInFifths) { expect_ticks(nice_ticks(0, 1), {0, 0.2, 0.4, 0.6, 0.8, 1.0}); }

TEST(PlotTicks, StepIsTheSmallestNiceOneOfAtLeastTheRangeOverTarget) {
  // 1.34 / 6 = 0.223: 0.25, the last tick the first multiple of it at or above 1.34.
  expect_ticks(nice_ticks(0, 1.34), {0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5});
  // 100 / 6 = 16.7: 20, from the multiple at or below -3.
  expect_ticks(nice_ticks(-3, 97), {-20, 0, 20, 40, 60, 80, 100});
  // 9 / 3 = 3: 5.
  expect_ticks(nice_ticks(0.5, 9.5, 3), {0, 5, 10});
  // Small and large magnitudes: 0.006 / 6 = 0.001; 5e6 / 5 = 1e6.
  expect_ticks(nice_ticks(0.002, 0.008), {0.002, 0.003, 0.004, 0.005, 0.006, 0.007, 0.008});
  expect_ticks(nice_ticks(0, 5e6, 5), {0, 1e6, 2e6, 3e6, 4e6, 5e6});
}

TEST(PlotTicks, DegenerateAndReversedRanges) {
  // lo == hi: widened by 10% (1 at zero).
  expect_ticks(nice_ticks(0, 0), {-1, -0.5, 0, 0.5, 1});  // [-1, 1]: 2 / 6 = 0.33 -> 0.5
  expect_ticks(nice_ticks(10, 10), {9, 9.5, 10, 10.5, 11});
  expect_ticks(nice_ticks(1, 0), nice_ticks(0, 1));
  EXPECT_THROW(nice_ticks(0, std::numeric_limits<double>::infinity()), Error);
  EXPECT_THROW(nice_ticks(0, 1, 0), Error);
}

TEST(PlotTicks, LabelsShowTheStepsDecimals) {
  EXPECT_EQ(tick_label(0.5, 0.25), "0.50");
  EXPECT_EQ(tick_label(0.6000000000000001, 0.2), "0.6");
  EXPECT_EQ(tick_label(-20, 20), "-20");
  EXPECT_EQ(tick_label(1e-17, 0.2), "0.0");
  EXPECT_EQ(tick_label(2e6, 1e6), "2e+06");
  EXPECT_EQ(tick_label(0, 1e-5), "0");  // the same format as its neighbour "1e-05"
  EXPECT_EQ(tick_label(3e-5, 1e-5), "3e-05");
}

TEST(PlotFrame, ExplicitRangesAreKeptAndAutoRangesWidenToTicks) {
  Chart c = unit_chart();
  ChartFrame f = chart_frame(c);
  EXPECT_EQ(f.x_min, 0);
  EXPECT_EQ(f.y_max, 1);
  EXPECT_LT(f.left, f.right);
  EXPECT_LT(f.top, f.bottom);
  EXPECT_EQ(f.to_pixel(0, 0), glm::vec2(f.left, f.bottom));
  EXPECT_EQ(f.to_pixel(1, 1), glm::vec2(f.right, f.top));

  Chart a;
  a.series.push_back(series("", {-3, 97}, {0.1, 1.34}));
  f = chart_frame(a);
  EXPECT_DOUBLE_EQ(f.x_min, -20);
  EXPECT_DOUBLE_EQ(f.x_max, 100);
  EXPECT_DOUBLE_EQ(f.y_min, 0);
  EXPECT_DOUBLE_EQ(f.y_max, 1.4);  // 1.24 / 7 (500 px: 7 y ticks) = 0.18 -> 0.2

  a.bands.push_back({false, -1, 0.5, "", {}});  // a band widens the y range
  EXPECT_DOUBLE_EQ(chart_frame(a).y_min, -1);
  a.y_min = 0.5;  // one bound given: kept, the other from the data
  EXPECT_DOUBLE_EQ(chart_frame(a).y_min, 0.5);
  EXPECT_DOUBLE_EQ(chart_frame(a).y_max, 1.4);
}

TEST(PlotFrame, NoFiniteDataGivesTheUnitRange) {
  Chart c;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.series.push_back(series("empty", {nan, 1}, {2, nan}));
  c.series.push_back(series("none", {}, {}));
  const ChartFrame f = chart_frame(c);
  EXPECT_EQ(f.x_min, 0);
  EXPECT_EQ(f.x_max, 1);
  EXPECT_EQ(f.y_min, 0);
  EXPECT_EQ(f.y_max, 1);
  const Image im = draw_chart(c);
  EXPECT_EQ(im.width, 800);
  EXPECT_EQ(im.height, 500);
}

TEST(PlotDraw, LineRunsThroughItsPointsAndNowhereElse) {
  Chart c = unit_chart();
  c.series.push_back(series("diagonal", {0, 1}, {0, 1}, PlotSeries::Style::Line, kRed));
  const ChartFrame f = chart_frame(c);
  const Image im = draw_chart(c);
  for (const double t : {0.1, 0.3, 0.5, 0.77, 0.9}) EXPECT_LE(nearest_distance(im, f, t, t, kRed), 8) << t;
  // 0.1 off the diagonal is tens of pixels away: background or grid, not red.
  for (const double t : {0.3, 0.5, 0.7}) {
    EXPECT_GT(distance_at(im, f, t, t + 0.1, kRed), 100) << t;
    EXPECT_GT(distance_at(im, f, t + 0.1, t, kRed), 100) << t;
  }
  // At least `width` (2) px thick: across the diagonal, two pixels in a row are red.
  const auto [px, py] = pixel_of(f, 0.5, 0.5);
  int red_in_row = 0;
  for (std::int32_t dx = -4; dx <= 4; ++dx) red_in_row += distance(im, px + dx, py, kRed) <= 60 ? 1 : 0;
  EXPECT_GE(red_in_row, 2);
  EXPECT_LE(red_in_row, 5);
}

TEST(PlotDraw, LineBreaksAtNonFinitePointsAndIsClippedToThePlot) {
  Chart c = unit_chart();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.series.push_back(series("", {0.1, 0.3, 0.5, 0.7, 0.9}, {0.5, 0.5, nan, 0.5, 0.5}, PlotSeries::Style::Line, kRed));
  c.series.push_back(series("", {-1, 2}, {0.25, 0.25}, PlotSeries::Style::Line, kBlue));  // runs past both edges
  const ChartFrame f = chart_frame(c);
  const Image im = draw_chart(c);
  EXPECT_LE(nearest_distance(im, f, 0.2, 0.5, kRed), 8);
  EXPECT_LE(nearest_distance(im, f, 0.8, 0.5, kRed), 8);
  EXPECT_GT(nearest_distance(im, f, 0.5, 0.5, kRed), 100);  // the gap around the NaN
  EXPECT_LE(nearest_distance(im, f, 0.5, 0.25, kBlue), 8);
  const auto [px, py] = pixel_of(f, 0, 0.25);
  EXPECT_GT(distance(im, px - 12, py, kBlue), 100);  // left of the plot: tick labels' margin, no line
}

TEST(PlotDraw, BarsAndPointsLandWhereTheFrameSays) {
  Chart c;
  c.x_min = 0, c.x_max = 4, c.y_min = 0, c.y_max = 5;
  c.series.push_back(series("bars", {1, 2, 3}, {2, 4, 3}, PlotSeries::Style::Bars, kBlue));
  c.series.push_back(series("points", {0.5, 3.5}, {4.5, 1.5}, PlotSeries::Style::Points, kRed));
  const ChartFrame f = chart_frame(c);
  const Image im = draw_chart(c);
  EXPECT_LE(distance_at(im, f, 2, 2, kBlue), 2);  // inside bar 2 (0..4, x 1.6..2.4)
  EXPECT_LE(distance_at(im, f, 2.3, 3.5, kBlue), 2);
  EXPECT_GT(distance_at(im, f, 2, 4.5, kBlue), 100);    // above it
  EXPECT_GT(distance_at(im, f, 1.5, 0.7, kBlue), 100);  // between bars 1 and 2
  EXPECT_LE(distance_at(im, f, 0.5, 4.5, kRed), 2);     // point centres
  EXPECT_LE(distance_at(im, f, 3.5, 1.5, kRed), 2);
  EXPECT_GT(distance_at(im, f, 0.5 + 0.2, 4.5, kRed), 100);  // 0.2 x units ~ 37 px off
}

TEST(PlotDraw, BandsShadeTheirRange) {
  Chart c;
  c.x_min = 0, c.x_max = 4, c.y_min = 0, c.y_max = 5;
  c.bands.push_back({false, 1, 2, "", Rgb{0, 0, 255}});
  c.bands.push_back({true, 3.5, 3, "", Rgb{255, 0, 0}});  // either order
  c.bands.push_back({false, 3.5, 4, "", std::nullopt});   // the first default band: black at 20%, grey
  const ChartFrame f = chart_frame(c);
  const Image im = draw_chart(c);
  const Rgb blue_tint{204, 204, 255}, red_tint{255, 204, 204};  // 20% over white
  EXPECT_LE(distance_at(im, f, 0.5, 1.5, blue_tint), 2);
  EXPECT_LE(distance_at(im, f, 3.25, 4.5, red_tint), 2);
  EXPECT_LE(distance_at(im, f, 0.5, 3.75, Rgb{204, 204, 204}), 2);
  EXPECT_LE(distance_at(im, f, 3.25, 3.75, Rgb{204, 163, 163}), 2);  // red over grey
  EXPECT_LE(distance_at(im, f, 0.5, 2.5, kWhite), 0);
  EXPECT_LE(distance_at(im, f, 2.5, 0.5, kWhite), 0);
}

TEST(PlotDraw, TitleIsDrawnAboveThePlot) {
  Chart c = unit_chart();
  const ChartFrame plain = chart_frame(c);
  const Image without = draw_chart(c);
  const std::int32_t l = static_cast<std::int32_t>(plain.left) + 1, r = static_cast<std::int32_t>(plain.right);
  EXPECT_EQ(dark_pixels(without, l, 0, r, static_cast<std::int32_t>(plain.top)), 0);

  c.title = "Fundamental diagram";
  const ChartFrame titled = chart_frame(c);
  EXPECT_GT(titled.top, plain.top);
  const Image with = draw_chart(c);
  EXPECT_GT(dark_pixels(with, l, 0, r, static_cast<std::int32_t>(titled.top)), 100);
  // Centred: as much ink left of the middle as right of it, within a letter.
  const int left_ink = dark_pixels(with, 0, 0, 400, static_cast<std::int32_t>(titled.top));
  const int right_ink = dark_pixels(with, 400, 0, 800, static_cast<std::int32_t>(titled.top));
  EXPECT_NEAR(left_ink, right_ink, 0.25 * (left_ink + right_ink));
}

TEST(PlotDraw, AxisLabelsAndLegendAddInk) {
  Chart c = unit_chart();
  c.series.push_back(series("", {0, 1}, {1, 0}));
  const int bare = dark_pixels(draw_chart(c), 0, 0, 800, 500);
  c.x_label = "density (1/m²)";
  c.y_label = "speed (m/s)";
  const ChartFrame f = chart_frame(c);
  const Image labelled = draw_chart(c);
  EXPECT_GT(dark_pixels(labelled, 0, static_cast<std::int32_t>(f.bottom) + 25, 800, 500), 50);  // x label
  EXPECT_GT(dark_pixels(labelled, 0, 0, 25, 500), 30);                                          // y label, turned
  c.series[0].label = "Weidmann";
  EXPECT_GT(dark_pixels(draw_chart(c), 0, 0, 800, 500), dark_pixels(labelled, 0, 0, 800, 500) + 30);
  EXPECT_GT(dark_pixels(labelled, 0, 0, 800, 500), bare);
}

TEST(PlotDraw, TickLabelsOfANarrowChartKeepApart) {
  Chart c;
  c.width = 200, c.height = 200;
  c.series.push_back(series("", {0, 1e6, 2e6, 3e6}, {1e-5, 3e-5, 2e-5, 4.5e-5}));
  const ChartFrame f = chart_frame(c);
  const Image im = draw_chart(c);
  // The x tick labels' row: runs of inked columns, gaps under 10 px joined (the
  // fitting keeps labels 10 px apart; the gaps inside a label are 1-2 px). One
  // label ("3e+06") is 5 x 7 px wide; two closer than 10 px make a run of 70.
  const auto y0 = static_cast<std::int32_t>(f.bottom) + 6, y1 = y0 + 15;
  int run = 0, blank = 99, longest = 0, labels = 0;
  for (std::int32_t x = 0; x < im.width; ++x) {
    if (dark_pixels(im, x, y0, x + 1, y1) > 0) {
      labels += blank >= 10 ? 1 : 0;
      run = blank >= 10 ? 1 : run + blank + 1;
      blank = 0;
      longest = std::max(longest, run);
    } else {
      ++blank;
    }
  }
  EXPECT_GE(labels, 2);
  EXPECT_LE(longest, 40);
}

TEST(PlotDraw, UncolouredSeriesTakeThePaletteInTurn) {
  Chart c = unit_chart();
  c.series.push_back(series("", {0, 1}, {0.2, 0.2}));
  c.series.push_back(series("", {0, 1}, {0.5, 0.5}, PlotSeries::Style::Line, kRed));
  c.series.push_back(series("", {0, 1}, {0.8, 0.8}));
  const ChartFrame f = chart_frame(c);
  const Image im = draw_chart(c);
  EXPECT_LE(nearest_distance(im, f, 0.5, 0.2, palette_colour(0)), 8);
  EXPECT_LE(nearest_distance(im, f, 0.5, 0.8, palette_colour(1)), 8);
  EXPECT_NE(palette_colour(0), palette_colour(1));
  EXPECT_EQ(palette_colour(palette_size()), palette_colour(0));
}

TEST(PlotPng, WriteThenReadRoundTrips) {
  const auto dir = std::filesystem::temp_directory_path() / "throng_plot_test";
  std::filesystem::create_directories(dir);
  Chart c;
  c.title = "Weidmann: speed against density";
  c.x_label = "density (1/m²)";
  c.y_label = "speed (m/s)";
  PlotSeries curve = series("Weidmann (1993)", {}, {});
  PlotSeries measured = series("measured", {}, {}, PlotSeries::Style::Points);
  for (int i = 1; i <= 100; ++i) {
    const double rho = 5.4 * i / 100.0;
    curve.x.push_back(rho);
    curve.y.push_back(1.34 * (1 - std::exp(-1.913 * (1 / rho - 1 / 5.4))));
  }
  for (int i = 0; i < 12; ++i) {
    const double rho = 0.3 + 0.4 * i;
    measured.x.push_back(rho);
    measured.y.push_back(1.34 * (1 - std::exp(-1.913 * (1 / rho - 1 / 5.4))) + 0.06 * std::sin(3.7 * i));
  }
  c.series = {curve, measured};
  c.bands.push_back({false, 1.15, 1.45, "free-flow pass window", {}});
  const std::string path = (dir / "weidmann.png").string();
  write_chart_png(path, c);
  const Image back = read_png(path), drawn = draw_chart(c);
  EXPECT_EQ(back.width, 800);
  EXPECT_EQ(back.height, 500);
  EXPECT_EQ(back.rgba, drawn.rgba);
  EXPECT_THROW(write_chart_png((dir / "no-such-folder" / "x.png").string(), c), Error);
}

// The message of the Error `f` throws ("" and a failure when none).
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no Error";
  return "";
}

TEST(PlotValidation, BadInputThrowsNamingTheSeries) {
  Chart c;
  c.series.push_back(series("fine", {0, 1}, {0, 1}));
  c.series.push_back(series("speed", {0, 1, 2}, {0, 1}));
  std::string m = error_of([&] { draw_chart(c); });
  EXPECT_NE(m.find("series[1] 'speed'"), std::string::npos) << m;
  EXPECT_NE(m.find("3"), std::string::npos) << m;
  c.series[1] = series("", {0}, {0});
  c.series[1].width = 0;
  m = error_of([&] { chart_frame(c); });
  EXPECT_NE(m.find("series[1]"), std::string::npos) << m;

  Chart sized;
  sized.width = 100;
  EXPECT_NE(error_of([&] { draw_chart(sized); }).find("100x500"), std::string::npos);
  sized.width = 800, sized.height = 5000;
  EXPECT_THROW(draw_chart(sized), Error);

  Chart ranged;
  ranged.x_min = 2, ranged.x_max = 2;
  m = error_of([&] { draw_chart(ranged); });
  EXPECT_NE(m.find("x_min 2 must be below x_max 2"), std::string::npos) << m;
  ranged.x_max = std::nullopt, ranged.y_min = 3, ranged.y_max = 1;
  EXPECT_NE(error_of([&] { chart_frame(ranged); }).find("y range"), std::string::npos);
  ranged.y_min = std::nullopt, ranged.y_max = std::numeric_limits<double>::infinity();
  EXPECT_THROW(chart_frame(ranged), Error);

  Chart banded;
  banded.bands.push_back({true, 0, std::numeric_limits<double>::quiet_NaN(), "window", {}});
  EXPECT_NE(error_of([&] { draw_chart(banded); }).find("band[0] 'window'"), std::string::npos);
}

}  // namespace
}  // namespace throng::render
