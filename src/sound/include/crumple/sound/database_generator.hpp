#pragma once
// The generated default sound database (thesis 4.3.3;
// docs/SOUND.md "The default database"). There are no recordings to ship,
// so the database is made from a physically motivated model of what the
// thesis recorded: for each resonator size (l_r, l_c), a sheet of
// 80 g/m^2 paper l_r x l_c/2, its l_c/2 edge bent; its crumpling sound (the
// "flap" of a snap-through) and its friction spectrum; and the constrained
// cell (0, 0): the "clac" of a facet without a free border, and the
// near-white friction of a flat sheet.
//
// The output is a pure function of the model: only +, -, *, / and sqrt
// (IEEE-exact) go into a sample or a power (the generator carries its own
// exp, sin and cos), random numbers come from CounterRng keyed by cell and
// variant, and files are written in a fixed order and format. The shipped
// assets/sound/default is byte for byte what generateDatabase writes.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace crumple::sound {

// The model's constants. Lengths in metres unless named otherwise.
struct DatabaseModel {
  // --- the database (thesis 4.3.5: "Recording of the database")
  int sampleRate = 48000;  // Hz, of every clip
  int fftSize = 2048;      // M: a spectrum has M / 2 + 1 bins
  // l_r and l_c values of the grid (cm, as in the index): every pair is a cell.
  std::vector<double> gridCm = {2.5, 5.0, 7.5, 10.0, 12.5, 15.0, 20.0, 25.0, 30.0};
  int clipsPerCell = 3;                      // flap variants per unconstrained cell
  int spectraPerCell = 2;                    // friction variants per unconstrained cell
  int constrainedClips = 6;                  // clac variants
  int constrainedSpectra = 3;                // constrained friction variants
  std::uint64_t seed = 0x50415045524442ULL;  // "PAPERDB"

  // --- the paper: 80 g/m^2 printer paper (thesis 4.3.3)
  double thickness = 1.0e-4;     // h (m)
  double youngModulus = 3.5e9;   // E (Pa)
  double poissonRatio = 0.3;     // nu
  double surfaceDensity = 0.08;  // rho_s (kg/m^2)

  // --- the flap: modes of the curved strip l_r x l_c/2 (plate bending plus
  // the shallow shell's curvature cut-on), struck by the snap-through
  double flapArc = 1.5734;        // rad the l_c/2 edge spans: chord 0.9 x arc (10 % compression)
  int flapModes = 16;             // orders m, n = 1 .. flapModes
  double airDamping = 24.0;       // 1/s at 1 kHz: the air's, (f / 1 kHz)^(1/4) elsewhere
  double lossFactor = 0.0005;     // eta: the paper's, pi eta f
  double snapTime = 5.0e-5;       // s: the snap's force pulse (its spectrum's corner)
  double flapTransient = 0.6;     // the onset's crack, to the modes' peak
  double flapCrackTime = 1.0e-3;  // s: its decay time constant
  double flapLength = 0.6;        // s: the longest flap before trimming

  // --- the clac: a small facet held by ridges, no free border
  double facetMin = 0.01;  // its sides are drawn in [facetMin, facetMax]
  double facetMax = 0.025;
  double facetRadius = 0.03;    // its curvature radius
  double ridgeDamping = 350.0;  // 1/s: what the ridges drain, for every mode
  double facetLossFactor = 0.01;
  double clacTransient = 1.0;  // the crack, to the modes' peak
  double clacCrackTime = 4.0e-4;
  double clacLength = 0.06;  // s

  // --- clip level: every clip has this RMS over its first loudnessWindow s
  // (the ear's integration time), so a clac and a flap sound equally loud
  double clipRms = 0.0316;      // -30 dBFS
  double loudnessWindow = 0.1;  // s
  double trimLevelDb = 42.0;    // a clip ends where its 5 ms energy is this far below its peak

  // --- friction: contact noise through the resonator's modes (thesis 4.3.1, Fig. 4.6, 4.16)
  double frictionArc = 2.8204;       // rad: chord 0.7 x arc (30 % compression, thesis 4.3.5)
  int frictionModes = 24;            // orders m, n = 1 .. frictionModes
  double frictionLossFactor = 0.12;  // the table's contact damps the modes
  double analysisBins = 1.5;         // the M-point analysis' resolution (bins)
  double contactCorner = 6000.0;     // Hz: the contact noise's -3 dB/octave corner
  double constrainedPower = 0.8;     // the contact noise's power per bin at low frequency
  double resonantGain = 8.0;         // the modes' power, to the contact noise's
  double frictionJitter = 0.0025;    // a variant's mode frequencies vary by +-this, weights 10x
  double binJitter = 0.02;           // a variant's bins vary by +-binJitter
};

// Thesis 4.3.3 "Sound Databases": the crumpling clip `variant` of the cell
// (l_r, l_c) = (ruling, border) (m): a clac when border = 0 (ruling is then
// ignored), else a flap. Mono at model.sampleRate, as stored: 16-bit steps
// of 1/32768. Throws std::invalid_argument for a bad model, a variant
// outside 0 .. 255, a size outside [0, 10] m or l_r = 0 with l_c > 0;
// std::runtime_error if the model's level would clip it.
std::vector<float> crumplingClip(const DatabaseModel& model, double ruling, double border,
                                 int variant);

// Thesis 4.3.3 "Sound Databases" and Fig. 4.6, 4.16: the friction power
// spectrum `variant` of the cell (l_r, l_c) (m): the near-white spectrum of a
// flat sheet when border = 0, else contact noise through the modes of the
// l_r x l_c/2 strip. M / 2 + 1 powers (bin k at k * rate / M Hz), as stored.
// Throws as crumplingClip does.
std::vector<float> frictionSpectrum(const DatabaseModel& model, double ruling, double border,
                                    int variant);

// Thesis 4.3.3 "Sound Databases": writes the database into `dir` (created if
// need be; files of the same names are overwritten): index.toml,
// crumpling/*.wav (16-bit PCM), friction/*.txt. The constrained cell comes
// first, then the grid with l_r outer, l_c inner. Throws
// std::invalid_argument for a bad model, std::runtime_error naming the file
// when one cannot be written.
void generateDatabase(const std::filesystem::path& dir, const DatabaseModel& model = {});

}  // namespace crumple::sound
