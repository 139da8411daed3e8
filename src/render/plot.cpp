#include "render/plot.h"

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "core/error.h"

namespace throng::render {
namespace {

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kText{32, 32, 32};
constexpr Rgb kAxis{64, 64, 64};
constexpr Rgb kGrid{228, 228, 228};
constexpr Rgb kLegendBorder{176, 176, 176};
constexpr float kBandOpacity = 0.2f;
constexpr float kTickLength = 5.0f;
constexpr float kSmallFont = 13.0f, kLargeFont = 26.0f;

// ---- text ---------------------------------------------------------------

// ProggyClean at 13 px (labels) and 26 px (title), built once; no ImGui context.
struct Fonts {
  ImFontAtlas atlas;
  ImFont* small = nullptr;
  ImFont* large = nullptr;
  unsigned char* pixels = nullptr;
  int tex_w = 0, tex_h = 0;

  Fonts() {
    ImFontConfig cfg;
    cfg.SizePixels = kSmallFont;
    small = atlas.AddFontDefault(&cfg);
    ImFontConfig big;
    big.SizePixels = kLargeFont;
    large = atlas.AddFontDefault(&big);
    if (small == nullptr || large == nullptr || !atlas.Build())
      throw Error("cannot build the chart font (Dear ImGui's ProggyClean)");
    atlas.GetTexDataAsAlpha8(&pixels, &tex_w, &tex_h);
  }
};

const Fonts& fonts() {
  static const Fonts f;  // thread-safe initialisation
  return f;
}

// UTF-8 to code points; a malformed byte becomes U+FFFD (drawn as the fallback glyph).
std::vector<ImWchar> decode_utf8(const std::string& s) {
  std::vector<ImWchar> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const int extra = b < 0x80 ? 0 : (b >> 5) == 6 ? 1 : (b >> 4) == 14 ? 2 : (b >> 3) == 30 ? 3 : -1;
    std::uint32_t c = extra == 0 ? b : extra == 1 ? (b & 0x1Fu) : extra == 2 ? (b & 0x0Fu) : (b & 0x07u);
    bool ok = extra >= 0 && i + static_cast<std::size_t>(extra) < s.size();
    for (int k = 1; ok && k <= extra; ++k) {
      const auto n = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      ok = (n & 0xC0u) == 0x80u;
      c = (c << 6) | (n & 0x3Fu);
    }
    out.push_back(ok && c <= 0xFFFF ? static_cast<ImWchar>(c) : static_cast<ImWchar>(0xFFFD));
    i += ok ? static_cast<std::size_t>(extra) + 1 : 1;
  }
  return out;
}

float text_width(const ImFont* font, const std::string& s) {
  float w = 0;
  for (const ImWchar c : decode_utf8(s)) w += font->FindGlyph(c)->AdvanceX;
  return w;
}

void blend(Image& im, std::int32_t x, std::int32_t y, Rgb c, float a) {
  if (x < 0 || y < 0 || x >= im.width || y >= im.height || a <= 0) return;
  a = std::min(a, 1.0f);
  std::uint8_t* p =
      im.rgba.data() +
      (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 4u;
  const std::uint8_t rgb[3] = {c.r, c.g, c.b};
  for (int k = 0; k < 3; ++k) p[k] = static_cast<std::uint8_t>(std::lround(p[k] + (rgb[k] - p[k]) * a));
}

// Draws `s` with the top-left of its box at (x, y) - (ax, ay) x box size. Rotated:
// turned 90 degrees counter-clockwise (reads bottom to top), the box is then
// FontSize wide and the text's width tall.
void put_text(Image& im, const ImFont* font, const std::string& s, float x, float y, float ax, float ay, Rgb colour,
              bool rotated = false) {
  const Fonts& f = fonts();
  const float tw = text_width(font, s), th = font->FontSize;
  const float bw = rotated ? th : tw, bh = rotated ? tw : th;
  const auto ox = static_cast<std::int32_t>(std::lround(x - ax * bw));
  const auto oy = static_cast<std::int32_t>(std::lround(y - ay * bh));
  float pen = 0;
  for (const ImWchar c : decode_utf8(s)) {
    const ImFontGlyph* g = font->FindGlyph(c);
    const auto gx = static_cast<std::int32_t>(std::lround(pen + g->X0)),
               gy = static_cast<std::int32_t>(std::lround(g->Y0));
    const auto gw = static_cast<std::int32_t>(std::lround(g->X1 - g->X0));
    const auto gh = static_cast<std::int32_t>(std::lround(g->Y1 - g->Y0));
    const auto u0 = static_cast<std::int32_t>(std::lround(g->U0 * static_cast<float>(f.tex_w)));
    const auto v0 = static_cast<std::int32_t>(std::lround(g->V0 * static_cast<float>(f.tex_h)));
    const auto uw = static_cast<std::int32_t>(std::lround((g->U1 - g->U0) * static_cast<float>(f.tex_w)));
    const auto vh = static_cast<std::int32_t>(std::lround((g->V1 - g->V0) * static_cast<float>(f.tex_h)));
    for (std::int32_t j = 0; g->Visible && j < gh; ++j)
      for (std::int32_t i = 0; i < gw; ++i) {
        const std::int32_t u = u0 + i * uw / std::max(gw, 1), v = v0 + j * vh / std::max(gh, 1);
        const float a =
            f.pixels[static_cast<std::size_t>(v) * static_cast<std::size_t>(f.tex_w) + static_cast<std::size_t>(u)] /
            255.0f;
        const std::int32_t tx = gx + i, ty = gy + j;  // in the text's own box
        if (rotated)
          blend(im, ox + ty, oy + static_cast<std::int32_t>(std::lround(tw)) - 1 - tx, colour, a);
        else
          blend(im, ox + tx, oy + ty, colour, a);
      }
    pen += g->AdvanceX;
  }
}

// ---- coverage masks: one series' shapes, composited once ----------------

// Coverage in 0..1 over pixel columns [x0, x1) and rows [y0, y1); the largest
// coverage wins, so overlapping pieces of one series never darken each other.
struct Mask {
  std::int32_t x0, y0, x1, y1;
  std::vector<float> a;
  Mask(std::int32_t ax0, std::int32_t ay0, std::int32_t ax1, std::int32_t ay1)
      : x0(ax0),
        y0(ay0),
        x1(std::max(ax0, ax1)),
        y1(std::max(ay0, ay1)),
        a(static_cast<std::size_t>(x1 - x0) * static_cast<std::size_t>(y1 - y0), 0.0f) {}
  void cover(std::int32_t x, std::int32_t y, double c) {
    if (x < x0 || y < y0 || x >= x1 || y >= y1 || c <= 0) return;
    float& m =
        a[static_cast<std::size_t>(y - y0) * static_cast<std::size_t>(x1 - x0) + static_cast<std::size_t>(x - x0)];
    m = std::max(m, static_cast<float>(std::min(c, 1.0)));
  }
  // Clamps [lo, hi) of continuous coordinates to whole pixels inside the mask.
  std::pair<std::int32_t, std::int32_t> span(double lo, double hi, bool columns) const {
    const double a_lo = columns ? x0 : y0, a_hi = columns ? x1 : y1;
    return {static_cast<std::int32_t>(std::floor(std::clamp(lo, a_lo, a_hi))),
            static_cast<std::int32_t>(std::ceil(std::clamp(hi, a_lo, a_hi)))};
  }
};

void composite(Image& im, const Mask& m, Rgb colour, float opacity) {
  for (std::int32_t y = m.y0; y < m.y1; ++y)
    for (std::int32_t x = m.x0; x < m.x1; ++x) {
      const float c = m.a[static_cast<std::size_t>(y - m.y0) * static_cast<std::size_t>(m.x1 - m.x0) +
                          static_cast<std::size_t>(x - m.x0)];
      if (c > 0) blend(im, x, y, colour, c * opacity);
    }
}

struct P {
  double x, y;
};

// Liang-Barsky: clips segment a-b to [lo, hi]; false when nothing is left.
bool clip_segment(P& a, P& b, P lo, P hi) {
  double t0 = 0, t1 = 1;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double p[4] = {-dx, dx, -dy, dy}, q[4] = {a.x - lo.x, hi.x - a.x, a.y - lo.y, hi.y - a.y};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0) {
      if (q[k] < 0) return false;
      continue;
    }
    const double t = q[k] / p[k];
    if (p[k] < 0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
  }
  if (t0 > t1) return false;
  const P a0 = a;
  a = {a0.x + t0 * dx, a0.y + t0 * dy};
  b = {a0.x + t1 * dx, a0.y + t1 * dy};
  return true;
}

// An anti-aliased segment `width` px wide with round ends.
void cover_segment(Mask& m, P a, P b, double width) {
  const double r = width / 2 + 0.5;
  if (!clip_segment(a, b, {m.x0 - r, m.y0 - r}, {m.x1 + r, m.y1 + r})) return;
  const auto [cx0, cx1] = m.span(std::min(a.x, b.x) - r, std::max(a.x, b.x) + r, true);
  const auto [cy0, cy1] = m.span(std::min(a.y, b.y) - r, std::max(a.y, b.y) + r, false);
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  for (std::int32_t y = cy0; y < cy1; ++y)
    for (std::int32_t x = cx0; x < cx1; ++x) {
      const double qx = x + 0.5 - a.x, qy = y + 0.5 - a.y;
      const double t = len2 > 0 ? std::clamp((qx * dx + qy * dy) / len2, 0.0, 1.0) : 0.0;
      const double d = std::hypot(qx - t * dx, qy - t * dy);
      m.cover(x, y, r - d);
    }
}

void cover_disc(Mask& m, P c, double radius) {
  const auto [cx0, cx1] = m.span(c.x - radius - 1, c.x + radius + 1, true);
  const auto [cy0, cy1] = m.span(c.y - radius - 1, c.y + radius + 1, false);
  for (std::int32_t y = cy0; y < cy1; ++y)
    for (std::int32_t x = cx0; x < cx1; ++x) m.cover(x, y, radius + 0.5 - std::hypot(x + 0.5 - c.x, y + 0.5 - c.y));
}

// Pixels whose centres lie in [a, b) (either order), at least one pixel each way.
void cover_rect(Mask& m, P a, P b) {
  double lx = std::min(a.x, b.x), hx = std::max(a.x, b.x), ly = std::min(a.y, b.y), hy = std::max(a.y, b.y);
  const auto widen = [](double& lo, double& hi) {  // to the one pixel holding the middle
    if (hi - lo >= 1) return;
    lo = std::floor((lo + hi) / 2);
    hi = lo + 1;
  };
  widen(lx, hx);
  widen(ly, hy);
  const auto [cx0, cx1] = m.span(lx, hx + 1, true);
  const auto [cy0, cy1] = m.span(ly, hy + 1, false);
  for (std::int32_t y = cy0; y < cy1; ++y)
    for (std::int32_t x = cx0; x < cx1; ++x)
      if (x + 0.5 >= lx && x + 0.5 < hx && y + 0.5 >= ly && y + 0.5 < hy) m.cover(x, y, 1.0);
}

// A polyline, solid or dashed (4 x width on, 3 x width off; the phase runs on
// across its segments). A lone point becomes a dot.
void cover_polyline(Mask& m, const std::vector<P>& pts, double width, bool dashed) {
  if (pts.size() == 1) cover_disc(m, pts[0], width / 2);
  const double on = 4 * width, period = 7 * width;
  double phase = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const P a = pts[i - 1], b = pts[i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    if (!dashed || len > 1e5) {  // a segment that long runs far off the plot: drawn solid
      cover_segment(m, a, b, width);
      continue;
    }
    for (double s = 0; s < len;) {
      const double pos = std::fmod(phase + s, period), left = (pos < on ? on : period) - pos;
      const double e = std::min(len, s + left);
      if (pos < on)
        cover_segment(m, {a.x + (b.x - a.x) * s / len, a.y + (b.y - a.y) * s / len},
                      {a.x + (b.x - a.x) * e / len, a.y + (b.y - a.y) * e / len}, width);
      s = e;
    }
    phase = std::fmod(phase + len, period);
  }
}

// ---- ranges and layout ---------------------------------------------------

std::string describe_series(std::size_t i, const std::string& label) {
  return label.empty() ? fmt::format("chart series[{}]", i) : fmt::format("chart series[{}] '{}'", i, label);
}

bool finite_point(const PlotSeries& s, std::size_t i) { return std::isfinite(s.x[i]) && std::isfinite(s.y[i]); }

// Half the bar width in x units: 0.4 of the smallest spacing of distinct x;
// 0 when fewer than two distinct x (the caller picks a width from the frame).
double bar_half_width(const PlotSeries& s) {
  std::vector<double> xs;
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (finite_point(s, i)) xs.push_back(s.x[i]);
  std::sort(xs.begin(), xs.end());
  double gap = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < xs.size(); ++i)
    if (xs[i] > xs[i - 1]) gap = std::min(gap, xs[i] - xs[i - 1]);
  return std::isfinite(gap) ? 0.4 * gap : 0.0;
}

