#include "crumple/sound/database_generator.hpp"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include "crumple/core/rng.hpp"
#include "crumple/sound/wav.hpp"

namespace crumple::sound {

namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
constexpr double kPcmScale = 32768.0;  // a 16-bit step is 1 / 32768 (libsndfile's reading)

// ---- Portable math: only IEEE +, -, *, / and exact rounding, so a sample is
// the same on every machine and with every libm (the shipped files are
// compared byte for byte with what the generator makes).

// e^x, |x| < 700: x = k ln 2 + r, |r| <= ln 2 / 2, and a Taylor polynomial.
double expP(double x) {
  constexpr double kLn2Hi = 6.93147180369123816490e-01;  // ln 2 in two parts
  constexpr double kLn2Lo = 1.90821492927058770002e-10;
  constexpr double kInvLn2 = 1.44269504088896338700e+00;
  const double k = std::nearbyint(x * kInvLn2);
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  double p = 1.0;
  for (int i = 16; i >= 1; --i) p = 1.0 + r * p / i;
  return std::ldexp(p, static_cast<int>(k));
}

// sin x and cos x, |x| <= 1000: x = k pi/2 + r, |r| <= pi/4, and Taylor polynomials.
void sinCosP(double x, double& s, double& c) {
  constexpr double kPio2Hi = 1.57079632673412561417e+00;  // pi / 2 in two parts
  constexpr double kPio2Lo = 6.07710050650619224932e-11;
  constexpr double k2OverPi = 6.36619772367581382433e-01;
  const double k = std::nearbyint(x * k2OverPi);
  const double r = (x - k * kPio2Hi) - k * kPio2Lo;
  const double r2 = r * r;
  double ts = 1.0;
  double tc = 1.0;
  for (int j = 11; j >= 1; --j) {
    ts = 1.0 - r2 * ts / ((2.0 * j) * (2.0 * j + 1.0));
    tc = 1.0 - r2 * tc / ((2.0 * j - 1.0) * (2.0 * j));
  }
  // sin over the four quadrants; cos x = sin(x + pi/2), the next one.
  const double sines[4] = {r * ts, tc, -r * ts, -tc};
  const int quadrant = ((static_cast<int>(k) % 4) + 4) % 4;
  s = sines[quadrant];
  c = sines[(quadrant + 1) % 4];
}

double sinP(double x) {
  double s = 0.0;
  double c = 0.0;
  sinCosP(x, s, c);
  return s;
}

double cosP(double x) {
  double s = 0.0;
  double c = 0.0;
  sinCosP(x, s, c);
  return c;
}

// ---- The model

void validate(const DatabaseModel& m) {
  const auto positive = [](double v, const char* what) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("DatabaseModel: ") + what +
                                  " must be finite and > 0");
  };
  if (!supportedSampleRate(m.sampleRate))
    throw std::invalid_argument("DatabaseModel: the sample rate must be 48000 or 44100");
  if (m.fftSize < 64 || m.fftSize > (1 << 20) || (m.fftSize & (m.fftSize - 1)) != 0)
    throw std::invalid_argument("DatabaseModel: fft_size must be a power of two >= 64");
  if (m.gridCm.empty()) throw std::invalid_argument("DatabaseModel: an empty grid");
  for (std::size_t i = 0; i < m.gridCm.size(); ++i) {
    positive(m.gridCm[i], "a grid value");
    if (m.gridCm[i] > 500.0) throw std::invalid_argument("DatabaseModel: a grid value > 500 cm");
    if (i > 0 && !(m.gridCm[i] > m.gridCm[i - 1]))
      throw std::invalid_argument("DatabaseModel: the grid must increase");
  }
  for (const int n : {m.clipsPerCell, m.spectraPerCell, m.constrainedClips, m.constrainedSpectra})
    if (n < 1 || n > 256)
      throw std::invalid_argument("DatabaseModel: variants per cell must be in 1 .. 256");
  for (const int n : {m.flapModes, m.frictionModes})
    if (n < 1 || n > 64) throw std::invalid_argument("DatabaseModel: mode orders in 1 .. 64");
  positive(m.thickness, "the thickness");
  positive(m.youngModulus, "Young's modulus");
  positive(m.surfaceDensity, "the surface density");
  if (!(m.poissonRatio >= 0.0 && m.poissonRatio < 0.5))
    throw std::invalid_argument("DatabaseModel: Poisson's ratio must be in [0, 0.5)");
  for (const double v : {m.flapArc,        m.lossFactor,    m.airDamping,      m.snapTime,
                         m.flapTransient,  m.flapCrackTime, m.flapLength,      m.facetMin,
                         m.facetMax,       m.facetRadius,   m.ridgeDamping,    m.facetLossFactor,
                         m.clacTransient,  m.clacCrackTime, m.clacLength,      m.clipRms,
                         m.loudnessWindow, m.trimLevelDb,   m.frictionArc,     m.frictionLossFactor,
                         m.analysisBins,   m.contactCorner, m.constrainedPower})
    positive(v, "a model constant");
  if (m.trimLevelDb > 120.0) throw std::invalid_argument("DatabaseModel: trimLevelDb > 120");
  if (m.facetMax < m.facetMin) throw std::invalid_argument("DatabaseModel: facetMax < facetMin");
  if (!(m.resonantGain >= 0.0) || !std::isfinite(m.resonantGain) || !(m.binJitter >= 0.0) ||
      !(m.binJitter < 1.0) || !(m.frictionJitter >= 0.0) || !(m.frictionJitter < 0.05))
    throw std::invalid_argument(
        "DatabaseModel: resonantGain >= 0, binJitter in [0, 1), frictionJitter in [0, 0.05)");
}

