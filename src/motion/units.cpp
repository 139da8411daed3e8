#include "motion/units.h"

#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>
#include <vector>

namespace throng::motion {

double metres_per_unit(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Metre: return 1.0;
    case LengthUnit::Centimetre: return 0.01;
    case LengthUnit::Millimetre: return 0.001;
    case LengthUnit::Inch: return 0.0254;
    case LengthUnit::CmuAsf: return 0.0254 / 0.45;
  }
  return 1.0;
}

const char* to_string(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Metre: return "m";
    case LengthUnit::Centimetre: return "cm";
    case LengthUnit::Millimetre: return "mm";
    case LengthUnit::Inch: return "in";
    case LengthUnit::CmuAsf: return "cmu";
  }
  return "?";
}

std::optional<LengthUnit> parse_length_unit(std::string_view text) {
  std::string l(text);
  for (char& c : l) c = static_cast<char>((c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c);
  if (l == "m" || l == "metre" || l == "metres" || l == "meter" || l == "meters") return LengthUnit::Metre;
  if (l == "cm" || l == "centimetre" || l == "centimetres" || l == "centimeter" || l == "centimeters")
    return LengthUnit::Centimetre;
  if (l == "mm" || l == "millimetre" || l == "millimetres" || l == "millimeter" || l == "millimeters")
    return LengthUnit::Millimetre;
  if (l == "in" || l == "inch" || l == "inches") return LengthUnit::Inch;
  if (l == "cmu" || l == "asf") return LengthUnit::CmuAsf;
  return std::nullopt;
}

namespace {
double leg_length(const Skeleton& s, Role thigh, Role ankle) {
  const std::int32_t t = s.role(thigh), a = s.role(ankle);
  if (t < 0 || a < 0) return 0.0;
  double length = 0.0;
  for (std::int32_t j = a; j != t; j = s.parents[static_cast<std::size_t>(j)]) {
    if (j < 0) return 0.0;
    length += glm::length(glm::dvec3(s.offsets[static_cast<std::size_t>(j)]));
  }
  return length;
}
}  // namespace

UnitGuess guess_length_unit(const Skeleton& s) {
  UnitGuess g;
  double nominal_m;
  const double legs =
      std::max(leg_length(s, Role::LeftThigh, Role::LeftAnkle), leg_length(s, Role::RightThigh, Role::RightAnkle));
  if (legs > 0.0) {
    g.measured = legs;
    g.from_legs = true;
    nominal_m = 0.85;
  } else {
    // Rest pose: joints and end sites in model space, largest box side.
    std::vector<glm::dvec3> at(s.offsets.size());
    glm::dvec3 lo(0.0), hi(0.0);
    for (std::size_t j = 0; j < at.size(); ++j) {
      const std::int32_t p = s.parents[j];
      at[j] = (p >= 0 ? at[static_cast<std::size_t>(p)] : glm::dvec3(0.0)) + glm::dvec3(s.offsets[j]);
      lo = glm::min(lo, at[j]);
      hi = glm::max(hi, at[j]);
      if (j < s.has_end_site.size() && s.has_end_site[j]) {
        const glm::dvec3 e = at[j] + glm::dvec3(s.end_sites[j]);
        lo = glm::min(lo, e);
        hi = glm::max(hi, e);
      }
    }
    const glm::dvec3 size = hi - lo;
    g.measured = std::max(size.x, std::max(size.y, size.z));
    nominal_m = 1.7;
  }
  if (!(g.measured > 0.0) || !std::isfinite(g.measured)) return g;  // nothing to go by: metres
  double best = 1e300;
  for (LengthUnit u :
       {LengthUnit::Metre, LengthUnit::Centimetre, LengthUnit::Millimetre, LengthUnit::Inch, LengthUnit::CmuAsf}) {
    const double miss = std::abs(std::log(g.measured * metres_per_unit(u) / nominal_m));
    if (miss < best) {
      best = miss;
      g.unit = u;
    }
  }
  return g;
}

}  // namespace throng::motion