struct Extent {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
  bool empty() const { return lo > hi; }
};

// The data's extent along x, or along y over the points whose x lies in [x_lo, x_hi].
Extent data_extent(const Chart& c, bool along_y, double x_lo, double x_hi) {
  Extent e;
  for (const PlotSeries& s : c.series) {
    const bool bars = s.style == PlotSeries::Style::Bars;
    const double half = bars && !along_y ? bar_half_width(s) : 0.0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!finite_point(s, i)) continue;
      if (!along_y) e.add(s.x[i] - half), e.add(s.x[i] + half);
      if (along_y && s.x[i] >= x_lo && s.x[i] <= x_hi) e.add(s.y[i]);
      if (along_y && bars && s.x[i] >= x_lo && s.x[i] <= x_hi) e.add(0.0);
    }
  }
  for (const PlotBand& b : c.bands)
    if (b.vertical != along_y) e.add(b.from), e.add(b.to);
  return e;
}

// An axis' range: the given bounds, the rest from the data widened to nice ticks.
std::pair<double, double> axis_range(std::optional<double> given_lo, std::optional<double> given_hi, Extent e,
                                     int target) {
  if (given_lo && given_hi) return {*given_lo, *given_hi};
  if (e.empty())
    e = given_lo ? Extent{*given_lo, *given_lo + 1} : given_hi ? Extent{*given_hi - 1, *given_hi} : Extent{0, 1};
  double lo = given_lo.value_or(e.lo), hi = given_hi.value_or(e.hi);
  if (given_lo && hi <= lo) hi = lo + std::max(1.0, std::abs(lo) * 0.1);
  if (given_hi && lo >= hi) lo = hi - std::max(1.0, std::abs(hi) * 0.1);
  const std::vector<double> ticks = nice_ticks(lo, hi, target);
  return {given_lo ? lo : ticks.front(), given_hi ? hi : ticks.back()};
}

