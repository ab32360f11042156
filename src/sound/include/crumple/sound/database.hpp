#pragma once
// The sound database (thesis 4.3.3): for each resonator
// size (l_r, the mean ruling length, and l_c, the total free curved border
// length), crumpling clips in the time domain and friction power spectra,
// several variants per cell, plus the constrained cell (0, 0) that every
// resonator without a free border (l_c = 0) uses.
//
// On disk, a folder with an index file (docs/SOUND.md "The sound
// database"):
//
//   DIR/index.toml
//     [database]
//     format = "crumple-sound-db"
//     version = 1
//     sample_rate = 48000        # Hz, of every clip (48000 or 44100)
//     fft_size = 2048            # M: a friction spectrum has M / 2 + 1 bins
//     [[cell]]
//     l_r_cm = 2.5               # 0 and 0: the constrained cell
//     l_c_cm = 5.0
//     crumpling = ["crumpling/lr2.5_lc5_0.wav", ...]   # mono WAVs at sample_rate
//     friction = ["friction/lr2.5_lc5_0.txt", ...]     # M / 2 + 1 powers, one per line
//
// Paths are relative to DIR. A spectrum file holds non-negative numbers, one
// per line, for bins 0 .. M/2 (bin k at k * sample_rate / M Hz); blank lines
// and lines starting with '#' are skipped. A cell may have clips, spectra or
// both; the database needs the constrained cell and at least one other.
// The same loader reads the generated default database (assets/) and a
// user-recorded one.
#include <filesystem>
#include <vector>

namespace crumple::sound {

struct SoundCell {
  double ruling = 0.0;                      // l_r (m)
  double border = 0.0;                      // l_c (m)
  std::vector<std::vector<float>> clips;    // crumpling variants, mono at the database's rate
  std::vector<std::vector<float>> spectra;  // friction variants, M / 2 + 1 powers each
  bool constrained() const { return ruling == 0.0 && border == 0.0; }
};

class SoundDatabase {
 public:
  // Reads DIR/index.toml and every file it names. Throws InputError naming
  // the file (and the index line) for anything missing or malformed: an
  // unknown format or version, a rate other than 48000 / 44100, an fft_size
  // that is not a power of two >= 64, a negative or repeated cell, a clip
  // that is not mono or not at the database's rate or is empty, a spectrum
  // of the wrong length or with a negative or non-finite value, no
  // constrained cell, or no other cell.
  static SoundDatabase load(const std::filesystem::path& dir);

  int sampleRate() const { return rate_; }
  int fftSize() const { return fft_; }
  const std::vector<SoundCell>& cells() const { return cells_; }

  // Thesis 4.3.3: the cell for a resonator of size (l_r, l_c) (m): the
  // constrained cell when l_c = 0, else the nearest other cell in (l_r, l_c)
  // (Euclidean; ties to the first in index order) among those that have
  // clips (crumpling) or spectra (friction). nullptr when no cell has any.
  const SoundCell* crumplingCell(double ruling, double border) const;
  const SoundCell* frictionCell(double ruling, double border) const;

  // The database at another rate (48000 <-> 44100): clips resampled with a
  // windowed sinc below the lower Nyquist frequency, spectra read at the
  // same frequencies (the same fft_size). Throws std::invalid_argument for
  // an unsupported rate. The same database when the rate is its own.
  SoundDatabase resampledTo(int rate) const;

 private:
  const SoundCell* nearest(double ruling, double border, bool clips) const;
  int rate_ = 0;
  int fft_ = 0;
  std::vector<SoundCell> cells_;
};

}  // namespace crumple::sound
