#pragma once
// The soundtrack's spectrogram (a PNG beside the WAV, as
// the thesis shows its results, Figs. 4.4, 4.20-4.22): time left to right,
// frequency 0 to rate / 2 bottom to top, level in dB as colour.
#include <cstdint>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/sound/wav.hpp"

namespace crumple::sound {

struct SpectrogramParams {
  int fftSize = 1024;  // Hann-windowed frames of this many samples
  int height = 256;    // pixels: fftSize / 2 bins folded onto this many rows
  int pixelsPerSecond = 200;
  int maxWidth = 4000;      // a long shot gets fewer pixels per second
  double floorDb = -100.0;  // dB below full scale drawn black
};

// The channels' mean power per bin, in dB (full scale: a sine of amplitude
// 1 reads about 0 dB), coloured from black through blue, red and yellow to
// white. One column per hop; deterministic. Throws std::invalid_argument
// for an empty audio or a bad parameter.
ImageRGBA8 spectrogram(const Audio& audio, const SpectrogramParams& params = {});

// The same levels as numbers: levels[column][row], row 0 the lowest band.
std::vector<std::vector<float>> spectrogramLevels(const Audio& audio,
                                                  const SpectrogramParams& params = {});

}  // namespace crumple::sound