int x_tick_target(const Chart& c) { return std::clamp(c.width / 110, 3, 10); }
int y_tick_target(const Chart& c) { return std::clamp(c.height / 70, 3, 10); }

struct AxisTicks {
  std::vector<double> at;  // inside [lo, hi]
  double step = 1;
};

// The ticks inside [lo, hi] for about `target` of them.
AxisTicks axis_ticks(double lo, double hi, int target) {
  const std::vector<double> all = nice_ticks(lo, hi, target);
  AxisTicks t;
  t.step = all.size() > 1 ? all[1] - all[0] : hi - lo;
  const double eps = (hi - lo) * 1e-9;
  for (const double v : all)
    if (v >= lo - eps && v <= hi + eps) t.at.push_back(v);
  return t;
}

// The most ticks (from `target` down to 2) whose labels keep 10 px apart along
// an axis `length_px` long: labels' widths along x, their height along y.
AxisTicks fitting_ticks(double lo, double hi, int target, float length_px, bool along_x) {
  const ImFont* font = fonts().small;
  for (;; --target) {
    AxisTicks t = axis_ticks(lo, hi, target);
    float extent = font->FontSize;
    for (const double v : t.at)
      if (along_x) extent = std::max(extent, text_width(font, tick_label(v, t.step)));
    if (target <= 2 || t.step / (hi - lo) * length_px >= extent + 10) return t;
  }
}

