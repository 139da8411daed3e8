#include "core/interrupt.h"

#include <spdlog/spdlog.h>

#include <chrono>

namespace throng {

std::atomic<bool>& interrupt_flag() {
  static std::atomic<bool> flag{false};
  static_assert(std::atomic<bool>::is_always_lock_free);
  return flag;
}

void setup_checkpoint(const char* during, double fraction) {
  check_interrupt(during);
  using Clock = std::chrono::steady_clock;
  static Clock::time_point last = Clock::now();
  static const char* last_during = nullptr;
  const Clock::time_point now = Clock::now();
  if (during != last_during) {  // a new piece of work: its first report after 2 s
    last_during = during;
    last = now;
    return;
  }
  if (now - last < std::chrono::seconds(2)) return;
  last = now;
  if (fraction >= 0.0)
    spdlog::info("set-up: {} ({:.0f} %)", during, 100.0 * fraction);
  else
    spdlog::info("set-up: {}", during);
}

}  // namespace throng
