// What the soundtrack costs (its requirement: "synthesis speed as a multiple of real
// time per sample (target >= 200x) and the per-frame cost of events and
// resonators"):
//
//   bench_sound [SAMPLE ...] [--runs 3] [--json FILE]
//
// Simulates each sample (default: the samples with [sound]) `runs` times on
// one thread, without rendering, and makes its soundtrack (stereo, 48 kHz,
// the default database) `runs` times from the cache. Prints the medians of
// the simulation step per frame, the sound events' detection per frame and,
// of it, the resonators' growth; and the synthesis's time against the
// soundtrack's length (x real time; reading the cache and writing the files
// not included).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/pipeline/sound.hpp"
#include "shot_bench.hpp"

namespace {

using namespace crumple;
namespace fs = std::filesystem;

struct Row {
  std::string sample;
  int frames = 0;
  long events = 0;
  double stepMs = 0.0, eventsMs = 0.0, resonatorMs = 0.0;
  double seconds = 0.0, synthesisMs = 0.0, realTime = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  const auto parsed = bench::parseShotBenchArgs(
      argc, argv, "bench_sound", {"wiggle", "slide-on-table", "crumple", "tear-fast"});
  if (!parsed) return 0;
  const bench::ShotBenchArgs& args = *parsed;
  setThreadCount(1);
  const bench::ScratchDir scratch("crumple-bench-sound");
  std::vector<Row> rows;
  for (const std::string& name : args.samples) {
    const io::SceneSpec scene = bench::sampleScene(name);
    if (!scene.soundEnabled) {
      std::fprintf(stderr, "bench_sound: %s has no [sound] table\n", name.c_str());
      return 2;
    }
    Row row;
    row.sample = name;
    std::vector<double> step, events, resonators, synthesis;
    std::string cachePath;
    for (int r = 0; r < args.runs; ++r) {
      const pipeline::ShotReport report = bench::simulateQuietly(scene, scratch / name);
      const double frames = std::max(1, report.framesSimulated);
      step.push_back(bench::stepTotalMs(report) / frames);
      events.push_back(report.stages.at("sound events").totalMs / frames);
      resonators.push_back(report.soundResonatorMs / frames);
      row.frames = report.framesSimulated;
      row.events = report.soundEvents[0] + report.soundEvents[1] + report.soundEvents[2];
      cachePath = report.cachePath;
    }
    for (int r = 0; r < args.runs; ++r) {
      pipeline::SoundOptions options;
      options.out = (scratch.path() / name / "bench.wav").string();
      options.spectrogram = false;
      options.log = nullptr;
      options.interactive = 0;
      const pipeline::SoundReport sound = pipeline::makeSound(cachePath, options);
      synthesis.push_back(sound.synthesisMs);
      row.seconds = sound.seconds;
    }
    row.stepMs = bench::median(step);
    row.eventsMs = bench::median(events);
    row.resonatorMs = bench::median(resonators);
    row.synthesisMs = bench::median(synthesis);
    row.realTime = row.synthesisMs > 0.0 ? 1000.0 * row.seconds / row.synthesisMs : 0.0;
    rows.push_back(row);
    std::printf(
        "%-15s %3d frames, %4ld events  step %7.2f ms/frame  events %6.3f ms/frame (resonators "
        "%6.3f)  synthesis %7.1f ms for %.2f s: %6.0fx real time\n",
        row.sample.c_str(), row.frames, row.events, row.stepMs, row.eventsMs, row.resonatorMs,
        row.synthesisMs, row.seconds, row.realTime);
    std::fflush(stdout);
  }
  const auto toJson = [](const Row& r) {
    return bench::format(
        "{\"sample\": \"%s\", \"frames\": %d, \"events\": %ld, "
        "\"step_ms_per_frame\": %.6g, \"events_ms_per_frame\": %.6g, "
        "\"resonator_ms_per_frame\": %.6g, \"seconds\": %.6g, \"synthesis_ms\": %.6g, "
        "\"x_real_time\": %.6g}",
        r.sample.c_str(), r.frames, r.events, r.stepMs, r.eventsMs, r.resonatorMs, r.seconds,
        r.synthesisMs, r.realTime);
  };
  if (!bench::writeSampleRows(args, "bench_sound", rows, toJson)) return 1;
  return 0;
}