AxisTicks y_ticks(const Chart& c, const ChartFrame& f) {
  return fitting_ticks(f.y_min, f.y_max, y_tick_target(c), f.bottom - f.top, false);
}
// Fitted to the plot's width less the widest right margin (the frame's right
// edge depends on the last label), so that chart_frame and drawing agree.
AxisTicks x_ticks(const Chart& c, const ChartFrame& f) {
  return fitting_ticks(f.x_min, f.x_max, x_tick_target(c), static_cast<float>(c.width) - f.left - 16, true);
}

// ---- drawing stages --------------------------------------------------------

void fill_rect(Image& im, std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1, Rgb c, float a) {
  for (std::int32_t y = std::max(y0, 0); y < std::min(y1, im.height); ++y)
    for (std::int32_t x = std::max(x0, 0); x < std::min(x1, im.width); ++x) blend(im, x, y, c, a);
}

std::int32_t px(double v) { return static_cast<std::int32_t>(std::lround(v)); }

// Grid lines at the ticks inside the plot, tick marks outside it with their labels.
void draw_grid_and_ticks(Image& im, const Chart& c, const ChartFrame& f) {
  const ImFont* font = fonts().small;
  const AxisTicks xt = x_ticks(c, f), yt = y_ticks(c, f);
  for (const double t : xt.at) {
    const std::int32_t col = px(f.to_pixel(t, f.y_min).x);
    fill_rect(im, col, px(f.top), col + 1, px(f.bottom), kGrid, 1);
    fill_rect(im, col, px(f.bottom) + 1, col + 1, px(f.bottom + kTickLength) + 1, kAxis, 1);
    put_text(im, font, tick_label(t, xt.step), col + 0.5f, f.bottom + kTickLength + 3, 0.5f, 0, kText);
  }
  for (const double t : yt.at) {
    const std::int32_t row = px(f.to_pixel(f.x_min, t).y);
    fill_rect(im, px(f.left), row, px(f.right), row + 1, kGrid, 1);
    fill_rect(im, px(f.left - kTickLength), row, px(f.left), row + 1, kAxis, 1);
    put_text(im, font, tick_label(t, yt.step), f.left - kTickLength - 3, row + 0.5f, 1, 0.5f, kText);
  }
}

