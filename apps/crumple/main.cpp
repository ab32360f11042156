// The `crumple` command line (docs/ARCHITECTURE.md "The command line"): the commands
// and their options, and the exit status each outcome maps to: 0 success, 1
// internal failure (including a numerical failure that survived substep
// halving), 2 bad input. `crumple bench` runs crumple-bench, built beside
// this binary (the production binary does not link the bench harness).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "cli.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/exit_status.hpp"

namespace crumple::cli {
namespace {

// Every command, once registered (dispatch asks which one was given).
struct Commands {
  CLI::App* run = nullptr;
  CLI::App* simulate = nullptr;
  CLI::App* render = nullptr;
  CLI::App* soundCmd = nullptr;
  CLI::App* compare = nullptr;
  CLI::App* inspect = nullptr;
  CLI::App* exportCmd = nullptr;
  CLI::App* farm = nullptr;
  CLI::App* farmSlurm = nullptr;
  CLI::App* bench = nullptr;
  CLI::App* init = nullptr;
};

// `run` and `simulate`: a shot from its scene.
void addShotCommands(CLI::App& app, Args& a, Commands& c) {
  c.run = app.add_subcommand(
      "run",
      "Simulate a shot, write its cache and render its frames (and, for a scene with [sound], "
      "write its soundtrack sound.wav).");
  c.simulate = app.add_subcommand(
      "simulate",
      "Simulate a shot and write its cache only (with the sound events of a scene with [sound]).");
  for (auto* cmd : {c.run, c.simulate}) {
    cmd->add_option("SCENE", a.scene, "scene.toml, or a folder holding one")->required();
    cmd->add_option("--out", a.out,
                    "output folder (default: the scene's [output] dir, else out/<scene name>); "
                    "one crumple writes into a folder at a time (DIR/.crumple.lock): another "
                    "one writing there makes this exit 2");
    cmd->add_option(
        "--frames", a.frames,
        "A-B: simulate from the scene's first frame to B, render A-B (default: the scene's range)");
    cmd->add_option(
        "--seed", a.seed,
        "override the scene's seed, 0 ... 2^63 - 1 (it places the crumpling model's singular "
        "vertices, draws [air]'s gusts and the soundtrack's variations and seeds the path "
        "tracer's samples)");
    cmd->add_option("--threads", a.threads, "worker threads; results are identical for any count")
        ->check(CLI::Range(1, 256));
    cmd->add_option("--shutter", a.shutter, kShutterShotHelp);
    cmd->add_option("--checkpoint-every", a.checkpointEvery,
                    "N: write the whole simulation state to DIR/checkpoint.bin every N frames "
                    "(atomically)")
        ->check(CLI::Range(1, 1 << 30));
    cmd->add_flag("--resume", a.resume,
                  "go on from DIR/checkpoint.bin after an interruption: the cache and the "
                  "summary end as an uninterrupted run's (the cache byte-identical); exit 2 when "
                  "the scene file, its animation file, paper preset or texture changed since");
    cmd->add_option("--debug", a.debug,
                    "developer traces and checks, comma-separated, to stderr: newton (every "
                    "Newton iteration), geometry[=1-3] (the crumpling model's geometric step), "
                    "tear (every tear candidate's test), invariants (S_G's invariants after "
                    "every geometric step), dump=FILE (the mesh of a failed step, OBJ); none "
                    "changes a result");
  }
  addRenderOptions(c.run, a);
  c.run->add_flag(
      "--debug-structure", a.debugStructure,
      "draw the crumpling model's structure: flat regions green, curved regions magenta "
      "with their rulings, singular vertices red, junction vertices yellow, handles black");
}

// `render`: frames of a cache.
void addRenderCommand(CLI::App& app, Args& a, Commands& c) {
  c.render = app.add_subcommand("render", "Render frames of a cache (frame-parallel farm work).");
  c.render->add_flag("--debug-structure", a.debugStructure,
                     "draw the crumpling model's structure (see `run --help`)");
  c.render->add_option("CACHE", a.cache, "a .pcache file")->required();
  c.render->add_option("--frames", a.frames, "A-B: frames to render (default: every cached frame)");
  addRenderOptions(c.render, a);
  c.render->add_option("--shutter", a.shutter, kShutterRenderHelp);
  c.render->add_option("--out", a.out,
                       "frames folder (default: frames/ beside the cache); locked while rendering "
                       "(exit 2 when another crumple writes there), shared by renders of a "
                       "--frames range (a farm's array tasks)");
  c.render
      ->add_option("--threads", a.threads,
                   "embree: worker threads (the images are identical for any count); osmesa: "
                   "the rasteriser sizes its own threads (LP_NUM_THREADS), identical images too")
      ->check(CLI::Range(1, 256));
}

// `sound`, `compare`, `inspect`, `export`: what else reads a cache.
void addCacheCommands(CLI::App& app, Args& a, Commands& c) {
  c.soundCmd = app.add_subcommand(
      "sound",
      "Make the soundtrack of a cache whose scene has [sound]: crumpling, friction and tearing "
      "sounds from the events the simulation stored, heard from the camera; a WAV lasting "
      "exactly frame_count / fps, and its spectrogram PNG beside it.");
  c.soundCmd->add_option("CACHE", a.cache, "a .pcache file")->required();
  c.soundCmd->add_option("--out", a.out,
                         "the WAV file, or a folder to write sound.wav into (default: sound.wav "
                         "beside the cache); its folder is locked while writing (exit 2 when "
                         "another crumple writes there)");
  c.soundCmd
      ->add_option("--rate", a.rate, "sample rate: 48000 or 44100 (default: the scene's, 48000)")
      ->check(CLI::IsMember({48000, 44100}));
  c.soundCmd->add_option(
      "--format", a.format,
      "pcm24 (24-bit PCM) or float (32-bit float) (default: the scene's, pcm24)");
  c.soundCmd
      ->add_option("--channels", a.channels, "1 (mono) or 2 (stereo) (default: the scene's, 2)")
      ->check(CLI::IsMember({1, 2}));
  c.soundCmd->add_option("--database", a.database,
                         "sound database folder (default: the scene's [sound] database, else "
                         "assets/sound/default)");
  c.soundCmd->add_option("--gain-db", a.gainDb,
                         "a fixed gain in dB, -200 ... 200 (default: the mix's peak normalised to "
                         "-1 dBFS)");
  c.soundCmd->add_flag("--no-spectrogram", a.noSpectrogram, "do not write the PNG");
  c.soundCmd->add_flag("--events", a.listEvents,
                       "print the cache's sound events, one line each, and make no sound");
  c.compare = app.add_subcommand(
      "compare",
      "Compare two images (PNG, or EXR as sRGB) for golden-image tests, writing a diff image; "
      "or two caches (.pcache) by their shapes: per shared frame, the mean and largest distance "
      "between the sheets' points at the same pattern position, whatever their meshes "
      "(docs/CRUMPLING.md). Exit 0 when within the tolerance, 1 when not, 2 on bad input.");
  c.compare->add_option("A", a.imageA, "reference image or cache")->required();
  c.compare->add_option("B", a.imageB, "image or cache under test")->required();
  c.compare->add_option("--shape-tolerance", a.shapeTolerance,
                        "caches: pass when every frame's mean distance is at most this (m)");
  c.compare->add_option("--frames", a.frames,
                        "caches: A-B, the frames to compare (default: all shared)");
  c.compare->add_flag("--json", a.json, "caches: one JSON object for scripts");
  c.compare
      ->add_option("--metric", a.metric,
                   "mae: mean |difference| over RGBA in 8-bit units; psnr: dB over RGBA; flip: "
                   "mean LDR-FLIP error in [0, 1] (Andersson et al. 2020) of the images over grey")
      ->capture_default_str();
  c.compare
      ->add_option("--tolerance", a.tolerance,
                   "pass when mae/flip <= tolerance, or psnr >= tolerance")
      ->capture_default_str();
  c.compare->add_option("--diff", a.diff, "diff image path (default: B's folder, <B>.diff.png)");
  c.inspect = app.add_subcommand(
      "inspect",
      "Print per-frame sizes, strain, sharpest fold, handle error and popping (the sheet's jump "
      "against its handles' motion, docs/CRUMPLING.md) of a cache.");
  c.inspect->add_option("CACHE", a.cache, "a .pcache file")->required();
  c.inspect->add_flag("--json", a.json,
                      "one JSON object for scripts; per frame also how far the sheet passes into "
                      "itself (self_depth in thicknesses, self_crossings) and the crumpling "
                      "model's structure changes (structure_changes)");
  c.exportCmd = app.add_subcommand(
      "export",
      "Export cached frames for DCC tools (docs/EXPORT.md): obj (NNNN.obj + .mtl, UVs = the "
      "pattern, torn frames cut by NNNN_tears.png), ply (binary NNNN.ply, UVs, region per face), "
      "gltf (NNNN.glb, and shot.glb with every frame as a node shown only on its frame) or usda "
      "(shot.usda, a time-varying Mesh). Needs only the cache.");
  c.exportCmd->add_option("CACHE", a.cache, "a .pcache file")->required();
  c.exportCmd->add_option("--format", a.exportFormat, "obj, ply, gltf or usda")->required();
  c.exportCmd->add_option(
      "--out", a.out,
      "output folder (default: export/<format>/ beside the cache); locked while "
      "writing (exit 2 when another crumple writes there), shared by exports "
      "of a --frames range");
  c.exportCmd->add_option(
      "--refine", a.refine,
      "the crumpling model's curved regions written finer along their rulings, isometric to "
      "the pattern: auto (folds of at most 1.8 degrees between sub-cells; default), off (the "
      "simulated mesh) or N sub-cells per face; docs/EXPORT.md");
  c.exportCmd->add_option("--frames", a.frames,
                          "A-B: frames to export (default: every cached frame)");
}

// `init`: a starter shot.
void addInitCommand(CLI::App& app, Args& a, Commands& c) {
  c.init = app.add_subcommand(
      "init",
      "Write a starter shot into DIR: scene.toml, commented key by key, and gather.gltf, four "
      "corner handles gathering a 20 cm sheet of office paper (crumpling model, camera, lights, "
      "ground, sound). Run it with `crumple run DIR`.");
  c.init->add_option("DIR", a.scene, "the folder to write (created when missing)")->required();
  c.init->add_flag("--force", a.force, "replace DIR's scene.toml and gather.gltf if there");
}

// `farm slurm` and `farm movie`.
void addFarmCommand(CLI::App& app, Args& a, Commands& c) {
  c.farm = app.add_subcommand("farm", "Run a shot on a render farm (docs/FARM.md).");
  c.farm->require_subcommand(1);
  c.farmSlurm = c.farm->add_subcommand(
      "slurm",
      "Write a shot's sbatch scripts into DIR/farm/ and submit them: a simulate job, a render "
      "job array over frame chunks after it (afterok), a finalize job (soundtrack, movie) after "
      "the whole array; prints the job ids.");
  c.farmSlurm->add_option("SCENE", a.scene, "scene.toml, or a folder holding one")->required();
  c.farmSlurm->add_option("--out", a.slurm.outDir,
                          "the shot folder (default: the scene's [output] dir, else "
                          "out/<scene name>)");
  c.farmSlurm->add_option("--chunk", a.slurm.chunk, "frames per render array task")
      ->capture_default_str();
  c.farmSlurm->add_option("--partition", a.slurm.partition, "sbatch --partition of every job");
  c.farmSlurm->add_option("--time", a.slurm.time, "sbatch --time of every job (e.g. 1:00:00)");
  c.farmSlurm
      ->add_option("--cpus-per-task", a.slurm.cpusPerTask,
                   "sbatch --cpus-per-task of every job, and its crumple --threads")
      ->check(CLI::PositiveNumber);
  c.farmSlurm->add_option("--mem", a.slurm.mem, "sbatch --mem of every job (e.g. 4G)");
  c.farmSlurm->add_option("--render-args", a.slurm.renderArgs,
                          "more `crumple render` arguments for every array task, as one word: "
                          "--render-args=\"--backend embree --spp 64\"");
  c.farmSlurm->add_option("--crumple", a.slurm.crumple,
                          "the crumple binary the jobs run (default: this one)");
  c.farmSlurm->add_flag("--no-movie{false}", a.slurm.movie,
                        "finalize makes no preview.mp4 (it makes it by default, with ffmpeg)");
  c.farmSlurm->add_flag("--dry-run", a.dryRun,
                        "print the scripts and the sbatch command lines; write and submit nothing");
  auto* farmMovie = c.farm->add_subcommand(
      "movie",
      "The finalize job's movie: preview.mp4 beside the cache from the frames already in "
      "frames/ (with sound.wav when there is one), through ffmpeg; renders nothing.");
  farmMovie->add_option("CACHE", a.cache, "a .pcache file")->required();
}

// `bench`: listed here for --help; its options are crumple-bench's.
void addBenchCommand(CLI::App& app, Args& /*a*/, Commands& c) {
  c.bench = app.add_subcommand(
      "bench",
      "Speed against error (docs/BENCH.md): every sample's cost per frame by stage beside its "
      "error measures, and each model's Pareto front. Runs crumple-bench (beside this binary): "
      "`crumple bench --help` lists what it measures and its options.");
  c.bench->allow_extras();
}

// `crumple bench ARGS`: crumple-bench ARGS, from the folder this binary is in.
int runBench(int argc, char** argv) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path bench =
      (ec ? std::filesystem::path(argv[0]) : self).parent_path() / "crumple-bench";
  std::vector<std::string> words{bench.string()};
  for (int i = 2; i < argc; ++i) words.emplace_back(argv[i]);
  std::vector<char*> args;
  for (auto& w : words) args.push_back(w.data());
  args.push_back(nullptr);
  ::execv(bench.c_str(), args.data());
  std::fprintf(stderr,
               "crumple: error: `crumple bench` runs %s, which is not there (build the "
               "crumple-bench target)\n",
               bench.c_str());
  return 2;
}

// The given command, run; exceptions become the exit status.
int dispatch(const Commands& c, const Args& a) {
  return runWithExitStatus("crumple", [&] {
    if (*c.run) return runOrSimulate(a, true);
    if (*c.simulate) return runOrSimulate(a, false);
    if (*c.render) return renderCommand(a);
    if (*c.inspect) return inspectCommand(a);
    if (*c.soundCmd) return soundCommand(a);
    if (*c.compare) return compareCommand(a);
    if (*c.exportCmd) return exportCommand(a);
    if (*c.farm) return farmCommand(a, *c.farmSlurm);
    if (*c.init) return initCommand(a);
    return 1;
  });
}

}  // namespace
}  // namespace crumple::cli

int main(int argc, char** argv) {
  using namespace crumple::cli;
  if (argc > 1 && std::string_view(argv[1]) == "bench") return runBench(argc, argv);
  CLI::App app{
      "crumple: paper animation -- simulate a sheet from keyframed handles, cache it, render it, "
      "make its sound.\n"
      "Exit status: 0 success, 1 internal failure, 2 bad input."};
  app.set_version_flag("--version", "crumple 0.1.0");
  app.require_subcommand(1);
  Args a;
  Commands c;
  addShotCommands(app, a, c);
  addRenderCommand(app, a, c);
  addCacheCommands(app, a, c);
  addFarmCommand(app, a, c);
  addBenchCommand(app, a, c);
  addInitCommand(app, a, c);

  // A first word that is neither an option nor a command is named, with the commands.
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::fprintf(stderr, "crumple: error: '%s' is not a command (one of: %s; see --help)\n",
                   argv[1], names.c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  return dispatch(c, a);
}
