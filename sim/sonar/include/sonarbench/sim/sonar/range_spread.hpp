#pragma once

#include <span>
#include <vector>

#include "sonarbench/sim/sonar/receiver.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

// How a beam's echo spreads in range, in place on its noise-free power per bin, before speckle
// (docs/physics.md: the pulse's skirts, reverberation, the second trip).
namespace sonarbench::sim {

/// Shares each bin's power with skirts on both sides (S = 10^(pulse_skirt_db/10), falling by
/// q = exp(-bin / pulse_skirt_length_m) per bin): the bin keeps 1 / (1 + S), the skirts hold
/// S / (1 + S). Power is redistributed, not added. No change at pulse_skirt_length_m 0.
void AddPulseSkirts(const SensorModel& sensor, std::vector<double>& echo_power);

/// Adds a tail behind each echo, from the next bin on, falling by q = exp(-bin /
/// reverberation_length_m) per bin and holding R = 10^(reverberation_db/10) of the echo in all.
/// Echoes feed it, the tail does not. No change at reverberation_length_m 0.
void AddReverberation(const SensorModel& sensor, std::vector<double>& echo_power);

/// Whether the acoustics have a second trip (second_trip_db above -100).
[[nodiscard]] inline bool HasSecondTrip(const Acoustics& a) {
  return a.tail.second_trip_db > -100.0;
}

/// Adds the second trip: the echo the head reflects goes out again, so trips to r and r' are
/// heard at r + r', P2(R) = T g(R) Σ_{r + r' = R} (P(r) / g(r)) (h(r') / g(r')), T the trip's
/// level, g the receiver's time-varied gain, `impulse_power` h the echoes each over one bin;
/// its own reverberation added before it joins the echo. Bins under 1e-6 of the largest skipped.
void AddSecondTrip(const SensorModel& sensor, const Receiver& receiver,
                   std::vector<double>& echo_power, std::span<const double> impulse_power);

}  // namespace sonarbench::sim
