#pragma once
// The sound of a tear (thesis 4.4.1): white noise whose
// every sample is multiplied by r^alpha, r uniform in [0, 1) drawn per
// sample (alpha = 1: white noise; alpha = 100, the thesis' value: a
// crackle of sparse bursts, the breaking fibres), with its amplitude and
// pitch linear in the tip's speed: a faster tear breaks more fibres per
// second (louder) and runs over the paper's density changes faster (the
// crackle plays faster).
#include <cstdint>
#include <span>
#include <vector>

namespace crumple::sound {

struct TearingNoiseParams {
  double alpha = 100.0;  // thesis 4.4.1
  double referenceSpeed =
      0.1;            // m/s: the tip speed at which the crackle plays at `gain`, unshifted
  double gain = 1.0;  // amplitude at the reference speed
};

// One tear's noise. The crackle is a fixed sequence c_j = n_j r_j^alpha
// (n_j uniform in [-1, 1], both from CounterRng(seed, tear)); output sample
// i reads it at a position that advances by v_i / referenceSpeed per
// sample (the pitch; between two crackle samples a blend that keeps the
// noise's power) and scales it by
// gain * v_i / referenceSpeed (the amplitude).
class TearingNoise {
 public:
  // Throws std::invalid_argument for alpha < 1, a non-positive reference
  // speed or a negative gain.
  TearingNoise(std::uint64_t seed, int tear, const TearingNoiseParams& params = {});

  // Adds the noise of output samples start .. start + speeds.size() - 1,
  // the tip moving at speeds[k] (m/s, >= 0), into `out` (grown as needed).
  // Calls must follow each other (start = the previous call's end): the
  // crackle goes on where it stopped. Throws std::invalid_argument for a
  // negative or non-finite speed or a start that does not follow.
  void add(std::int64_t start, std::span<const double> speeds, std::vector<float>& out);

 private:
  double crackle(std::int64_t j) const;  // c_j
  std::uint64_t seed_;
  int tear_;
  TearingNoiseParams params_;
  double position_ = 0.0;   // where the next sample reads the crackle
  std::int64_t next_ = -1;  // the next output sample expected (-1: any)
};

}  // namespace crumple::sound