void validateCell(double ruling, double border, int variant) {
  if (!(ruling >= 0.0) || !(border >= 0.0) || !std::isfinite(ruling) || !std::isfinite(border) ||
      ruling > 10.0 || border > 10.0)
    throw std::invalid_argument("sound database: a cell's l_r and l_c must be in [0, 10] m");
  if (border > 0.0 && ruling == 0.0)
    throw std::invalid_argument("sound database: an unconstrained cell needs l_r > 0");
  if (variant < 0 || variant > 255)
    throw std::invalid_argument("sound database: a variant must be in 0 .. 255");
}

// The random stream of one variant of one cell: kind 0 for its clip, 1 for
// its spectrum; the cell keyed by its size in tenths of a millimetre.
CounterRng variantRng(const DatabaseModel& m, std::int64_t kind, double ruling, double border,
                      int variant) {
  const auto key = [](double length) {
    return static_cast<std::int64_t>(std::llround(length * 1e4));
  };
  const std::int64_t cell = (kind << 20 | key(ruling)) << 20 | key(border);
  return CounterRng(m.seed, cell << 8 | variant, RngPurpose::SoundVariant);
}

// Thesis 4.3.3: a mode of the curved strip (Hz), wavenumbers kx along its
// rulings and ky around its curve of radius `radius`: the plate's bending
// D k^4, plus the stiffness the curvature adds, taken at the shallow
// shell's cut-on 2 sqrt(D E h) kx^2 / R (Donnell-Mushtari's curvature term
// E h (kx/k)^4 / R^2 where it balances bending). Every mode falls as the
// strip grows along its rulings (kx) or around its curve (ky, R).
double stripFrequency(const DatabaseModel& m, double kx, double ky, double radius) {
  const double h = m.thickness;
  const double bending =
      m.youngModulus * h * h * h / (12.0 * (1.0 - m.poissonRatio * m.poissonRatio));
  const double k2 = kx * kx + ky * ky;
  const double curve = 2.0 * std::sqrt(bending * m.youngModulus * h) * kx * kx / radius;
  return std::sqrt((bending * k2 * k2 + curve) / m.surfaceDensity) / (2.0 * kPi);
}

// A flap mode's decay rate (1/s) at f: the air's damping of a light sheet,
// growing as f^(1/4) (between the drag's flat rate and the viscous boundary
// layer's sqrt(f)), and the paper's own loss pi eta f.
double flapDecay(const DatabaseModel& m, double f) {
  return m.airDamping * std::sqrt(std::sqrt(f / 1000.0)) + kPi * m.lossFactor * f;
}

struct Mode {
  double frequency = 0.0;  // Hz
  double decay = 0.0;      // 1/s: the amplitude's e^{-decay t}
  double amplitude = 0.0;
  double phase = 0.0;  // rad
};