Mask plot_mask(const ChartFrame& f) { return Mask(px(f.left), px(f.top), px(f.right) + 1, px(f.bottom) + 1); }

Rgb band_colour(const Chart& c, std::size_t index) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < index; ++i) k += c.bands[i].colour ? 0 : 1;
  return c.bands[index].colour.value_or(palette_colour(palette_size() - 1 - k % palette_size()));
}

Rgb series_colour(const Chart& c, std::size_t index) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < index; ++i) k += c.series[i].colour ? 0 : 1;
  return c.series[index].colour.value_or(palette_colour(k));
}

void draw_bands(Image& im, const Chart& c, const ChartFrame& f) {
  for (std::size_t i = 0; i < c.bands.size(); ++i) {
    const PlotBand& b = c.bands[i];
    Mask m = plot_mask(f);
    const glm::vec2 a = b.vertical ? f.to_pixel(b.from, f.y_min) : f.to_pixel(f.x_min, b.from);
    const glm::vec2 z = b.vertical ? f.to_pixel(b.to, f.y_max) : f.to_pixel(f.x_max, b.to);
    cover_rect(m, {a.x, a.y}, {z.x, z.y});
    composite(im, m, band_colour(c, i), kBandOpacity);
  }
}

// The runs of consecutive finite points, in pixels; a Steps series' runs with
// the steps put in.
std::vector<std::vector<P>> pixel_runs(const PlotSeries& s, const ChartFrame& f) {
  std::vector<std::vector<P>> runs(1);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!finite_point(s, i)) {
      if (!runs.back().empty()) runs.emplace_back();
      continue;
    }
    const glm::vec2 p = f.to_pixel(s.x[i], s.y[i]);
    if (s.style == PlotSeries::Style::Steps && !runs.back().empty()) runs.back().push_back({p.x, runs.back().back().y});
    runs.back().push_back({p.x, p.y});
  }
  return runs;
}

void cover_bars(Mask& m, const PlotSeries& s, const ChartFrame& f) {
  double half = bar_half_width(s);
  if (half == 0) half = 0.05 * (f.x_max - f.x_min);
  const double base = std::clamp(0.0, f.y_min, f.y_max);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!finite_point(s, i)) continue;
    const glm::vec2 a = f.to_pixel(s.x[i] - half, base), b = f.to_pixel(s.x[i] + half, s.y[i]);
    cover_rect(m, {a.x, a.y}, {b.x, b.y});
  }
}

