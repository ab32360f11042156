// `crumple farm slurm` (docs/FARM.md): the sbatch scripts' text, the chain of
// job ids through a stand-in sbatch, the scripts run by bash as Slurm would
// run them, and bad input. Nothing here needs Slurm (scripts/slurm-test.sh
// runs a real one).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <regex>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/farm.hpp"
#include "test_util.hpp"

using namespace crumple::testing;
namespace pipeline = crumple::pipeline;

namespace {

// The frame chunks a render script's case table gives its array tasks, in
// task order (checks the task numbers count up from 0).
std::vector<pipeline::FrameRange> caseTable(const std::string& script) {
  std::vector<pipeline::FrameRange> chunks;
  const std::regex line(R"(\n  (\d+)\) frames=(-?\d+)-(-?\d+) ;;)");
  for (std::sregex_iterator it(script.begin(), script.end(), line), end; it != end; ++it) {
    EXPECT_EQ(std::stoi((*it)[1]), static_cast<int>(chunks.size()));
    chunks.push_back({std::stoi((*it)[2]), std::stoi((*it)[3])});
  }
  return chunks;
}

// Every line of `script` that is a command: not blank, not a comment.
std::vector<std::string> commands(const std::string& script) {
  std::vector<std::string> out;
  std::istringstream in(script);
  for (std::string l; std::getline(in, l);)
    if (!l.empty() && l[0] != '#') out.push_back(l);
  return out;
}

// The #SBATCH lines all come before the first command (sbatch stops reading
// them there).
void expectSbatchLinesFirst(const std::string& script) {
  EXPECT_EQ(script.rfind("#!/bin/bash\n", 0), 0u) << script;
  const auto firstCommand = script.find("\nset -euo pipefail\n");
  ASSERT_NE(firstCommand, std::string::npos) << script;
  EXPECT_EQ(commands(script).front(), "set -euo pipefail");
  EXPECT_LT(script.rfind("#SBATCH"), firstCommand) << script;
}

crumple::io::SceneSpec sampleScene(const std::string& name) {
  return crumple::io::loadScene(sourcePath("samples/" + name + "/scene.toml"));
}

pipeline::SlurmOptions drapeOptions(const fs::path& out) {
  pipeline::SlurmOptions o;
  o.outDir = out.string();
  o.chunk = 12;
  o.partition = "debug";
  o.time = "0:30:00";
  o.cpusPerTask = 2;
  o.mem = "2G";
  o.renderArgs = "--backend embree --spp '8'";
  o.crumple = CRUMPLE_BIN;
  return o;
}

// A folder with stand-ins for sbatch and scancel: sbatch appends its
// arguments to sbatch.log and prints ids 101, 102, ... (as "<id>;cluster"
// once, as --parsable does on a federation), and fails on call `failOn`.
fs::path fakeSlurm(const TempDir& tmp, int failOn = 0) {
  const fs::path bin = tmp / "fakebin";
  fs::create_directories(bin);
  const std::string log = (tmp / "sbatch.log").string();
  const std::string counter = (tmp / "sbatch.count").string();
  writeFile(
      bin / "sbatch",
      "#!/bin/sh\nn=$(cat '" + counter + "' 2>/dev/null || echo 0)\nn=$((n + 1))\necho $n > '" +
          counter + "'\necho \"$*\" >> '" + log + "'\nif [ $n -eq " + std::to_string(failOn) +
          " ]; then echo 'sbatch: error: invalid partition' >&2; exit 1; fi\n"
          "if [ $n -eq 2 ]; then echo \"$((100 + n));cluster\"; else echo $((100 + n)); fi\n");
  writeFile(bin / "scancel",
            "#!/bin/sh\necho \"$*\" >> '" + (tmp / "scancel.log").string() + "'\n");
  for (const char* name : {"sbatch", "scancel"}) ::chmod((bin / name).c_str(), 0755);
  return bin;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

}  // namespace

TEST(FarmSlurm, ChunksCoverTheRangeExactly) {
  for (const auto& [range, chunk] :
       std::vector<std::pair<pipeline::FrameRange, int>>{{{0, 72}, 12},
                                                         {{1, 6}, 3},
                                                         {{1, 6}, 100},
                                                         {{-5, 4}, 1},
                                                         {{10, 10}, 10},
                                                         {{0, 72}, 10}}) {
    const auto chunks = pipeline::frameChunks(range, chunk);
    ASSERT_FALSE(chunks.empty());
    EXPECT_EQ(chunks.front().first, range.first);
    EXPECT_EQ(chunks.back().last, range.last);
    const int count = range.last - range.first + 1;
    EXPECT_EQ(static_cast<int>(chunks.size()), (count + chunk - 1) / chunk);
    for (std::size_t i = 0; i < chunks.size(); ++i) {
      const int size = chunks[i].last - chunks[i].first + 1;
      if (i + 1 < chunks.size()) {
        EXPECT_EQ(size, chunk);
        EXPECT_EQ(chunks[i + 1].first, chunks[i].last + 1) << "no gap, no overlap";
      } else {
        EXPECT_GE(size, 1);
        EXPECT_LE(size, chunk);
      }
    }
  }
  const auto drape = pipeline::frameChunks({0, 72}, 12);
  ASSERT_EQ(drape.size(), 7u);
  EXPECT_EQ(drape.back().first, 72) << "the last chunk is shorter: frame 72 alone";
  EXPECT_THROW(pipeline::frameChunks({0, 72}, 0), crumple::InputError);
  EXPECT_THROW(pipeline::frameChunks({0, 72}, -3), crumple::InputError);
}

TEST(FarmSlurm, TheDrapeSamplesScripts) {
  TempDir tmp;
  const auto scene = sampleScene("drape");
  const auto s = pipeline::slurmScripts(scene, drapeOptions(tmp / "shot"));
  const std::string out = (tmp / "shot").string();
  const std::string bin = CRUMPLE_BIN;
  EXPECT_EQ(s.outDir, out);
  EXPECT_EQ(s.farmDir, out + "/farm");
  EXPECT_EQ(s.cachePath, out + "/cache.pcache");
  EXPECT_FALSE(s.sound) << "drape has no [sound]";
  for (const auto* script : {&s.simulate, &s.render, &s.finalize}) {
    expectSbatchLinesFirst(*script);
    for (const char* line : {"#SBATCH --partition=debug\n", "#SBATCH --time=0:30:00\n",
                             "#SBATCH --cpus-per-task=2\n", "#SBATCH --mem=2G\n"})
      EXPECT_NE(script->find(line), std::string::npos) << line << " in\n" << *script;
  }

  // Simulate: one job, its log named by job name and id.
  EXPECT_NE(s.simulate.find("#SBATCH --job-name=drape-simulate\n"), std::string::npos);
  EXPECT_NE(s.simulate.find("#SBATCH --output=" + out + "/farm/logs/%x-%j.out\n"),
            std::string::npos);
  EXPECT_EQ(commands(s.simulate).back(), bin + " simulate " +
                                             sourcePath("samples/drape/scene.toml") + " --out " +
                                             out + " --threads 2");

  // Render: an array of 7 tasks over frames 0-72, 12 frames each, the last one alone.
  EXPECT_NE(s.render.find("#SBATCH --job-name=drape-render\n"), std::string::npos);
  EXPECT_NE(s.render.find("#SBATCH --output=" + out + "/farm/logs/%x-%A_%a.out\n"),
            std::string::npos);
  EXPECT_NE(s.render.find("#SBATCH --array=0-6\n"), std::string::npos) << s.render;
  EXPECT_NE(s.render.find("#SBATCH --kill-on-invalid-dep=yes\n"), std::string::npos);
  const auto table = caseTable(s.render);
  ASSERT_EQ(table.size(), s.chunks.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(table[i].first, s.chunks[i].first);
    EXPECT_EQ(table[i].last, s.chunks[i].last);
  }
  EXPECT_EQ(table.front().first, 0);
  EXPECT_EQ(table.front().last, 11);
  EXPECT_EQ(table.back().first, 72);
  EXPECT_EQ(table.back().last, 72);
  EXPECT_EQ(commands(s.render).back(), bin + " render " + out +
                                           "/cache.pcache --frames=\"$frames\" --threads 2 "
                                           "--backend embree --spp 8");

  // Finalize: after the array; no sound for drape, the movie from the frames.
  EXPECT_NE(s.finalize.find("#SBATCH --job-name=drape-finalize\n"), std::string::npos);
  EXPECT_NE(s.finalize.find("#SBATCH --kill-on-invalid-dep=yes\n"), std::string::npos);
  const auto fin = commands(s.finalize);
  ASSERT_EQ(fin.size(), 3u) << s.finalize;
  EXPECT_EQ(fin[1], bin + " farm movie " + out + "/cache.pcache");
  EXPECT_EQ(fin[2].rfind("echo ", 0), 0u);
  EXPECT_EQ(s.finalize.find(" sound "), std::string::npos);
}

TEST(FarmSlurm, FinalizeMakesTheSoundtrackOfASceneWithSound) {
  TempDir tmp;
  pipeline::SlurmOptions o;
  o.outDir = (tmp / "w").string();
  o.crumple = CRUMPLE_BIN;
  const auto s = pipeline::slurmScripts(sampleScene("wiggle"), o);
  EXPECT_TRUE(s.sound);
  const std::string cache = (tmp / "w/cache.pcache").string();
  const auto fin = commands(s.finalize);
  ASSERT_EQ(fin.size(), 4u) << s.finalize;
  EXPECT_EQ(fin[1], std::string(CRUMPLE_BIN) + " sound " + cache);
  EXPECT_EQ(fin[2], std::string(CRUMPLE_BIN) + " farm movie " + cache)
      << "the movie after the soundtrack, so it is muxed in";
  // Defaults: 10 frames a chunk over 0-90, no resources asked, no --threads.
  EXPECT_EQ(s.chunks.size(), 10u);
  EXPECT_EQ(s.chunks.back().first, 90);
  EXPECT_EQ(s.render.find("--cpus-per-task"), std::string::npos);
  EXPECT_EQ(s.render.find("--threads"), std::string::npos);
  EXPECT_EQ(s.simulate.find("--partition"), std::string::npos);

  o.movie = false;
  const auto silent = pipeline::slurmScripts(sampleScene("wiggle"), o);
  EXPECT_EQ(silent.finalize.find("farm movie"), std::string::npos);
  EXPECT_NE(silent.finalize.find(" sound "), std::string::npos);
}

TEST(FarmSlurm, TheSubmissionChainsEachJobAfterTheOneBefore) {
  TempDir tmp;
  pipeline::SlurmOptions o;
  o.outDir = (tmp / "shot").string();
  o.crumple = CRUMPLE_BIN;
  const auto s = pipeline::slurmScripts(sampleScene("drape"), o);
  const auto l = lines(pipeline::sbatchCommands(s));
  ASSERT_EQ(l.size(), 4u);
  EXPECT_EQ(l[0], "simulate=$(sbatch --parsable " + s.farmDir + "/simulate.sbatch)");
  EXPECT_EQ(l[1], "render=$(sbatch --parsable --dependency=afterok:${simulate%%;*} " + s.farmDir +
                      "/render.sbatch)");
  EXPECT_EQ(l[2], "finalize=$(sbatch --parsable --dependency=afterok:${render%%;*} " + s.farmDir +
                      "/finalize.sbatch)");
  // The snippet runs as printed: through bash with a stand-in sbatch.
  const fs::path bin = fakeSlurm(tmp);
  const auto r =
      runCommand("PATH=" + bin.string() + ":$PATH bash -c '" + pipeline::sbatchCommands(s) + "'");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("simulate 101 render 102 finalize 103"), std::string::npos) << r.output;
  const auto calls = lines(readFile(tmp / "sbatch.log"));
  ASSERT_EQ(calls.size(), 3u);
  EXPECT_NE(calls[2].find("--dependency=afterok:102 "), std::string::npos) << calls[2];
}

