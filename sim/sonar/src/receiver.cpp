#include "sonarbench/sim/sonar/receiver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace sonarbench::sim {
namespace {

// The receiver's ceiling (Acoustics::ad_knee, ad_ceiling) on a level x in AD steps, as the AD
// window maps it: x to the knee, then knee + w·tanh((x - knee) / w), w = ceiling - knee (a hard
// clip at the ceiling for w = 0).
double ReceiverCeiling(const Acoustics& a, double x) {
  const double width = a.converter.ceiling - a.converter.knee;
  if (x <= a.converter.knee) return x;
  if (width <= 0.0) return a.converter.ceiling;
  return a.converter.knee + width * std::tanh((x - a.converter.knee) / width);
}

// Its inverse: the least x whose output reaches y; infinite where the ceiling keeps it from y.
double UnderCeiling(const Acoustics& a, double y) {
  const double width = a.converter.ceiling - a.converter.knee;
  if (y <= a.converter.knee) return y;
  if (y >= a.converter.ceiling) return std::numeric_limits<double>::infinity();
  return a.converter.knee + width * std::atanh((y - a.converter.knee) / width);
}

// QuantisePower's tables, held in locals by a loop over bins: an 8-bit store may alias anything,
// so a loop reading them through `this` reloads them after every level it writes.
struct AdSteps {
  const double* thresholds;
  const std::uint8_t* bucket_steps;
  const std::uint8_t* reported;
  std::uint64_t first_bucket;
  int bucket_shift;
  std::uint8_t top;  // the highest reading the ceiling lets a level reach

  // The value reported for the largest reading q with thresholds[q] <= power (the thresholds
  // increase; q = 0 below them): the table gives q at the start of the power's bucket, and the
  // power may pass the next threshold within the bucket (a compare added, not branched on: it is
  // a coin toss). Buckets of half a reading's step hold at most one threshold; the loop keeps it
  // exact for wider ones.
  std::uint8_t operator()(double power) const {
    if (!(power >= thresholds[1])) return reported[0];
    if (power >= thresholds[top]) return reported[top];
    const std::uint64_t bucket =
        (std::bit_cast<std::uint64_t>(power) >> bucket_shift) - first_bucket;
    unsigned q = bucket_steps[bucket];
    q += power >= thresholds[q + 1] ? 1 : 0;
    while (power >= thresholds[q + 1]) ++q;
    return reported[q];
  }
};

}  // namespace

Receiver::Receiver(const SensorModel& sensor)
    : acoustics_(sensor.acoustics), bin_size_m_(sensor.geometry.bin_size_m) {
  TabulateGain(sensor.geometry);
  TabulateConverter();
  TabulateRangeLoss(sensor.geometry.MaxRangeM());
  TabulateJitter();
}

void Receiver::TabulateGain(const mapping::SensorGeometry& g) {
  const Acoustics& a = acoustics_;
  const double noise = std::pow(10.0, a.noise.level_db / 10.0);
  const double before_tvg =
      a.noise.before_tvg_db > -100.0 ? std::pow(10.0, a.noise.before_tvg_db / 10.0) : 0.0;
  for (int i = 0; i < g.num_bins; ++i) {
    const double r = (i + 0.5) * g.bin_size_m;
    tvg_at_bin_.push_back(std::pow(r, a.gain.tvg_db_per_decade / 10.0));
    untvg_at_bin_.push_back(1.0 / tvg_at_bin_.back());
    noise_at_bin_.push_back(noise + before_tvg * tvg_at_bin_.back());
  }
}

void Receiver::TabulateConverter() {
  const Acoustics& a = acoustics_;
  // Quantise rounds half up: the converter's reading q begins where the output reaches q - 0.5
  // of its steps (255 / ad_levels intensity units each), at the level the ceiling's inverse
  // gives; the readings past the ceiling, or past ad_levels, are never reached.
  const double reading_steps = 255.0 / a.converter.levels;  // 1 exactly for 255 levels
  ad_thresholds_.fill(std::numeric_limits<double>::infinity());
  ad_thresholds_[0] = 0.0;
  ad_top_reading_ = 0;
  for (int q = 1; q <= a.converter.levels; ++q) {
    const double steps = UnderCeiling(a, (q - 0.5) * reading_steps);
    const double level_db = a.converter.low_db + steps / 255.0 * a.converter.span_db;
    ad_thresholds_[static_cast<std::size_t>(q)] =
        std::isinf(steps) ? steps : std::pow(10.0, level_db / 10.0);
    if (!std::isinf(steps)) ad_top_reading_ = static_cast<std::uint8_t>(q);
  }
  for (int q = 0; q < 256; ++q) {
    ad_reported_[static_cast<std::size_t>(q)] =
        static_cast<std::uint8_t>(std::min(q, a.converter.levels) * 255 / a.converter.levels);
  }
  // Buckets of positive doubles by their exponent and top mantissa bits: with 2^m per octave,
  // a bucket spans 3.01/2^m dB; m is chosen so that spans half a reading's step, or less.
  const double step_db = a.converter.span_db / a.converter.levels;
  int mantissa_bits = 0;
  while (mantissa_bits < 20 &&
         10.0 * std::log10(2.0) / std::ldexp(1.0, mantissa_bits) > 0.5 * step_db) {
    ++mantissa_bits;
  }
  ad_bucket_shift_ = 52 - mantissa_bits;
  ad_first_bucket_ = std::bit_cast<std::uint64_t>(ad_thresholds_[1]) >> ad_bucket_shift_;
  const std::uint64_t last_bucket =
      std::bit_cast<std::uint64_t>(ad_thresholds_[ad_top_reading_]) >> ad_bucket_shift_;
  ad_bucket_steps_.resize(last_bucket - ad_first_bucket_ + 1);
  unsigned q = 0;
  for (std::uint64_t b = ad_first_bucket_; b <= last_bucket; ++b) {
    const double start = std::bit_cast<double>(b << ad_bucket_shift_);
    while (q < ad_top_reading_ && start >= ad_thresholds_[q + 1]) ++q;
    ad_bucket_steps_[b - ad_first_bucket_] = static_cast<std::uint8_t>(q);
  }
}