// Adds each mode's a e^{-decay t} sin(2 pi f t + phase), sample by sample as
// a complex rotation, until it has fallen 100 dB below the strongest mode.
void addModes(const std::vector<Mode>& modes, int rate, std::vector<double>& out) {
  double strongest = 0.0;
  for (const Mode& mode : modes) strongest = std::max(strongest, std::abs(mode.amplitude));
  const double floor2 = 1e-10 * strongest * strongest;
  for (const Mode& mode : modes) {
    double zs = 0.0;
    double zc = 0.0;
    sinCosP(2.0 * kPi * mode.frequency / rate, zs, zc);
    const double g = expP(-mode.decay / rate);
    const double zr = g * zc;
    const double zi = g * zs;
    double ps = 0.0;
    double pc = 0.0;
    sinCosP(mode.phase, ps, pc);
    double re = mode.amplitude * pc;
    double im = mode.amplitude * ps;
    for (std::size_t i = 0; i < out.size(); ++i) {
      out[i] += im;
      const double next = re * zr - im * zi;
      im = re * zi + im * zr;
      re = next;
      if ((i & 255) == 255 && re * re + im * im < floor2) break;
    }
  }
}

// Thesis 4.3.1: the snap's crack at the onset: white noise decaying as
// e^{-t / tau}, scaled to `peak`.
void addCrack(const CounterRng& rng, std::uint64_t first, double tau, double peak, int rate,
              std::vector<double>& out) {
  std::vector<double> crack;
  const double g = expP(-1.0 / (tau * rate));
  double envelope = 1.0;
  double largest = 0.0;
  for (std::size_t i = 0; i < out.size() && envelope > 1e-5; ++i) {
    crack.push_back(envelope * (2.0 * rng.uniform(first + i) - 1.0));
    largest = std::max(largest, std::abs(crack.back()));
    envelope *= g;
  }
  if (largest == 0.0) return;
  for (std::size_t i = 0; i < crack.size(); ++i) out[i] += peak / largest * crack[i];
}

double peakOf(const std::vector<double>& x) {
  double p = 0.0;
  for (const double v : x) p = std::max(p, std::abs(v));
  return p;
}

// Thesis 4.3.1, Fig. 4.7 (right): the flap of the strip l_r x l_c/2, its
// l_c/2 edge bent over flapArc, held at its straight edges, free along its
// curved ones: its modes, struck by the snap-through at a random point.
std::vector<Mode> flapModes(const DatabaseModel& m, double ruling, double border,
                            const CounterRng& rng) {
  const double a = ruling;        // along the rulings, between the free borders
  const double b = 0.5 * border;  // around the curve
  const double radius = b / m.flapArc;
  const double x0 = 0.2 + 0.6 * rng.uniform(0);
  const double y0 = 0.2 + 0.6 * rng.uniform(1);
  std::vector<Mode> modes;
  for (int i = 1; i <= m.flapModes; ++i)
    for (int j = 1; j <= m.flapModes; ++j) {
      const std::uint64_t draw = 16 + 4 * static_cast<std::uint64_t>((i - 1) * m.flapModes + j - 1);
      const double kx = (i - 0.5) * kPi / a;  // free borders: antinodes
      const double ky = j * kPi / b;
      const double f = stripFrequency(m, kx, ky, radius) * (1.0 + 0.02 * (rng.uniform(draw) - 0.5));
      if (f < 20.0 || f > 0.45 * m.sampleRate) continue;
      const double shape = cosP((i - 0.5) * kPi * x0) * sinP(j * kPi * y0);
      Mode mode;
      mode.frequency = f;
      mode.decay = flapDecay(m, f);
      const double w = 2.0 * kPi * f * m.snapTime;
      mode.amplitude = shape / ((i - 0.5) * j) * w / std::sqrt(1.0 + w * w) *
                       (0.75 + 0.5 * rng.uniform(draw + 1));
      mode.phase = 2.0 * kPi * rng.uniform(draw + 2);
      modes.push_back(mode);
    }
  return modes;
}

