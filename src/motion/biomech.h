// Published relations between speed and the timing of human gait, used to
// give the procedural motion set (motion/default_set.h) realistic cadence,
// stride and contact timing. Sources and ranges: docs/default_motions.md.
//
// Units: speed in m/s, cadence in steps per minute (one step = one foot
// contact; one stride = two steps), lengths in metres, times in seconds.
#pragma once

namespace throng::motion::biomech {

// Walk ratio (step length / cadence), roughly constant for adults over the
// usual walking speeds (Sekiya & Nagasaki 1998; Murakami & Otaka 2017 find it
// holds down to about 62 m/min, 1.0 m/s). 0.0065 m per step/min suits a 1.75 m adult.
inline constexpr double kWalkRatio = 0.0065;
// Preferred walk-to-run transition speed of adults, about 2 m/s (e.g.
// Thorstensson & Roberthson 1987, Hreljac 1993).
inline constexpr double kWalkRunTransitionSpeed = 2.0;
// Running cadence rises only slowly with speed: about 165 steps/min at
// 3.0 m/s, +3 steps/min for +15 % speed (outdoor recreational runners, Eur J
// Sport Sci 2020, 20:182, PMID 31284825), 154-160 steps/min at 2.4-2.9 m/s in novices
// (van Oeveren et al. 2017). Linear fit used here: 145 + 6.5 v.
inline constexpr double kRunCadenceAtZero = 145.0;
inline constexpr double kRunCadencePerSpeed = 6.5;
// Distance the body travels while a foot is on the ground when running;
// changes little with speed (Weyand et al. 2000), so contact time ~ Lc / v.
inline constexpr double kRunContactLength = 0.80;

enum class Gait { Stand, Walk, Run };
const char* to_string(Gait gait);

// Stand below 0.05 m/s, walk below the transition speed, run above it.
Gait gait_for_speed(double speed);

// Walking: v = step * cadence / 60 and step = kWalkRatio * cadence, so
// cadence = sqrt(60 v / kWalkRatio).
double walking_cadence(double speed);
double running_cadence(double speed);
// Cadence of the gait chosen for this speed (0 when standing).
double cadence(Gait gait, double speed);

// Step and stride length implied by a cadence at a speed.
double step_length(double speed, double cadence_steps_per_min);
double stride_length(double speed, double cadence_steps_per_min);

// Fraction of the stride a foot is on the ground. Walking: about 0.61 at
// 1.35 m/s, shrinking slowly with speed (Perry & Burnfield: stance ~60-62 %
// at free speed, more when slower). Running: contact time / stride time.
double walking_duty_factor(double speed);
double running_contact_time(double speed);
double duty_factor(Gait gait, double speed, double stride_time_s);

}  // namespace throng::motion::biomech