void Receiver::TabulateRangeLoss(double max_range_m) {
  const double range_step_m = bin_size_m_ / 16.0;
  range_steps_per_m_ = 16.0 / bin_size_m_;
  const auto steps = static_cast<std::size_t>(std::ceil(max_range_m / range_step_m));
  range_loss_.resize(steps + 2);
  for (std::size_t k = 0; k < range_loss_.size(); ++k) {
    range_loss_[k] = RangeLoss(static_cast<double>(k) * range_step_m);
  }
}

void Receiver::TabulateJitter() {
  const Acoustics& a = acoustics_;
  if (a.noise.level_jitter_db <= 0.0) return;
  // a² + b² = 1 and a b = ρ: a² and b² are the roots of x² - x + ρ².
  const double rho = a.noise.level_jitter_bin_correlation;
  const double root = std::sqrt(1.0 - 4.0 * rho * rho);
  const double own = rho > 0.0 ? std::sqrt(0.5 * (1.0 + root)) : 1.0;
  const double shared = std::sqrt(0.5 * (1.0 - root));
  level_jitter_factors_.reserve(kLevelJitters);
  for (int i = 0; i < kLevelJitters; ++i) {
    const double z = NormalQuantile((i + 0.5) / kLevelJitters);
    level_jitter_factors_.push_back(std::pow(10.0, a.noise.level_jitter_db * own * z / 10.0));
    if (rho > 0.0) {
      level_jitter_next_factors_.push_back(
          std::pow(10.0, a.noise.level_jitter_db * shared * z / 10.0));
    }
  }
}

double Receiver::RangeLoss(double range_m) const {
  const Acoustics& a = acoustics_;
  const double spreading_exponent =
      (a.gain.spreading_db_per_decade - a.gain.tvg_db_per_decade) / 10.0;
  const double absorption_per_m = a.gain.absorption_db_per_m * std::log(10.0) / 10.0;
  const double exponent =
      (spreading_exponent != 0.0 ? spreading_exponent * std::log(range_m) : 0.0) +
      absorption_per_m * range_m;
  return std::exp(-exponent);
}

std::uint8_t Receiver::QuantisePower(double power) const {
  return AdSteps{.thresholds = ad_thresholds_.data(),
                 .bucket_steps = ad_bucket_steps_.data(),
                 .reported = ad_reported_.data(),
                 .first_bucket = ad_first_bucket_,
                 .bucket_shift = ad_bucket_shift_,
                 .top = ad_top_reading_}(power);
}

std::uint8_t Receiver::Quantise(double level_db) const {
  const Acoustics& a = acoustics_;
  const double output =
      ReceiverCeiling(a, (level_db - a.converter.low_db) / a.converter.span_db * 255.0);
  const double reading = std::round(output / (255.0 / a.converter.levels));  // / 1 for 255 levels
  return ad_reported_[static_cast<std::size_t>(std::clamp(reading, 0.0, 255.0))];
}

void Receiver::Jitter(std::span<double> powers, Rng& rng) const {
  const std::vector<double>& jitter = level_jitter_factors_;
  if (jitter.empty()) return;
  static_assert(kLevelJitters == 1 << 12, "12 bits per pick");
  std::uint64_t bits = 0;
  int picks_left = 0;
  const auto pick = [&] {
    if (picks_left == 0) {
      bits = rng.Next();
      picks_left = 5;
    }
    const std::uint64_t i = bits & (kLevelJitters - 1);
    bits >>= 12;
    --picks_left;
    return i;
  };
  if (const std::vector<double>& next = level_jitter_next_factors_; next.empty()) {
    for (double& power : powers) power *= jitter[pick()];
  } else {
    std::uint64_t own = pick();
    for (double& power : powers) {
      const std::uint64_t shared = pick();
      power *= jitter[own] * next[shared];
      own = shared;
    }
  }
}

void Receiver::Convert(std::span<const double> powers, std::uint8_t* levels) const {
  const AdSteps quantise{.thresholds = ad_thresholds_.data(),
                         .bucket_steps = ad_bucket_steps_.data(),
                         .reported = ad_reported_.data(),
                         .first_bucket = ad_first_bucket_,
                         .bucket_shift = ad_bucket_shift_,
                         .top = ad_top_reading_};
  for (std::size_t k = 0; k < powers.size(); ++k) levels[k] = quantise(powers[k]);
}

}  // namespace sonarbench::sim
