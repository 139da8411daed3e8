#include "motion/biomech.h"

#include <algorithm>
#include <cmath>

namespace throng::motion::biomech {

const char* to_string(Gait gait) {
  switch (gait) {
    case Gait::Stand: return "stand";
    case Gait::Walk: return "walk";
    case Gait::Run: return "run";
  }
  return "unknown";
}

Gait gait_for_speed(double speed) {
  if (!(speed >= 0.05)) return Gait::Stand;
  return speed < kWalkRunTransitionSpeed ? Gait::Walk : Gait::Run;
}

double walking_cadence(double speed) { return speed > 0.0 ? std::sqrt(60.0 * speed / kWalkRatio) : 0.0; }

double running_cadence(double speed) { return kRunCadenceAtZero + kRunCadencePerSpeed * std::max(speed, 0.0); }

double cadence(Gait gait, double speed) {
  switch (gait) {
    case Gait::Stand: return 0.0;
    case Gait::Walk: return walking_cadence(speed);
    case Gait::Run: return running_cadence(speed);
  }
  return 0.0;
}

double step_length(double speed, double cadence_steps_per_min) {
  return cadence_steps_per_min > 0.0 ? 60.0 * speed / cadence_steps_per_min : 0.0;
}

double stride_length(double speed, double cadence_steps_per_min) {
  return 2.0 * step_length(speed, cadence_steps_per_min);
}

// Linear through ~0.63 at 1.0 m/s and ~0.59 at 1.8 m/s.
double walking_duty_factor(double speed) { return std::clamp(0.677 - 0.05 * speed, 0.55, 0.70); }

double running_contact_time(double speed) { return speed > 0.0 ? kRunContactLength / speed : 0.0; }

double duty_factor(Gait gait, double speed, double stride_time_s) {
  switch (gait) {
    case Gait::Stand: return 1.0;
    case Gait::Walk: return walking_duty_factor(speed);
    case Gait::Run:
      return stride_time_s > 0.0 ? std::clamp(running_contact_time(speed) / stride_time_s, 0.2, 0.49) : 0.4;
  }
  return 1.0;
}

}  // namespace throng::motion::biomech