void draw_series(Image& im, const Chart& c, const ChartFrame& f) {
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    const PlotSeries& s = c.series[i];
    Mask m = plot_mask(f);
    if (s.style == PlotSeries::Style::Bars) {
      cover_bars(m, s, f);
    } else if (s.style == PlotSeries::Style::Points) {
      for (std::size_t k = 0; k < s.x.size(); ++k) {
        if (!finite_point(s, k)) continue;
        const glm::vec2 p = f.to_pixel(s.x[k], s.y[k]);
        cover_disc(m, {p.x, p.y}, 1.5 * s.width);
      }
    } else {
      for (const std::vector<P>& run : pixel_runs(s, f)) cover_polyline(m, run, s.width, s.dashed);
    }
    composite(im, m, series_colour(c, i), 1);
  }
}

void draw_frame(Image& im, const ChartFrame& f) {
  const std::int32_t l = px(f.left), t = px(f.top), r = px(f.right), b = px(f.bottom);
  fill_rect(im, l, t, r + 1, t + 1, kAxis, 1);
  fill_rect(im, l, b, r + 1, b + 1, kAxis, 1);
  fill_rect(im, l, t, l + 1, b + 1, kAxis, 1);
  fill_rect(im, r, t, r + 1, b + 1, kAxis, 1);
}

// ---- legend ------------------------------------------------------------------

struct LegendEntry {
  std::string label;
  Rgb colour;
  PlotSeries::Style style;
  bool band = false, dashed = false;
  float width = 2;
};

std::vector<LegendEntry> legend_entries(const Chart& c) {
  std::vector<LegendEntry> out;
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    const PlotSeries& s = c.series[i];
    if (!s.label.empty()) out.push_back({s.label, series_colour(c, i), s.style, false, s.dashed, s.width});
  }
  for (std::size_t i = 0; i < c.bands.size(); ++i)
    if (!c.bands[i].label.empty())
      out.push_back({c.bands[i].label, band_colour(c, i), PlotSeries::Style::Bars, true, false, 2});
  return out;
}

constexpr float kLegendPad = 6, kLegendRow = 16, kLegendSample = 24, kLegendInset = 8;

// How many data points fall in the box [x0, x1) x [y0, y1), with points every
// 8 px (at most 64 a segment) along lines and steps.
std::size_t points_in_box(const Chart& c, const ChartFrame& f, float x0, float y0, float x1, float y1) {
  std::size_t n = 0;
  const auto inside = [&](double x, double y) { return x >= x0 && x < x1 && y >= y0 && y < y1 ? 1u : 0u; };
  for (const PlotSeries& s : c.series) {
    if (s.style == PlotSeries::Style::Line || s.style == PlotSeries::Style::Steps) {
      for (const std::vector<P>& run : pixel_runs(s, f))
        for (std::size_t i = 0; i < run.size(); ++i) {
          n += inside(run[i].x, run[i].y);
          if (i == 0) continue;
          const P a = run[i - 1], b = run[i];
          const double len = std::min(std::hypot(b.x - a.x, b.y - a.y), 1e6);
          const int k = std::clamp(static_cast<int>(len / 8), 1, 64);
          for (int j = 1; j < k; ++j) n += inside(a.x + (b.x - a.x) * j / k, a.y + (b.y - a.y) * j / k);
        }
      continue;
    }
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!finite_point(s, i)) continue;
      const glm::vec2 p = f.to_pixel(s.x[i], s.y[i]);
      n += inside(p.x, p.y);
    }
  }
  return n;
}

void draw_legend_sample(Image& im, const LegendEntry& e, float x, float y_mid) {
  Mask m(px(x), px(y_mid - kLegendRow / 2), px(x + kLegendSample), px(y_mid + kLegendRow / 2));
  const double cx = x + kLegendSample / 2.0;
  if (e.band || e.style == PlotSeries::Style::Bars)
    cover_rect(m, {cx - 6, y_mid - 5}, {cx + 6, y_mid + 5});
  else if (e.style == PlotSeries::Style::Points)
    cover_disc(m, {cx, y_mid}, std::min(1.5 * e.width, kLegendRow / 2.0 - 1));
  else
    cover_polyline(m, {{x + 1.0, y_mid}, {x + kLegendSample - 1.0, y_mid}}, std::min(e.width, 6.0f), e.dashed);
  composite(im, m, e.colour, e.band ? 2 * kBandOpacity : 1);
}

