#include "core/memory_budget.h"

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>

#include "core/error.h"

namespace throng {

namespace {
std::atomic<std::uint64_t> g_budget{0};
constexpr double kDefaultFraction = 0.8;
}  // namespace

std::uint64_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page) : 0;
}

std::uint64_t resident_memory_bytes() {
  // statm: total and resident sizes in pages. Read fresh each time (not
  // getrusage's peak), so that memory given back shows as well.
  std::ifstream statm("/proc/self/statm");
  std::uint64_t total = 0, resident = 0;
  const long page = sysconf(_SC_PAGE_SIZE);
  if (!(statm >> total >> resident) || page <= 0) return 0;
  return resident * static_cast<std::uint64_t>(page);
}

std::uint64_t memory_budget() {
  if (const std::uint64_t set = g_budget.load(); set > 0) return set;
  const std::uint64_t physical = physical_memory_bytes();
  return physical > 0 ? static_cast<std::uint64_t>(kDefaultFraction * static_cast<double>(physical)) : UINT64_MAX;
}

void set_memory_budget(std::uint64_t bytes) { g_budget.store(bytes); }

std::uint64_t parse_memory_size(const std::string& text, const std::string& field) {
  const auto bad = [&] {
    return Error(fmt::format("expected a size such as 512M, 8G or 1.5GiB, got '{}'", text), at_field(field));
  };
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [rest, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || !std::isfinite(value)) throw bad();
  std::string unit(rest, end);
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() > 1 && unit.back() == 'B') unit.pop_back();   // "GB", "GIB" -> "G", "GI"
  if (unit.size() == 2 && unit.back() == 'I') unit.pop_back();  // "GI" -> "G"
  double scale = 1;
  if (unit == "K")
    scale = 1024.0;
  else if (unit == "M")
    scale = 1024.0 * 1024.0;
  else if (unit == "G")
    scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T")
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!unit.empty() && unit != "B")
    throw bad();
  const double bytes = value * scale;
  if (!(bytes >= 1.0)) throw Error(fmt::format("the memory budget must be positive, got '{}'", text), at_field(field));
  if (bytes > 1.8e19) throw bad();
  return static_cast<std::uint64_t>(bytes);
}

std::string format_bytes(double bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 5) {
    bytes /= 1024.0;
    ++u;
  }
  return u == 0 ? fmt::format("{:.0f} bytes", bytes) : fmt::format("{:.3g} {}", bytes, units[u]);
}

void check_memory_budget(double bytes, const std::string& what, const std::string& field) {
  const std::uint64_t budget = memory_budget();
  if (bytes <= static_cast<double>(budget)) return;
  const bool set = g_budget.load() > 0;
  throw Error(
      fmt::format(
          "about {} for {} exceeds the memory budget of {} ({}); ask for less, or raise it with --max-memory",
          format_bytes(bytes), what, format_bytes(static_cast<double>(budget)),
          set ? "--max-memory"
              : fmt::format("80 % of this machine's {}", format_bytes(static_cast<double>(physical_memory_bytes())))),
      at_field(field));
}

}  // namespace throng
