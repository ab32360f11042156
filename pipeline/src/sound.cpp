// `crumple sound`: the soundtrack from a cache (docs/SOUND.md "crumple sound").
#include "crumple/pipeline/sound.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/progress.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "crumple/sound/database.hpp"
#include "crumple/sound/soundtrack.hpp"
#include "crumple/sound/spectrogram.hpp"
#include "crumple/sound/wav.hpp"

namespace crumple::pipeline {
namespace fs = std::filesystem;

namespace {

constexpr double kPeakDbfs = -1.0;  // the normalised mix's peak

const char* kindName(sound::EventKind kind) {
  return kind == sound::EventKind::Crumpling  ? "crumpling"
         : kind == sound::EventKind::Friction ? "friction"
                                              : "tearing";
}

// The table the sources are mirrored in (4.3.4): the scene's first plane
// collider, else its ground.
std::optional<sound::ReflectingPlane> tableOf(const io::SceneSpec& scene) {
  for (const auto& c : scene.colliders)
    if (c.kind == io::ColliderSpec::Kind::Plane && c.node.empty())
      return sound::ReflectingPlane{c.position, c.normal};
  if (scene.ground.enabled)
    return sound::ReflectingPlane{Vec3(0.0, scene.ground.height, 0.0), Vec3::UnitY()};
  return std::nullopt;
}

// Atomically: PATH.tmp then rename.
void renameInto(const fs::path& tmp, const fs::path& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw InputError(path.string(), "cannot write: " + ec.message());
}

}  // namespace

std::string defaultSoundDatabase() {
  if (const char* env = std::getenv("CRUMPLE_ASSETS"); env && *env) {
    const fs::path dir = fs::path(env) / "sound" / "default";
    if (fs::exists(dir / "index.toml")) return dir.string();
  }
  return (fs::path(CRUMPLE_SOURCE_ASSETS) / "sound" / "default").string();
}

namespace {

// A gain beyond this is no mix (200 dB is a factor of 1e10).
constexpr int kMaxGainDb = 200;

// The WAV: --out as given, DIR/sound.wav when --out names a folder (an
// existing one, or a path ending in '/'), else sound.wav beside the cache.
std::string soundPath(const std::string& cachePath, const std::string& out) {
  if (out.empty()) return (fs::path(cachePath).parent_path() / "sound.wav").string();
  std::error_code ec;
  if (out.back() == '/' || fs::is_directory(out, ec)) return (fs::path(out) / "sound.wav").string();
  return out;
}

// A frame's SEVT block, its errors naming the cache and the frame.
std::optional<std::vector<sound::SoundEvent>> frameEvents(const std::string& cachePath,
                                                          const cache::FrameRecord& record) {
  try {
    return cache::decodeSoundEvents(record.extensions);
  } catch (const CorruptDataError& e) {
    throw CorruptDataError(cachePath + ": frame " + std::to_string(record.frame) + ": " + e.what());
  }
}

}  // namespace

SoundReport makeSound(const std::string& cachePath, const SoundOptions& options) {
  const cache::CacheReader reader(cachePath);
  if (reader.frameCount() == 0) throw InputError(cachePath, "the cache holds no frames");
  const auto& header = reader.header();
  SoundReport report;
  if (std::string note = recoveredNote(reader); !note.empty()) {
    if (options.log) std::fprintf(options.log, "crumple sound: note: %s\n", note.c_str());
    report.notes.push_back(std::move(note));
  }
  if (!cache::decodeSoundSetup(header.extensions))
    throw InputError(cachePath,
                     "the cache has no sound events: its scene had no [sound] table when it was "
                     "simulated (add [sound] to the scene and run crumple simulate again)");
  const io::SceneSpec scene =
      io::parseScene(header.sceneText, header.sceneFile + " (in " + cachePath + ")",
                     fs::path(header.sceneFile).parent_path().string(),
                     /*checkFiles=*/false);
  report.sampleRate = options.sampleRate.value_or(scene.soundtrack.sampleRate);
  if (!sound::supportedSampleRate(report.sampleRate))
    throw InputError("--rate", std::to_string(report.sampleRate) + " Hz: 48000 or 44100");
  report.channels = options.channels.value_or(scene.soundtrack.channels);
  if (report.channels != 1 && report.channels != 2)
    throw InputError("--channels", std::to_string(report.channels) + ": 1 (mono) or 2 (stereo)");
  const bool floatSamples = options.floatSamples.value_or(scene.soundtrack.floatSamples);
  report.databasePath = !options.database.empty()            ? options.database
                        : !scene.soundtrack.database.empty() ? scene.soundtrack.database
                                                             : defaultSoundDatabase();
  report.wavPath = soundPath(cachePath, options.out);
  if (options.gainDb && !(std::abs(*options.gainDb) <= kMaxGainDb))
    throw InputError("--gain-db", "must be a number of dB within +-" + std::to_string(kMaxGainDb));
  std::optional<OutputLock> lock;
  if (options.lockFolder) lock.emplace(fs::path(report.wavPath).parent_path().string());

  const sound::SoundDatabase db =
      sound::SoundDatabase::load(report.databasePath).resampledTo(report.sampleRate);

  // The events, frame by frame, and where they are heard from.
  report.frames = static_cast<int>(reader.frameCount());
  std::vector<sound::FrameEvents> frames(reader.frameCount());
  Progress progress("crumple sound (reading events)", static_cast<long>(reader.frameCount()),
                    options.log, options.interactive);
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const cache::FrameRecord record = reader.readFrame(i);
    sound::FrameEvents& f = frames[i];
    f.listener = scene.soundtrack.listener.value_or(record.camera.position);
    f.right = record.camera.rotation * Vec3::UnitX();
    if (const auto events = frameEvents(cachePath, record))
      for (const auto& r : *events) {
        f.events.push_back(r);
        switch (r.kind) {
          case sound::EventKind::Crumpling:
            ++report.crumplingEvents;
            for (const auto& q : r.resonators)
              ++(q.border > 0.0 ? report.flapResonators : report.clacResonators);
            break;
          case sound::EventKind::Friction:
            ++report.frictionEvents;
            for (const auto& q : r.resonators)
              ++(q.border > 0.0 ? report.freeFriction : report.constrainedFriction);
            break;
          default:
            ++report.tearingEvents;
        }
      }
    progress.update(static_cast<long>(i + 1));
  }
  progress.finish();

