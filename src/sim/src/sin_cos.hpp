#pragma once
// Internal to src/sim: the sines and cosines of many phases at once, for the
// gusts' Fourier modes (wind.cpp).
#include <cstddef>

namespace crumple::sim {

// Phases (rad) up to this size are reduced exactly by sinCos below (q pi/2's
// two leading parts are exact products for |q| < 2^21); larger ones take
// std::sin and std::cos.
inline constexpr double kMaxReducedPhase = 3.0e6;

// sin and cos of every phase[i] (|phase| <= kMaxReducedPhase) within two
// units in the last place of the C library's (tests/sim/test_sin_cos.cpp),
// with no branch, so that the loop vectorises:
// Cody & Waite 1980's reduction by pi/2 in three parts (32, 32 and 53
// significant bits), then the Taylor series of sin and cos on
// [-pi/4, pi/4] to degree 17 and 16 (the next terms are below 1e-17).
inline void sinCos(const double* phase, double* sine, double* cosine, std::size_t n) {
  constexpr double kTwoOverPi = 0.6366197723675814;
  constexpr double kHalfPi1 = 1.5707963267341256, kHalfPi2 = 6.077100506303966e-11,
                   kHalfPi3 = 2.0222662487959506e-21;
  constexpr double kRound = 6755399441055744.0;  // 1.5 * 2^52: adding it rounds to an integer
  for (std::size_t i = 0; i < n; ++i) {
    const double x = phase[i];
    const double q = (x * kTwoOverPi + kRound) - kRound;  // the nearest quarter turn
    const double r = ((x - q * kHalfPi1) - q * kHalfPi2) - q * kHalfPi3;
    const double z = r * r;
    const double sr =
        r * (1.0 +
             z * (-1.0 / 6.0 +
                  z * (1.0 / 120.0 + z * (-1.0 / 5040.0 +
                                          z * (1.0 / 362880.0 +
                                               z * (-1.0 / 39916800.0 +
                                                    z * (1.0 / 6227020800.0 +
                                                         z * (-1.0 / 1307674368000.0 +
                                                              z * (1.0 / 355687428096000.0)))))))));
    const double cr =
        1.0 +
        z * (-0.5 +
             z * (1.0 / 24.0 +
                  z * (-1.0 / 720.0 +
                       z * (1.0 / 40320.0 +
                            z * (-1.0 / 3628800.0 +
                                 z * (1.0 / 479001600.0 + z * (-1.0 / 87178291200.0 +
                                                               z * (1.0 / 20922789888000.0))))))));
    // The quarter turn q mod 4, exactly: q = 4 a + b, round((q - 1.5) / 4) = a.
    const double b = q - 4.0 * (((q - 1.5) * 0.25 + kRound) - kRound);
    const bool odd = b == 1.0 || b == 3.0;
    const double s = odd ? cr : sr, c = odd ? sr : cr;
    sine[i] = b >= 2.0 ? -s : s;
    cosine[i] = (b == 1.0 || b == 2.0) ? -c : c;
  }
}

}  // namespace crumple::sim