// Thesis 4.3.1, Fig. 4.7 (left): the clac of a constrained resonator: a
// small, slightly curved facet held on all sides by ridges, which drain its
// vibration within milliseconds.
std::vector<Mode> clacModes(const DatabaseModel& m, const CounterRng& rng) {
  const double a = m.facetMin + (m.facetMax - m.facetMin) * rng.uniform(0);
  const double b = m.facetMin + (m.facetMax - m.facetMin) * rng.uniform(1);
  const double x0 = 0.1 + 0.8 * rng.uniform(2);
  const double y0 = 0.1 + 0.8 * rng.uniform(3);
  constexpr int kOrders = 12;
  std::vector<Mode> modes;
  for (int i = 1; i <= kOrders; ++i)
    for (int j = 1; j <= kOrders; ++j) {
      const std::uint64_t draw = 16 + 4 * static_cast<std::uint64_t>((i - 1) * kOrders + j - 1);
      const double f = stripFrequency(m, i * kPi / a, j * kPi / b, m.facetRadius) *
                       (1.0 + 0.04 * (rng.uniform(draw) - 0.5));
      if (f < 20.0 || f > 0.45 * m.sampleRate) continue;
      Mode mode;
      mode.frequency = f;
      mode.decay = m.ridgeDamping + kPi * m.facetLossFactor * f;
      mode.amplitude =
          sinP(i * kPi * x0) * sinP(j * kPi * y0) / (i * j) * (0.5 + rng.uniform(draw + 1));
      mode.phase = 2.0 * kPi * rng.uniform(draw + 2);
      modes.push_back(mode);
    }
  return modes;
}

// The energy of x over a centred window of `width` samples, at each sample.
std::vector<double> windowEnergy(const std::vector<double>& x, std::size_t width) {
  std::vector<double> prefix(x.size() + 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) prefix[i + 1] = prefix[i] + x[i] * x[i];
  std::vector<double> e(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::size_t lo = i >= width / 2 ? i - width / 2 : 0;
    const std::size_t hi = std::min(x.size(), i + width / 2 + 1);
    e[i] = prefix[hi] - prefix[lo];
  }
  return e;
}

// Thesis 4.3.3: a crumpling clip as the database stores it. The modes and
// the crack, a 0.1 ms attack; cut where the 5 ms energy has fallen
// trimLevelDb below its peak, with a 10 ms fade; scaled to clipRms over the
// first loudnessWindow; on 16-bit steps.
std::vector<float> finishClip(const DatabaseModel& m, std::vector<double> y) {
  const std::size_t attack = static_cast<std::size_t>(m.sampleRate / 10000);
  for (std::size_t i = 0; i < attack && i < y.size(); ++i)
    y[i] *= static_cast<double>(i + 1) / static_cast<double>(attack + 1);
  const std::vector<double> e = windowEnergy(y, static_cast<std::size_t>(m.sampleRate / 200));
  const double peak = *std::max_element(e.begin(), e.end());
  if (!(peak > 0.0)) throw std::runtime_error("sound database: a silent clip");
  const double threshold = peak * expP(-m.trimLevelDb / 10.0 * 2.302585092994045684);
  std::size_t end = e.size();
  while (end > 1 && e[end - 1] < threshold) --end;
  y.resize(end);
  const std::size_t fade = std::min(y.size(), static_cast<std::size_t>(m.sampleRate / 100));
  for (std::size_t j = 0; j < fade; ++j)
    y[y.size() - fade + j] *= 0.5 * (1.0 + cosP(kPi * static_cast<double>(j + 1) / fade));
  const auto window = static_cast<std::size_t>(std::llround(m.loudnessWindow * m.sampleRate));
  double energy = 0.0;
  for (std::size_t i = 0; i < std::min(window, y.size()); ++i) energy += y[i] * y[i];
  const double scale = m.clipRms * std::sqrt(static_cast<double>(window) / energy);
  std::vector<float> out(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) {
    const long long q = std::llround(y[i] * scale * kPcmScale);
    if (q > 32767 || q < -32768)
      throw std::runtime_error("sound database: a clip's peak exceeds full scale at clipRms " +
                               std::to_string(m.clipRms));
    out[i] = static_cast<float>(static_cast<double>(q) / kPcmScale);
  }
  return out;
}

std::string cmName(double cm) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", cm);
  return text;
}