// A boxed legend in the plot corner that hides the fewest data points.
void draw_legend(Image& im, const Chart& c, const ChartFrame& f) {
  const std::vector<LegendEntry> entries = legend_entries(c);
  if (entries.empty()) return;
  const ImFont* font = fonts().small;
  float text_w = 0;
  for (const LegendEntry& e : entries) text_w = std::max(text_w, text_width(font, e.label));
  const float w = 2 * kLegendPad + kLegendSample + 6 + text_w,
              h = 2 * kLegendPad + kLegendRow * static_cast<float>(entries.size());
  const std::array<glm::vec2, 4> corners{{{f.right - kLegendInset - w, f.top + kLegendInset},
                                          {f.left + kLegendInset, f.top + kLegendInset},
                                          {f.right - kLegendInset - w, f.bottom - kLegendInset - h},
                                          {f.left + kLegendInset, f.bottom - kLegendInset - h}}};
  glm::vec2 at = corners[0];
  std::size_t best = std::numeric_limits<std::size_t>::max();
  for (const glm::vec2 q : corners) {
    const std::size_t n = points_in_box(c, f, q.x, q.y, q.x + w, q.y + h);
    if (n < best) best = n, at = q;
  }
  const std::int32_t x0 = px(at.x), y0 = px(at.y), x1 = px(at.x + w), y1 = px(at.y + h);
  fill_rect(im, x0, y0, x1, y1, kWhite, 0.9f);
  fill_rect(im, x0, y0, x1, y0 + 1, kLegendBorder, 1), fill_rect(im, x0, y1 - 1, x1, y1, kLegendBorder, 1);
  fill_rect(im, x0, y0, x0 + 1, y1, kLegendBorder, 1), fill_rect(im, x1 - 1, y0, x1, y1, kLegendBorder, 1);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const float y_mid = static_cast<float>(y0) + kLegendPad + kLegendRow * (static_cast<float>(i) + 0.5f);
    draw_legend_sample(im, entries[i], static_cast<float>(x0) + kLegendPad, y_mid);
    put_text(im, font, entries[i].label, static_cast<float>(x0) + kLegendPad + kLegendSample + 6, y_mid, 0, 0.5f,
             kText);
  }
}

// Title above the plot, x label below the tick labels, y label turned along the left edge.
void draw_labels(Image& im, const Chart& c, const ChartFrame& f) {
  const Fonts& fs = fonts();
  if (!c.title.empty()) put_text(im, fs.large, c.title, static_cast<float>(c.width) / 2, 10, 0.5f, 0, kText);
  if (!c.x_label.empty())
    put_text(im, fs.small, c.x_label, (f.left + f.right) / 2, f.bottom + kTickLength + 3 + kSmallFont + 6, 0.5f, 0,
             kText);
  if (!c.y_label.empty()) put_text(im, fs.small, c.y_label, 10, (f.top + f.bottom) / 2, 0, 0.5f, kText, true);
}

}  // namespace

glm::vec2 ChartFrame::to_pixel(double x, double y) const {
  return {static_cast<float>(left + (x - x_min) / (x_max - x_min) * (right - left)),
          static_cast<float>(bottom - (y - y_min) / (y_max - y_min) * (bottom - top))};
}

void validate_chart(const Chart& c) {
  if (c.width < 200 || c.width > 4096 || c.height < 200 || c.height > 4096)
    throw Error(fmt::format("chart size {}x{} px: width and height must lie in [200, 4096]", c.width, c.height));
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    const PlotSeries& s = c.series[i];
    if (s.x.size() != s.y.size())
      throw Error(fmt::format("{}: x has {} values but y has {}; they must be as long", describe_series(i, s.label),
                              s.x.size(), s.y.size()));
    if (!std::isfinite(s.width) || s.width <= 0)
      throw Error(fmt::format("{}: width {} px must be finite and positive", describe_series(i, s.label), s.width));
  }
  for (std::size_t i = 0; i < c.bands.size(); ++i)
    if (!std::isfinite(c.bands[i].from) || !std::isfinite(c.bands[i].to))
      throw Error(fmt::format("chart band[{}]{}: from {} and to {} must be finite", i,
                              c.bands[i].label.empty() ? "" : " '" + c.bands[i].label + "'", c.bands[i].from,
                              c.bands[i].to));
  const auto check_axis = [](char axis, std::optional<double> lo, std::optional<double> hi) {
    if ((lo && !std::isfinite(*lo)) || (hi && !std::isfinite(*hi)))
      throw Error(fmt::format("chart {0}_min / {0}_max must be finite", axis));
    if (lo && hi && *lo >= *hi)
      throw Error(fmt::format("chart {0} range: {0}_min {1} must be below {0}_max {2}", axis, *lo, *hi));
  };
  check_axis('x', c.x_min, c.x_max);
  check_axis('y', c.y_min, c.y_max);
}

