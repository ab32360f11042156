// Thesis Algorithm 4: a shot's events into a soundtrack (docs/SOUND.md
// "The soundtrack").
#include "crumple/sound/soundtrack.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <span>
#include <stdexcept>
#include <string>

#include "crumple/core/rng.hpp"
#include "crumple/sound/crumpling_synth.hpp"
#include "crumple/sound/friction_synth.hpp"

namespace crumple::sound {
namespace {

constexpr double kMinDistance = 0.01;  // m: a source nearer the ear than this is not heard
constexpr double kTearRamp = 0.002;    // s: a tear's crackle fades in and out over this

std::vector<Vec3> earsOf(const FrameEvents& f, const SoundtrackSettings& s) {
  if (s.channels == 1) return {f.listener};
  const Vec3 right = f.right.norm() > 0.0 ? Vec3(f.right.normalized()) : Vec3::UnitX();
  return {f.listener - 0.5 * s.earSpacing * right, f.listener + 0.5 * s.earSpacing * right};
}

// The dipole's response at an ear, its gains relative to the reference
// disk's at 1 m; nullopt when the ear is at the source.
std::optional<DipoleResponse> responseAt(const Vec3& position, const Vec3& normal, double radius,
                                         const Vec3& ear, const SoundtrackSettings& s) {
  if ((ear - position).norm() < kMinDistance) return std::nullopt;
  const ReflectingPlane* table = s.table ? &*s.table : nullptr;
  const Vec3 n = normal.norm() > 0.0 ? Vec3(normal.normalized()) : Vec3::UnitY();
  DipoleResponse r = dipoleResponse({position, n, radius}, ear, table);
  const double unit = 1.0 / std::pow(s.referenceRadius, 3);
  r.direct.gain *= unit;
  if (r.image) r.image->gain *= unit;
  return r;
}

// Each resonator's share of its event: the event's power split by area.
double areaShare(const SoundEvent& e, const Resonator& r) {
  double total = 0.0;
  for (const auto& q : e.resonators) total += q.area;
  return total > 0.0 ? r.area / total : 0.0;
}

}  // namespace

double peakLevel(const Audio& audio) {
  double peak = 0.0;
  for (const auto& c : audio.channels)
    for (float v : c) peak = std::max(peak, static_cast<double>(std::abs(v)));
  return peak;
}

namespace {

// What the parts of a soundtrack share: the inputs, the frames with events and the output.
struct SoundtrackRender {
  const SoundDatabase& db;
  const Timeline& timeline;
  const std::vector<FrameEvents>& frames;
  const SoundtrackSettings& s;
  std::size_t frameCount;  // frames with events within the timeline
  std::int64_t length;     // samples
  Audio& audio;
  SoundtrackStats& stats;
};

// thesis 4.3.3: each crumpling resonator's clip at its frame's sample, its variant drawn per
// resonator (the same for both ears).
void addCrumplingClips(SoundtrackRender& render) {
  const SoundDatabase& db = render.db;
  const Timeline& timeline = render.timeline;
  const std::vector<FrameEvents>& frames = render.frames;
  const SoundtrackSettings& s = render.s;
  const std::size_t frameCount = render.frameCount;
  Audio& audio = render.audio;
  SoundtrackStats& stats = render.stats;
  std::int64_t clipId = 0;
  for (std::size_t f = 0; f < frameCount; ++f) {
    const std::vector<Vec3> ears = earsOf(frames[f], s);
    const double time = timeline.timeOf(timeline.frameStart(static_cast<int>(f)));
    for (const auto& e : frames[f].events) {
      if (e.kind != EventKind::Crumpling) continue;
      for (const auto& r : e.resonators) {
        const std::int64_t id = clipId++;
        const double amplitude =
            s.crumplingGain * (e.amplitude / s.crumplingReference) * std::sqrt(areaShare(e, r));
        for (std::size_t c = 0; c < ears.size(); ++c) {
          const auto response = responseAt(r.centre, r.normal, r.radius, ears[c], s);
          if (!response) {
            ++stats.silentSources;
            continue;
          }
          if (addCrumplingSound(db, {time, amplitude, r.ruling, r.border, *response}, timeline,
                                s.seed, id, audio.channels[c]))
            ++stats.crumplingClips;
        }
      }
    }
  }
}

// thesis Algorithm 4, eq. (4.12): per frame and ear, the friction resonators' spectra weighted
// by their event's speed and area share and by the dipole's factor, summed (empty: silent).
std::vector<std::vector<std::vector<float>>> frictionSpectra(SoundtrackRender& render,
                                                             bool& anyFriction) {
  const SoundDatabase& db = render.db;
  const Timeline& timeline = render.timeline;
  const std::vector<FrameEvents>& frames = render.frames;
  const SoundtrackSettings& s = render.s;
  const std::size_t frameCount = render.frameCount;
  SoundtrackStats& stats = render.stats;
  const int m = db.fftSize();
  const std::size_t bins = static_cast<std::size_t>(m / 2 + 1);
  std::vector<std::vector<std::vector<float>>> spectra(
      frameCount, std::vector<std::vector<float>>(static_cast<std::size_t>(s.channels)));
  for (std::size_t f = 0; f < frameCount; ++f) {
    const std::vector<Vec3> ears = earsOf(frames[f], s);
    std::int64_t resonatorIndex = 0;
    for (const auto& e : frames[f].events) {
      if (e.kind != EventKind::Friction) continue;
      for (const auto& r : e.resonators) {
        const SoundCell* cell = db.frictionCell(r.ruling, r.border);
        if (cell == nullptr) continue;
        const CounterRng rng(s.seed, static_cast<std::int64_t>(f), RngPurpose::SoundVariant);
        const auto& spectrum = cell->spectra[static_cast<std::size_t>(
            rng.bits(static_cast<std::uint64_t>(resonatorIndex++)) % cell->spectra.size())];
        const double weight =
            s.frictionGain * (e.amplitude / s.frictionReference) * areaShare(e, r);
        for (std::size_t c = 0; c < ears.size(); ++c) {
          const auto response = responseAt(r.centre, r.normal, r.radius, ears[c], s);
          if (!response) {
            ++stats.silentSources;
            continue;
          }
          const std::vector<float> factor = powerFactor(*response, m, timeline.sampleRate());
          auto& sum = spectra[f][c];
          if (sum.empty()) sum.assign(bins, 0.0f);
          for (std::size_t k = 0; k < bins; ++k)
            sum[k] += static_cast<float>(weight * spectrum[k] * factor[k]);
          anyFriction = true;
        }
      }
    }
  }
  return spectra;
}

// thesis 4.3.3 (friction by inverse FFT): each channel's friction noise, each block sounding
// the spectrum of its centre's time interpolated between frames.
void synthesizeFriction(SoundtrackRender& render,
                        const std::vector<std::vector<std::vector<float>>>& spectra) {
  const Timeline& timeline = render.timeline;
  const SoundtrackSettings& s = render.s;
  const std::size_t frameCount = render.frameCount;
  const std::int64_t length = render.length;
  Audio& audio = render.audio;
  SoundtrackStats& stats = render.stats;
  const int m = render.db.fftSize();
  const std::size_t bins = static_cast<std::size_t>(m / 2 + 1);
  const std::int64_t hop = m / 2;
  // Blocks start one hop before the first sample, so that every sample
  // lies under two windows.
  const std::int64_t blocks = (length + hop) / hop + 1;
  std::vector<float> power(bins);
  for (std::size_t c = 0; c < static_cast<std::size_t>(s.channels); ++c) {
    FrictionSynth synth(m, s.seed);
    std::vector<float> out;
    for (std::int64_t b = 0; b < blocks; ++b) {
      const double centre = timeline.timeOf(b * hop - hop + m / 2);
      const double at =
          std::clamp(centre * timeline.fps(), 0.0, static_cast<double>(frameCount - 1));
      const std::size_t f0 = static_cast<std::size_t>(std::floor(at));
      const std::size_t f1 = std::min(f0 + 1, frameCount - 1);
      const double w = at - static_cast<double>(f0);
      const auto& p0 = spectra[f0][c];
      const auto& p1 = spectra[f1][c];
      if (p0.empty() && p1.empty()) continue;
      bool silent = true;
      for (std::size_t k = 0; k < bins; ++k) {
        power[k] = static_cast<float>((p0.empty() ? 0.0 : (1.0 - w) * p0[k]) +
                                      (p1.empty() ? 0.0 : w * p1[k]));
        silent = silent && power[k] == 0.0f;
      }
      if (silent) continue;
      synth.addBlock(b, power, out);
      ++stats.frictionBlocks;
    }
    auto& channel = audio.channels[c];
    channel.resize(std::max(channel.size(), out.size() > static_cast<std::size_t>(hop)
                                                ? out.size() - static_cast<std::size_t>(hop)
                                                : 0),
                   0.0f);
    for (std::size_t i = static_cast<std::size_t>(hop); i < out.size(); ++i)
      channel[i - static_cast<std::size_t>(hop)] += out[i];
  }
}

// thesis 4.4.1: each tear's crackle at its tip's speed over the time each advance took, its
// edges ramped, spatialised frame by frame as a small disk at the tip.
void addTearingNoise(SoundtrackRender& render) {
  const Timeline& timeline = render.timeline;
  const std::vector<FrameEvents>& frames = render.frames;
  const SoundtrackSettings& s = render.s;
  const std::size_t frameCount = render.frameCount;
  const std::int64_t length = render.length;
  Audio& audio = render.audio;
  SoundtrackStats& stats = render.stats;
  std::map<int, std::vector<std::pair<std::size_t, const SoundEvent*>>> tears;
  for (std::size_t f = 0; f < frameCount; ++f)
    for (const auto& e : frames[f].events)
      if (e.kind == EventKind::Tearing) tears[e.tear].push_back({f, &e});
  const double frameTime = 1.0 / timeline.fps();
  const auto frameSample = [&](std::size_t f) { return timeline.frameStart(static_cast<int>(f)); };
  for (const auto& [tear, advances] : tears) {
    // The tip's speed at every sample the tear sounds in.
    const std::int64_t first = std::max<std::int64_t>(
        0, timeline.sampleAt(static_cast<double>(advances.front().first) * frameTime -
                             advances.front().second->duration));
    const std::int64_t last = std::min<std::int64_t>(length, frameSample(advances.back().first));
    if (last <= first) continue;
    std::vector<double> speed(static_cast<std::size_t>(last - first), 0.0);
    const double ramp = kTearRamp * timeline.sampleRate();
    for (const auto& [f, e] : advances) {
      const std::int64_t to = std::min(last, frameSample(f));
      const std::int64_t from =
          std::max(first, timeline.sampleAt(static_cast<double>(f) * frameTime - e->duration));
      for (std::int64_t i = from; i < to; ++i) {
        const double edge =
            std::min(static_cast<double>(i - from + 1), static_cast<double>(to - i));
        speed[static_cast<std::size_t>(i - first)] += e->amplitude * std::min(1.0, edge / ramp);
      }
    }
    for (std::size_t c = 0; c < static_cast<std::size_t>(s.channels); ++c) {
      TearingNoise noise(s.seed, tear, s.tearing);
      std::vector<float> track;  // the crackle at the tip, by output sample
      noise.add(first, speed, track);
      stats.tearingSamples += static_cast<long>(speed.size());
      // Frame by frame: heard from where the tip was at the frame's end
      // (the next advance's place).
      std::size_t next = 0;
      for (std::size_t f = 0; f < frameCount; ++f) {
        const std::int64_t start = std::max(first, f == 0 ? 0 : frameSample(f - 1));
        const std::int64_t end = std::min(last, frameSample(f));
        if (end <= start) continue;
        while (next + 1 < advances.size() && advances[next].first < f) ++next;
        const SoundEvent& at = *advances[next].second;
        const std::vector<Vec3> ears = earsOf(frames[f], s);
        const auto response = responseAt(at.position, at.normal, s.tearingRadius, ears[c], s);
        if (!response) {
          ++stats.silentSources;
          continue;
        }
        addClip(std::span<const float>(track.data() + start, static_cast<std::size_t>(end - start)),
                *response, timeline.sampleRate(), start, audio.channels[c]);
      }
    }
  }
}

}  // namespace

Audio renderSoundtrack(const SoundDatabase& db, const Timeline& timeline,
                       const std::vector<FrameEvents>& frames, const SoundtrackSettings& s,
                       SoundtrackStats* statsOut) {
  if (db.sampleRate() != timeline.sampleRate())
    throw std::invalid_argument("renderSoundtrack: the database is at " +
                                std::to_string(db.sampleRate()) + " Hz, the soundtrack at " +
                                std::to_string(timeline.sampleRate()));
  if (s.channels != 1 && s.channels != 2)
    throw std::invalid_argument("renderSoundtrack: 1 or 2 channels, not " +
                                std::to_string(s.channels));
  SoundtrackStats stats;
  const std::int64_t length = timeline.sampleCount();
  const std::size_t frameCount =
      std::min(frames.size(), static_cast<std::size_t>(timeline.frameCount()));
  Audio audio;
  audio.sampleRate = timeline.sampleRate();
  audio.channels.assign(static_cast<std::size_t>(s.channels), {});

  // Crumpling (4.3.3): each resonator's clip at the frame's sample, its
  // variant drawn per resonator (the same for both ears).
  SoundtrackRender render{db, timeline, frames, s, frameCount, length, audio, stats};
  addCrumplingClips(render);

  // Friction (Algorithm 4): per frame and ear, the resonators' spectra
  // weighted by their event's speed and area share and by the dipole's
  // eq. (4.12) factor, summed; each noise block sounds the spectrum of its
  // centre's time, interpolated between frames.
  bool anyFriction = false;
  const std::vector<std::vector<std::vector<float>>> spectra = frictionSpectra(render, anyFriction);
  if (anyFriction) synthesizeFriction(render, spectra);

  // Tearing (4.4.1): each tear's crackle at its tip's speed over the time
  // each advance took (SoundEvent::duration, ending at its frame), its
  // edges ramped over kTearRamp; spatialised frame by frame as a small disk
  // at the tip.
  addTearingNoise(render);
  for (auto& channel : audio.channels) channel.resize(static_cast<std::size_t>(length), 0.0f);
  if (statsOut != nullptr) *statsOut = stats;
  return audio;
}

}  // namespace crumple::sound