std::string cmValue(double cm) {
  std::string s = cmName(cm);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

struct SndfileCloser {
  void operator()(SNDFILE* f) const { sf_close(f); }
};

// A mono 16-bit PCM WAV of samples on 16-bit steps, through libsndfile.
void writePcm16(const fs::path& path, const std::vector<float>& clip, int rate) {
  std::vector<short> q(clip.size());
  for (std::size_t i = 0; i < clip.size(); ++i)
    q[i] = static_cast<short>(std::llround(static_cast<double>(clip[i]) * kPcmScale));
  SF_INFO info{};
  info.samplerate = rate;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  std::unique_ptr<SNDFILE, SndfileCloser> file(sf_open(path.c_str(), SFM_WRITE, &info));
  if (!file)
    throw std::runtime_error(path.string() + ": cannot write the clip: " + sf_strerror(nullptr));
  const auto n = static_cast<sf_count_t>(q.size());
  if (sf_write_short(file.get(), q.data(), n) != n)
    throw std::runtime_error(path.string() +
                             ": writing the clip failed: " + sf_strerror(file.get()));
  if (sf_close(file.release()) != 0)
    throw std::runtime_error(path.string() + ": closing the clip failed");
}

void writeSpectrum(const fs::path& path, const std::vector<float>& power, const std::string& what,
                   const DatabaseModel& m) {
  std::string text = "# " + what + ": " + std::to_string(power.size()) + " powers, bin k at k * " +
                     std::to_string(m.sampleRate) + " / " + std::to_string(m.fftSize) + " Hz\n";
  char line[48];
  for (const float p : power) {
    std::snprintf(line, sizeof line, "%.9g\n", static_cast<double>(p));
    text += line;
  }
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": cannot write the spectrum");
}

// The checked cell's random stream for a clip (kind 0) or a friction
// spectrum (kind 1): a constrained resonator (border 0) draws the same
// stream whatever its ruling length.
CounterRng cellRng(const DatabaseModel& model, int kind, double ruling, double border,
                   int variant) {
  validate(model);
  validateCell(ruling, border, variant);
  return border == 0.0 ? variantRng(model, kind, 0.0, 0.0, variant)
                       : variantRng(model, kind, ruling, border, variant);
}

}  // namespace

std::vector<float> crumplingClip(const DatabaseModel& model, double ruling, double border,
                                 int variant) {
  const CounterRng rng = cellRng(model, 0, ruling, border, variant);
  const bool clac = border == 0.0;
  const double seconds = clac ? model.clacLength : model.flapLength;
  std::vector<double> y(static_cast<std::size_t>(std::llround(seconds * model.sampleRate)), 0.0);
  addModes(clac ? clacModes(model, rng) : flapModes(model, ruling, border, rng), model.sampleRate,
           y);
  const double crack = (clac ? model.clacTransient : model.flapTransient) * peakOf(y);
  addCrack(rng, 1u << 20, clac ? model.clacCrackTime : model.flapCrackTime, crack, model.sampleRate,
           y);
  return finishClip(model, std::move(y));
}