TEST(FarmSlurm, BadInputIsAClearError) {
  TempDir tmp;
  const auto drape = sampleScene("drape");
  const auto fails = [&](pipeline::SlurmOptions o, const std::string& says) {
    if (o.crumple.empty()) o.crumple = CRUMPLE_BIN;
    o.outDir = (tmp / "x").string();
    try {
      (void)pipeline::slurmScripts(drape, o);
      ADD_FAILURE() << "accepted; expected an error saying " << says;
    } catch (const crumple::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  pipeline::SlurmOptions o;
  o.chunk = 0;
  fails(o, "--chunk");
  for (const char* own : {"--frames 1-4", "--out=/tmp/y", "--movie", "--contact-sheet"}) {
    o = {};
    o.renderArgs = std::string("--backend osmesa ") + own;
    fails(o, "the farm's to set");
  }
  o = {};
  o.renderArgs = "--exr --no-png";
  fails(o, "--no-movie");
  o.movie = false;
  EXPECT_NO_THROW({
    o.crumple = CRUMPLE_BIN;
    (void)pipeline::slurmScripts(drape, o);
  });
  o = {};
  o.renderArgs = "--backend 'embree";
  fails(o, "unclosed quote");
  o = {};
  o.partition = "debug gpu";
  fails(o, "--partition");
  o = {};
  o.mem = "4G\n#SBATCH --exclusive";
  fails(o, "--mem");
  o = {};
  o.crumple = (tmp / "no-such-binary").string();
  fails(o, "not an executable");
  auto noFrames = drape;
  noFrames.output.frames = false;
  o = {};
  o.crumple = CRUMPLE_BIN;
  EXPECT_THROW((void)pipeline::slurmScripts(noFrames, o), crumple::InputError);
  EXPECT_EQ(pipeline::splitArguments(" --backend  \"a b\" ''  c'd'e "),
            (std::vector<std::string>{"--backend", "a b", "", "cde"}));
}

TEST(FarmCli, DryRunPrintsTheScriptsAndSubmitsNothing) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const fs::path bin = fakeSlurm(tmp);
  const std::string out = (tmp / "shot").string();
  const auto r = runCommand("PATH=" + bin.string() + ":$PATH " + CRUMPLE_BIN + " farm slurm " +
                            (tmp / "scene").string() + " --chunk 4 --out " + out + " --dry-run");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* name : {"simulate", "render", "finalize"})
    EXPECT_NE(r.output.find("# ---- " + out + "/farm/" + name + ".sbatch\n#!/bin/bash\n"),
              std::string::npos)
        << name << "\n"
        << r.output;
  EXPECT_NE(r.output.find("#SBATCH --array=0-1\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  0) frames=1-4 ;;\n  1) frames=5-6 ;;\n  *)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("render=$(sbatch --parsable --dependency=afterok:${simulate%%;*} "),
            std::string::npos);
  EXPECT_NE(r.output.find("dry run: nothing written, nothing submitted"), std::string::npos);
  EXPECT_FALSE(fs::exists(tmp / "sbatch.log")) << "sbatch was called";
  EXPECT_FALSE(fs::exists(out)) << "a dry run writes nothing";
}

TEST(FarmCli, SubmitsTheChainAndPrintsTheJobIds) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const fs::path bin = fakeSlurm(tmp);
  const std::string out = (tmp / "shot").string();
  const auto r = runCommand("PATH=" + bin.string() + ":$PATH " + CRUMPLE_BIN + " farm slurm " +
                            (tmp / "scene").string() + " --chunk 4 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("simulate job 101\nrender job 102 (array 0-1: frames 1-6 in chunks of "
                          "4)\nfinalize job 103\n"),
            std::string::npos)
      << r.output;
  const auto calls = lines(readFile(tmp / "sbatch.log"));
  ASSERT_EQ(calls.size(), 3u);
  EXPECT_EQ(calls[0], "--parsable " + out + "/farm/simulate.sbatch");
  EXPECT_EQ(calls[1], "--parsable --dependency=afterok:101 " + out + "/farm/render.sbatch");
  EXPECT_EQ(calls[2], "--parsable --dependency=afterok:102 " + out + "/farm/finalize.sbatch")
      << "the id without its ';cluster'";
  for (const char* name : {"simulate", "render", "finalize"}) {
    const fs::path script = fs::path(out) / "farm" / (std::string(name) + ".sbatch");
    ASSERT_TRUE(fs::exists(script)) << script;
    EXPECT_NE(readFile(script).find("#SBATCH --job-name=small-" + std::string(name)),
              std::string::npos);
    EXPECT_NE(fs::status(script).permissions() & fs::perms::owner_exec, fs::perms::none);
  }
  EXPECT_TRUE(fs::is_directory(fs::path(out) / "farm/logs")) << "Slurm does not create it";
  EXPECT_FALSE(fs::exists(tmp / "scancel.log"));
}

TEST(FarmCli, ARefusedJobCancelsTheJobsBeforeIt) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const fs::path bin = fakeSlurm(tmp, /*failOn=*/2);
  const auto r = runCommand("PATH=" + bin.string() + ":$PATH " + CRUMPLE_BIN + " farm slurm " +
                            (tmp / "scene").string() + " --out " + (tmp / "shot").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("render.sbatch: sbatch refused it (exit status 1)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("sbatch: error: invalid partition"), std::string::npos)
      << "sbatch's own message passes through";
  EXPECT_NE(r.output.find("cancelled the job(s) submitted before: 101"), std::string::npos)
      << r.output;
  EXPECT_EQ(readFile(tmp / "scancel.log"), "101\n");
  EXPECT_EQ(lines(readFile(tmp / "sbatch.log")).size(), 2u) << "finalize was not submitted";
}

TEST(FarmCli, BadInputExitsTwo) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const std::string scene = (tmp / "scene").string();
  fs::create_directories(tmp / "empty");
  // No sbatch on PATH (Slurm is installed on some test machines: hide it).
  auto r = runCommand("PATH=" + (tmp / "empty").string() + " " + CRUMPLE_BIN + " farm slurm " +
                      scene + " --out " + (tmp / "a").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("sbatch: not found on PATH"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--dry-run"), std::string::npos) << "says how to go without";
  r = runCrumple("farm slurm " + scene + " --chunk 0 --dry-run");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--chunk"), std::string::npos) << r.output;
  r = runCrumple("farm slurm " + scene + " --render-args=--movie --dry-run");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(runCrumple("farm slurm " + scene + " --cpus-per-task 0 --dry-run").status, 2);
  EXPECT_EQ(runCrumple("farm slurm " + (tmp / "nothing").string() + " --dry-run").status, 2);
  EXPECT_EQ(runCrumple("farm").status, 2) << "slurm or movie";
  r = runCrumple("farm slurm --help");
  EXPECT_EQ(r.status, 0);
  for (const char* option : {"--chunk", "--dry-run", "--render-args", "--crumple", "--no-movie"})
    EXPECT_NE(r.output.find(option), std::string::npos) << option;
  EXPECT_EQ(runCrumple("farm movie " + (tmp / "none.pcache").string()).status, 2);
  // --no-movie leaves the movie out; --render-args in one word with blanks.
  r = runCrumple("farm slurm " + scene +
                 " --no-movie --dry-run --render-args=\"--backend embree\"");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("farm movie"), std::string::npos);
  EXPECT_NE(r.output.find("--frames=\"$frames\" --backend embree\n"), std::string::npos)
      << r.output;
}

// The scripts as Slurm runs them (bash, SLURM_ARRAY_TASK_ID set per task):
// the cache, every frame, the summary and the movie, with nothing but the
// scripts' own commands.
TEST(FarmCli, TheScriptsRunUnderBashMakeEveryOutput) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const fs::path bin = fakeSlurm(tmp);
  const fs::path out = tmp / "shot";
  ASSERT_EQ(runCommand("PATH=" + bin.string() + ":$PATH " + CRUMPLE_BIN + " farm slurm " +
                       (tmp / "scene").string() + " --chunk 4 --out " + out.string())
                .status,
            0);
  const auto job = [&](const std::string& script, const std::string& env = "") {
    return runCommand(env + " bash " + (out / "farm" / script).string());
  };
  auto r = job("simulate.sbatch");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "cache.pcache"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_NE(r.output.find("PROGRESS 100"), std::string::npos) << "progress lines for the farm";
  for (int task = 1; task >= 0; --task) {
    r = job("render.sbatch", "SLURM_ARRAY_TASK_ID=" + std::to_string(task));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(task == 0 ? "4 frames rendered" : "2 frames rendered"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("PROGRESS 100"), std::string::npos) << r.output;
  }
  for (int f = 1; f <= 6; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.png", f);
    EXPECT_TRUE(fs::exists(out / "frames" / name)) << name;
  }
  EXPECT_EQ(job("render.sbatch", "SLURM_ARRAY_TASK_ID=2").status, 2) << "no third chunk";
  EXPECT_NE(job("render.sbatch", "env -u SLURM_ARRAY_TASK_ID").status, 0);

  const bool haveFfmpeg = runCommand("command -v ffmpeg").status == 0;
  r = job("finalize.sbatch");
  if (!haveFfmpeg) {
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("ffmpeg: not found"), std::string::npos) << r.output;
    return;
  }
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GT(fs::file_size(out / "preview.mp4"), 1000u);
  EXPECT_NE(r.output.find("silent"), std::string::npos) << "no [sound]: " << r.output;
  EXPECT_NE(r.output.find("done, frames 1-6"), std::string::npos) << r.output;
  const auto probe =
      runCommand("ffprobe -v error -count_frames -show_entries stream=nb_read_frames -of csv=p=0 " +
                 (out / "preview.mp4").string());
  EXPECT_EQ(probe.output, "6\n") << "one movie frame per shot frame";

  // A frame missing: the movie names it and is not made.
  fs::remove(out / "preview.mp4");
  fs::remove(out / "frames/0005.png");
  r = runCrumple("farm movie " + (out / "cache.pcache").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("1 of the frames 1-6 are not rendered: 5"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out / "preview.mp4"));
}
