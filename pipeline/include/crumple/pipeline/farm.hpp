#pragma once
// Farm execution on Slurm (docs/FARM.md; `crumple farm slurm`): one
// simulate job, a render job array over frame chunks that waits for it
// (afterok), and a finalize job (the soundtrack, the movie) after the whole
// array. slurmScripts writes the sbatch scripts' text and nothing else;
// submitSlurm writes them into DIR/farm/ and submits them with sbatch.
#include <cstdio>
#include <string>
#include <vector>

#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::pipeline {

struct SlurmOptions {
  std::string outDir;  // the shot folder; empty: as `crumple run` ([output] dir, else out/<name>)
  int chunk = 10;      // frames per render array task
  std::string partition;   // #SBATCH --partition; empty: the cluster's default
  std::string time;        // #SBATCH --time of each job (e.g. 1:00:00); empty: the partition's
  int cpusPerTask = 0;     // #SBATCH --cpus-per-task and the jobs' --threads; 0: not asked
  std::string mem;         // #SBATCH --mem (e.g. 4G); empty: the partition's default
  std::string renderArgs;  // extra `crumple render` arguments (--backend embree --spp 64 ...)
  std::string crumple;     // the binary the jobs run; empty: this process's own (/proc/self/exe)
  bool movie = true;       // finalize makes preview.mp4 from the frames (ffmpeg)
};

// The three scripts of a shot and what they cover. Paths are absolute.
struct SlurmScripts {
  std::string jobName;  // from the scene's name: <name>-simulate, -render, -finalize
  std::string outDir;
  std::string farmDir;  // outDir/farm: the scripts
  std::string logsDir;  // outDir/farm/logs: the jobs' output
  std::string cachePath;
  FrameRange frames;               // the scene's range
  std::vector<FrameRange> chunks;  // one per array task, in order, covering `frames` exactly
  bool sound = false;              // the scene has [sound]: finalize runs `crumple sound`
  std::string simulate, render, finalize;  // the scripts' text
};

// The range in chunks of `chunk` frames, in order, the last one shorter when
// the range does not divide. Throws InputError for chunk < 1.
std::vector<FrameRange> frameChunks(const FrameRange& range, int chunk);

// Splits --render-args into words: blanks separate them, single or double
// quotes keep blanks inside one. Throws InputError for an unclosed quote.
std::vector<std::string> splitArguments(const std::string& text);

// The scripts for a scene from io::loadScene (the jobs simulate its file,
// scene.file). Pure: reads and writes nothing, but resolves relative paths
// against the working folder and checks that the jobs' binary is
// executable. Throws InputError for a bad chunk size, render arguments the
// farm sets itself (--frames, --out, --movie, --contact-sheet), values that
// would break an #SBATCH line and a scene with [output] frames = false.
SlurmScripts slurmScripts(const io::SceneSpec& scene, const SlurmOptions& options);

// The sbatch command lines that submit the scripts, as a shell snippet
// (each job's id taken from `sbatch --parsable` into the next one's
// --dependency=afterok).
std::string sbatchCommands(const SlurmScripts& scripts);

struct SlurmJobs {
  std::string simulate, render, finalize;  // job ids
};

// Writes the scripts into DIR/farm/ (and creates DIR/farm/logs/), then
// submits them with `sbatch --parsable`, each depending on the one before.
// Throws InputError when sbatch is not on PATH or refuses a job (the jobs
// already submitted are cancelled with scancel).
SlurmJobs submitSlurm(const SlurmScripts& scripts);

// The finalize job's movie (`crumple farm movie CACHE`): DIR/preview.mp4
// from the frames the array wrote (DIR/frames/NNNN.png over the cached
// range) with DIR/sound.wav muxed in when there is one, through ffmpeg as
// `render --movie` does, without rendering anything. Throws InputError for a
// missing frame or a missing ffmpeg, std::runtime_error when ffmpeg fails.
// Returns the movie's path; `note` says when it is silent.
std::string makeShotMovie(const std::string& cachePath, std::string& note);

}  // namespace crumple::pipeline