std::vector<float> frictionSpectrum(const DatabaseModel& model, double ruling, double border,
                                    int variant) {
  const CounterRng rng = cellRng(model, 1, ruling, border, variant);
  const bool constrained = border == 0.0;
  const std::size_t bins = static_cast<std::size_t>(model.fftSize / 2 + 1);
  const double binHz = static_cast<double>(model.sampleRate) / model.fftSize;
  const double level = model.constrainedPower * (1.0 + 0.1 * (rng.uniform(1) - 0.5));
  // The resonator's modal response, averaged over the contact's positions:
  // the modes add in power; broadband contact gives each mode the same
  // energy (equipartition), spread over its band of loss
  // frictionLossFactor (unit area), radiated in proportion to its weight.
  // `resonant` is the fraction of the modes' power in each bin.
  std::vector<double> resonant(bins, 0.0);
  if (!constrained) {
    const double a = ruling;
    const double b = 0.5 * border;
    const double radius = b / model.frictionArc;
    const double eta = model.frictionLossFactor;
    const int orders = model.frictionModes;
    double total = 0.0;
    for (int i = 1; i <= orders; ++i)
      for (int j = 1; j <= orders; ++j) {
        const std::uint64_t draw = 16 + 2 * static_cast<std::uint64_t>((i - 1) * orders + j - 1);
        const double f = stripFrequency(model, (i - 0.5) * kPi / a, j * kPi / b, radius) *
                         (1.0 + model.frictionJitter * (2.0 * rng.uniform(draw) - 1.0));
        const double nu = 1.0 / ((i - 0.5) * j);
        const double weight =
            nu * (1.0 + 10.0 * model.frictionJitter * (2.0 * rng.uniform(draw + 1) - 1.0));
        total += weight;
        // Its band as the M-point analysis sees it: its own bandwidth and the
        // analysis' resolution in quadrature. x^2 / ((1 - x^2)^2 + e^2 x^2)
        // has area pi / (2 e) over x.
        const double resolution = model.analysisBins * binHz / f;
        const double e = std::sqrt(eta * eta + resolution * resolution);
        const double unit = weight * 2.0 * e / kPi * binHz / f;
        for (std::size_t k = 1; k < bins; ++k) {
          const double x = k * binHz / f;
          const double x2 = x * x;
          resonant[k] += unit * x2 / ((1.0 - x2) * (1.0 - x2) + e * e * x2);
        }
      }
    for (double& r : resonant) r *= model.resonantGain * static_cast<double>(bins - 1) / total;
  }
  std::vector<float> power(bins, 0.0f);  // bin 0: no DC in friction noise
  const std::uint64_t jitter = 1u << 20;
  for (std::size_t k = 1; k < bins; ++k) {
    const double f = k * binHz / model.contactCorner;
    const double contact = level / std::sqrt(1.0 + f * f);
    const double wobble = 1.0 + model.binJitter * (2.0 * rng.uniform(jitter + k) - 1.0);
    power[k] = static_cast<float>(contact * (1.0 + resonant[k]) * wobble);
  }
  return power;
}

void generateDatabase(const fs::path& dir, const DatabaseModel& model) {
  validate(model);
  fs::create_directories(dir / "crumpling");
  fs::create_directories(dir / "friction");
  std::string index =
      "# The default sound database (thesis 4.3.3; docs/SOUND.md \"The default database\").\n"
      "# Generated by make_sound_db (apps/make_sound_db/make_sound_db.cpp) from a model, not\n"
      "# recorded: do not edit. Regenerate with scripts/make-sound-db.sh, or\n"
      "#   make_sound_db --force assets/sound/default\n"
      "\n[database]\n"
      "format = \"crumple-sound-db\"\n"
      "version = 1\n"
      "sample_rate = " +
      std::to_string(model.sampleRate) + "\nfft_size = " + std::to_string(model.fftSize) + "\n";
  const auto list = [](const std::vector<std::string>& names) {
    std::string s = "[";
    for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", \"" : "\"") + names[i] + "\"";
    return s + "]";
  };
  const auto cell = [&](double lrCm, double lcCm, const std::string& stem, int clips, int spectra) {
    const double ruling = 0.01 * lrCm;
    const double border = 0.01 * lcCm;
    std::vector<std::string> wavs;
    std::vector<std::string> txts;
    for (int v = 0; v < clips; ++v) {
      wavs.push_back("crumpling/" + stem + "_" + std::to_string(v) + ".wav");
      writePcm16(dir / wavs.back(), crumplingClip(model, ruling, border, v), model.sampleRate);
    }
    for (int v = 0; v < spectra; ++v) {
      txts.push_back("friction/" + stem + "_" + std::to_string(v) + ".txt");
      const std::string what = "friction spectrum of (l_r, l_c) = (" + cmName(lrCm) + ", " +
                               cmName(lcCm) + ") cm, variant " + std::to_string(v);
      writeSpectrum(dir / txts.back(), frictionSpectrum(model, ruling, border, v), what, model);
    }
    index += "\n[[cell]]\nl_r_cm = " + cmValue(lrCm) + "\nl_c_cm = " + cmValue(lcCm) +
             "\ncrumpling = " + list(wavs) + "\nfriction = " + list(txts) + "\n";
  };
  cell(0.0, 0.0, "constrained", model.constrainedClips, model.constrainedSpectra);
  for (const double lr : model.gridCm)
    for (const double lc : model.gridCm)
      cell(lr, lc, "lr" + cmName(lr) + "_lc" + cmName(lc), model.clipsPerCell,
           model.spectraPerCell);
  const fs::path path = dir / "index.toml";
  std::ofstream out(path, std::ios::binary);
  out << index;
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": cannot write the index");
}

}  // namespace crumple::sound