ChartFrame chart_frame(const Chart& c) {
  validate_chart(c);
  ChartFrame f{};
  std::tie(f.x_min, f.x_max) = axis_range(c.x_min, c.x_max, data_extent(c, false, 0, 0), x_tick_target(c));
  std::tie(f.y_min, f.y_max) = axis_range(c.y_min, c.y_max, data_extent(c, true, f.x_min, f.x_max), y_tick_target(c));
  // Top and bottom first (fixed by the fonts), then the y ticks and the left
  // margin that their labels need, then the x ticks and the right margin.
  f.top = c.title.empty() ? 14 : 10 + kLargeFont + 10;
  f.bottom = static_cast<float>(c.height) -
             std::round(kTickLength + 3 + kSmallFont + (c.x_label.empty() ? 0 : 6 + kSmallFont) + 10);
  const ImFont* font = fonts().small;
  float y_labels_w = 0;
  const AxisTicks yt = y_ticks(c, f);
  for (const double t : yt.at) y_labels_w = std::max(y_labels_w, text_width(font, tick_label(t, yt.step)));
  f.left = std::round(10 + (c.y_label.empty() ? 0 : kSmallFont + 8) + y_labels_w + 3 + kTickLength);
  const AxisTicks xt = x_ticks(c, f);
  const float last_x_w = xt.at.empty() ? 0 : text_width(font, tick_label(xt.at.back(), xt.step));
  f.right = std::round(static_cast<float>(c.width) - std::max(16.0f, last_x_w / 2 + 8));
  return f;
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || target < 1)
    throw Error(fmt::format("nice_ticks({}, {}, {}): bounds must be finite and target at least 1", lo, hi, target));
  if (lo > hi) std::swap(lo, hi);
  if (lo == hi) {
    const double d = lo == 0 ? 1.0 : std::abs(lo) * 0.1;
    lo -= d, hi += d;
  }
  const double raw = (hi - lo) / target;
  int k = static_cast<int>(std::floor(std::log10(raw)));
  double m = 10;
  for (const double cand : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (cand * std::pow(10.0, k) >= raw * (1 - 1e-12)) {
      m = cand;
      break;
    }
  if (m == 10) m = 1, ++k;
  // i x m x 10^k, dividing by 10^-k for k < 0 so that 3 x 0.2 is 0.6, not 0.6000000000000001.
  const auto value = [&](double i) { return k >= 0 ? i * m * std::pow(10.0, k) : i * m / std::pow(10.0, -k); };
  const double step = value(1);
  const double first = std::floor(lo / step + 1e-9), last = std::ceil(hi / step - 1e-9);
  std::vector<double> ticks;
  for (double i = first; i <= last; ++i) ticks.push_back(value(i) + 0.0);  // + 0.0: no -0
  return ticks;
}

std::string tick_label(double value, double step) {
  if (std::abs(value) < std::abs(step) * 1e-9) value = 0;
  if (std::abs(step) >= 1e5 || std::abs(step) < 1e-4) return fmt::format("{:g}", value + 0.0);
  int decimals = 0;
  for (double s = std::abs(step); decimals < 12 && std::abs(s - std::round(s)) > 1e-6 * std::max(s, 1.0); s *= 10)
    ++decimals;
  return fmt::format("{:.{}f}", value + 0.0, decimals);
}

Image draw_chart(const Chart& c) {
  const ChartFrame f = chart_frame(c);
  Image im(c.width, c.height);
  std::fill(im.rgba.begin(), im.rgba.end(), std::uint8_t{255});
  draw_grid_and_ticks(im, c, f);
  draw_bands(im, c, f);
  draw_frame(im, f);
  draw_series(im, c, f);
  draw_legend(im, c, f);
  draw_labels(im, c, f);
  return im;
}

void write_chart_png(const std::string& path, const Chart& c) { write_png(path, draw_chart(c)); }

}  // namespace throng::render
