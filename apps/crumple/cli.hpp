#pragma once
// The `crumple` command line (docs/ARCHITECTURE.md "The command line"): the options
// every command fills, and the commands. Exit status: 0 success, 1 internal
// failure (including a numerical failure that survived substep halving), 2
// bad input.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "crumple/pipeline/farm.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::cli {

struct Args {
  std::string scene;
  std::string cache;
  std::string out;
  std::string frames;
  std::string seed;  // --seed as typed (parseSeed)
  int threads = 1;
  std::string backend = "osmesa";
  int spp = 16;
  int bounces = 4;
  std::string pass = "beauty";
  bool exr = false;
  bool noPng = false;
  std::string aovs;     // --aov: a comma-separated list (render/aov.hpp)
  std::string refine;   // --refine: auto, off or N (pipeline/refine.hpp); empty: the default
  std::string shutter;  // --shutter as typed (parseShutter)
  bool contactSheet = false;
  bool movie = false;
  bool json = false;
  bool debugStructure = false;
  std::string debug;  // --debug switches (core/debug.hpp)
  int checkpointEvery = 0;
  bool resume = false;
  // compare
  std::string imageA, imageB, metric = "flip", diff;
  double tolerance = 0.05;
  std::optional<double> shapeTolerance;  // caches: m, on every frame's mean distance
  // sound
  std::optional<int> rate, channels;
  std::string format, database;
  std::optional<double> gainDb;
  bool noSpectrogram = false;
  bool listEvents = false;
  // export
  std::string exportFormat;
  // farm
  pipeline::SlurmOptions slurm;
  bool dryRun = false;
  // init
  bool force = false;
};

// How frames are drawn, from the options `run` and `render` share.
pipeline::RenderSettings renderSettings(const Args& a);
void addRenderOptions(CLI::App* cmd, Args& a);
// --seed: a whole number in [0, 2^63 - 1] (InputError otherwise).
std::uint64_t parseSeed(const std::string& text);
// --shutter: OPEN,CLOSE in frames (-1 <= OPEN < CLOSE <= 1), or S, the
// time it is open centred on the frame (0 <= S <= 2); 0 is closed (no motion
// blur). InputError otherwise.
cache::Shutter parseShutter(const std::string& text);
// The help text of --shutter for `run`/`simulate` and for `render`.
extern const char* const kShutterShotHelp;
extern const char* const kShutterRenderHelp;

// The commands; each returns the exit status or throws (main maps the
// exception to the status).
int runOrSimulate(const Args& a, bool render);
int renderCommand(const Args& a);
int soundCommand(const Args& a);
int compareCommand(const Args& a);
int exportCommand(const Args& a);
int inspectCommand(const Args& a);
int farmCommand(const Args& a, const CLI::App& slurm);
int initCommand(const Args& a);

}  // namespace crumple::cli