  const sound::Timeline timeline(report.sampleRate, header.fps, report.frames);
  sound::SoundtrackSettings settings;
  settings.channels = report.channels;
  settings.table = tableOf(scene);
  settings.seed = header.seed;
  const auto start = std::chrono::steady_clock::now();
  sound::Audio audio = sound::renderSoundtrack(db, timeline, frames, settings);
  report.synthesisMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const double peak = sound::peakLevel(audio);
  report.gainDb = options.gainDb ? *options.gainDb
                  : peak > 0.0   ? kPeakDbfs - 20.0 * std::log10(peak)
                                 : 0.0;
  const auto gain = static_cast<float>(std::pow(10.0, report.gainDb / 20.0));
  for (auto& channel : audio.channels)
    for (float& v : channel) v *= gain;
  report.peak = sound::peakLevel(audio);
  report.samples = static_cast<std::int64_t>(audio.sampleCount());
  report.seconds = static_cast<double>(report.samples) / report.sampleRate;

  const fs::path wav(report.wavPath);
  if (wav.has_parent_path()) fs::create_directories(wav.parent_path());
  const fs::path wavTmp = wav.string() + ".tmp";
  try {
    report.clipped = sound::writeWav(
        wavTmp, audio, floatSamples ? sound::SampleFormat::Float32 : sound::SampleFormat::Pcm24);
  } catch (const std::runtime_error& e) {
    std::error_code ec;
    fs::remove(wavTmp, ec);  // a full disk leaves no temporary behind
    throw InputError(report.wavPath, e.what());
  }
  renameInto(wavTmp, wav);
  if (options.spectrogram) {
    fs::path png = wav;
    png.replace_extension(".png");
    exporters::writePng(png.string(), sound::spectrogram(audio));
    report.spectrogramPath = png.string();
  }
  return report;
}

std::string eventTimeline(const std::string& cachePath) {
  const cache::CacheReader reader(cachePath);
  if (!cache::decodeSoundSetup(reader.header().extensions))
    throw InputError(cachePath, "the cache has no sound events (its scene had no [sound] table)");
  std::ostringstream out;
  out << "# frame time_s kind amplitude x y z | resonators: l_r_cm l_c_cm area_cm2 "
         "(clac/flap for crumpling)\n";
  char line[256];
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const cache::FrameRecord record = reader.readFrame(i);
    const auto events = frameEvents(cachePath, record);
    if (!events) continue;
    for (const auto& e : *events) {
      std::snprintf(line, sizeof line, "%d %.4f %s %.4g %.3f %.3f %.3f |", record.frame,
                    record.time, kindName(e.kind), e.amplitude, e.position.x(), e.position.y(),
                    e.position.z());
      out << line;
      for (const auto& q : e.resonators) {
        std::snprintf(
            line, sizeof line, " %.1f %.1f %.0f%s", 100.0 * q.ruling, 100.0 * q.border,
            1e4 * q.area,
            e.kind == sound::EventKind::Crumpling ? (q.border > 0.0 ? " flap" : " clac") : "");
        out << line << ";";
      }
      out << "\n";
    }
  }
  return out.str();
}

}  // namespace crumple::pipeline
