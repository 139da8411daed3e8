// Ctrl-C during long work. A command's SIGINT/SIGTERM handler sets one flag;
// the frame loop reads it between frames, and set-up work (world index,
// route planning, spawning) polls it between pieces of work so that an
// interrupt ends set-up within a fraction of a second too.
#pragma once

#include <atomic>
#include <exception>
#include <string>

namespace throng {

// Set from a signal handler (lock-free, so async-signal-safe).
std::atomic<bool>& interrupt_flag();

// Thrown by check_interrupt. Not an Error: handlers that locate errors in a
// file must not turn an interrupt into a message about the input.
class Interrupted : public std::exception {
 public:
  explicit Interrupted(std::string during) : during_(std::move(during)), what_("interrupted while " + during_) {}
  const std::string& during() const { return during_; }  // e.g. "placing agents"
  const char* what() const noexcept override { return what_.c_str(); }

 private:
  std::string during_, what_;
};

// Throws Interrupted naming what was being done when the flag is set.
inline void check_interrupt(const char* during) {
  if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted(during);
}

// check_interrupt, and on long set-up a sign of life: at most every 2 s an
// info line on stderr, "set-up: placing agents (40 %)" (fraction in [0, 1],
// or negative when unknown). Call it from the thread that runs set-up.
void setup_checkpoint(const char* during, double fraction = -1.0);

}  // namespace throng
