// Charts on the CPU: line, point, step and bar series, shaded bands, ticks,
// a legend and labels, rasterised into an `Image` with no GL context (text in
// Dear ImGui's built-in ProggyClean font through a standalone ImFontAtlas).
// For the charts of verification reports (fundamental diagrams, speed against
// time, error against step size) written as PNG next to their numbers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "render/image.h"

namespace throng::render {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

// The fixed, colour-blind-safe palette (Okabe and Ito's, yellow left out:
// too faint on white): blue, vermillion, bluish green, reddish purple,
// orange, sky blue, black. Here rather than in plot.cpp so that code
// describing charts needs no renderer (builds with -DTHRONG_RENDER=OFF).
inline constexpr std::array<Rgb, 7> kPalette{
    {{0, 114, 178}, {213, 94, 0}, {0, 158, 115}, {204, 121, 167}, {230, 159, 0}, {86, 180, 233}, {0, 0, 0}}};
// The i-th colour of the palette; it repeats after palette_size().
inline Rgb palette_colour(std::size_t i) { return kPalette[i % kPalette.size()]; }
inline std::size_t palette_size() { return kPalette.size(); }

struct PlotSeries {
  // Line: a polyline through the points, broken at non-finite ones.
  // Points: a disc of diameter 3 x `width` at each point.
  // Steps: a line that holds each y until the next x (post steps).
  // Bars: a filled bar from y = 0 (or the nearest edge of the y range) to y,
  //   centred on x, 0.8 of the smallest x spacing wide.
  enum class Style : std::uint8_t { Line, Points, Steps, Bars };
  std::string label;         // legend entry ("" = none)
  std::vector<double> x, y;  // same length; non-finite points are skipped (a Line breaks there)
  Style style = Style::Line;
  std::optional<Rgb> colour;  // nullopt = the next colour of the palette (counting only series without a colour)
  float width = 2.0f;         // line width / point diameter factor, px
  bool dashed = false;        // Line and Steps: dashes 4 x width long, 3 x width apart
};

// A shaded band: y in [from, to] across the plot (horizontal) or x in [from, to]
// (vertical); e.g. a pass window. Drawn at 20% opacity over the grid, under the
// series. nullopt colour = the palette backwards, counted over bands alone (the
// first band black, i.e. grey at 20%; the next sky blue, ...), so that default
// bands and default series differ.
struct PlotBand {
  bool vertical = false;
  double from = 0, to = 0;  // either order; finite
  std::string label;        // legend entry ("" = none)
  std::optional<Rgb> colour;
};

struct Chart {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  std::vector<PlotBand> bands;
  // nullopt = from the data (and bands), widened to nice ticks; a chart with no
  // finite data gets [0, 1]. An automatic y range looks only at the points whose
  // x lies in the x range; Bars add y = 0 and half a bar each side in x.
  std::optional<double> x_min, x_max, y_min, y_max;
  std::int32_t width = 800, height = 500;  // px, each in [200, 4096]
};

// Where the data land: the plot rectangle in pixels and the axis ranges.
// Pixel (i, j) covers [i, i + 1) x [j, j + 1); the rectangle's edges are whole
// pixels, so the pixel holding a data point is (floor(p.x), floor(p.y)). The
// axes' frame is drawn on columns `left` and `right` and rows `top` and `bottom`
// (x_min lands on column left, x_max on column right); series and bands are
// clipped to those columns and rows.
struct ChartFrame {
  float left, top, right, bottom;  // px, image rows top to bottom
  double x_min, x_max, y_min, y_max;
  glm::vec2 to_pixel(double x, double y) const;
};

// Throws Error (naming the series or band by index and label) for: a size
// outside [200, 4096], x and y of different lengths, a non-finite or
// non-positive width, a non-finite explicit bound or band edge, x_min >= x_max
// or y_min >= y_max when both are given.
void validate_chart(const Chart& c);
ChartFrame chart_frame(const Chart& c);

// "Nice" tick values (steps 1, 2, 2.5 or 5 x 10^k) covering [lo, hi], about
// `target` of them: the smallest such step of at least (hi - lo) / target; the
// first tick <= lo, the last >= hi. lo == hi is widened to lo -+ 10% (-+ 1 at
// 0); lo > hi is swapped. Non-finite bounds or target < 1 throw Error.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

// The label of a tick value for ticks `step` apart: as many decimals as the
// step has ("0.50" for 0.25 apart, "-20"); "%g" when the step is at least 1e5
// or below 1e-4 ("1e+06", "2e-05", "0").
std::string tick_label(double value, double step);

// White background, grid, bands, axes, ticks with labels, series, legend (when
// any series or band has a label: boxed, in the plot corner that hides the
// fewest data points), title and axis labels (y turned to read bottom to top).
// As many ticks as fit their labels 10 px apart. Series and bands are
// clipped to the plot rectangle. Every pixel is opaque.
Image draw_chart(const Chart& c);
// draw_chart + write_png; throws Error naming the path when it cannot write.
void write_chart_png(const std::string& path, const Chart& c);

}  // namespace throng::render
