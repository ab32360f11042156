// `crumple farm slurm` (docs/FARM.md): the sbatch scripts of a shot, their
// submission chained by job ids, and the finalize job's movie.
#include "crumple/pipeline/farm.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "frame_output.hpp"

extern char** environ;

namespace crumple::pipeline {
namespace fs = std::filesystem;

namespace {

// The largest --threads the CLI accepts.
constexpr int kMaxThreads = 256;

// Quotes a word for bash when it needs it ('...' with ' as '\'').
std::string shellQuote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
           std::string_view("_@%+=:,./-").find(c) != std::string_view::npos;
  });
  if (plain) return word;
  std::string out = "'";
  for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// A value on an #SBATCH line: one word, no line break.
std::string sbatchValue(const std::string& option, const std::string& value) {
  const bool bad = value.empty() || std::any_of(value.begin(), value.end(), [](char c) {
                     return std::isspace(static_cast<unsigned char>(c)) != 0 || c == '"' ||
                            c == '\'' || c == '#';
                   });
  if (bad) throw InputError(option, "'" + value + "' must be one word (no blanks, quotes or #)");
  return value;
}

// A path on an #SBATCH --output line: '%' is Slurm's pattern character
// ("%%" for a literal one); blanks need double quotes.
std::string sbatchPath(const std::string& path) {
  if (path.find_first_of("\"\n\r") != std::string::npos)
    throw InputError(path, "the shot folder's path must not hold double quotes or line breaks");
  std::string out;
  for (const char c : path) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out.find_first_of(" \t") == std::string::npos ? out : "\"" + out + "\"";
}

// Slurm job names: the scene's name with anything unusual replaced by '_'.
std::string jobNameOf(const std::string& scene) {
  std::string name = scene.empty() ? std::string("shot") : scene;
  for (char& c : name)
    if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '-' && c != '_' && c != '.')
      c = '_';
  return name;
}

std::string rangeText(const FrameRange& r) {
  return std::to_string(r.first) + "-" + std::to_string(r.last);
}

// This process's own binary, which the jobs run by default.
std::string selfExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("--crumple", "cannot find this binary (/proc/self/exe): give its path");
  return self.string();
}

// The first executable `name` on PATH, or empty.
std::string findOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate))
      return candidate.string();
  }
  return {};
}

struct ProcessResult {
  int status = -1;  // exit status, -1 when it could not run or was killed
  std::string out;  // its standard output (its standard error passes through)
};

// Runs argv (no shell) and captures its standard output.
ProcessResult runCapturing(const std::vector<std::string>& argv) {
  ProcessResult result;
  int fds[2];
  if (::pipe(fds) != 0) return result;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  if (spawned == 0) {
    char buf[4096];
    ssize_t n = 0;
    while ((n = ::read(fds[0], buf, sizeof buf)) > 0)
      result.out.append(buf, static_cast<size_t>(n));
  }
  ::close(fds[0]);
  if (spawned != 0) return result;
  int status = 0;
  if (::waitpid(pid, &status, 0) >= 0 && WIFEXITED(status)) result.status = WEXITSTATUS(status);
  return result;
}

// The #SBATCH lines every job shares, after its name and log file.
std::string sbatchHeader(const std::string& name, const std::string& log, const SlurmOptions& o) {
  std::string h = "#SBATCH --job-name=" + name + "\n#SBATCH --output=" + log + "\n";
  if (!o.partition.empty())
    h += "#SBATCH --partition=" + sbatchValue("--partition", o.partition) + "\n";
  if (!o.time.empty()) h += "#SBATCH --time=" + sbatchValue("--time", o.time) + "\n";
  if (o.cpusPerTask > 0) h += "#SBATCH --cpus-per-task=" + std::to_string(o.cpusPerTask) + "\n";
  if (!o.mem.empty()) h += "#SBATCH --mem=" + sbatchValue("--mem", o.mem) + "\n";
  return h;
}

bool hasOption(const std::vector<std::string>& words, const std::string& option) {
  return std::any_of(words.begin(), words.end(), [&](const std::string& w) {
    return w == option || w.rfind(option + "=", 0) == 0;
  });
}

// The sbatch argv of one script, after the job `after` (empty: none).
std::vector<std::string> sbatchArgv(const std::string& sbatch, const std::string& script,
                                    const std::string& after) {
  std::vector<std::string> argv = {sbatch, "--parsable"};
  if (!after.empty()) argv.push_back("--dependency=afterok:" + after);
  argv.push_back(script);
  return argv;
}

}  // namespace

std::vector<FrameRange> frameChunks(const FrameRange& range, int chunk) {
  if (chunk < 1)
    throw InputError("--chunk", std::to_string(chunk) + ": a chunk holds at least one frame");
  std::vector<FrameRange> chunks;
  for (long first = range.first; first <= range.last; first += chunk)
    chunks.push_back(
        {static_cast<int>(first), static_cast<int>(std::min<long>(first + chunk - 1, range.last))});
  return chunks;
}

std::vector<std::string> splitArguments(const std::string& text) {
  std::vector<std::string> words;
  std::string word;
  bool inWord = false;
  char quote = 0;
  for (const char c : text) {
    if (quote != 0) {
      if (c == quote)
        quote = 0;
      else
        word += c;
    } else if (c == '\'' || c == '"') {
      quote = c;
      inWord = true;
    } else if (std::isspace(static_cast<unsigned char>(c)) != 0) {
      if (inWord) words.push_back(word);
      word.clear();
      inWord = false;
    } else {
      word += c;
      inWord = true;
    }
  }
  if (quote != 0) throw InputError("--render-args", "unclosed quote in '" + text + "'");
  if (inWord) words.push_back(word);
  return words;
}

SlurmScripts slurmScripts(const io::SceneSpec& scene, const SlurmOptions& o) {
  SlurmScripts s;
  s.jobName = jobNameOf(scene.name);
  const std::string outDir = !o.outDir.empty()           ? o.outDir
                             : !scene.output.dir.empty() ? scene.output.dir
                                                         : (fs::path("out") / scene.name).string();
  s.outDir = fs::absolute(outDir).lexically_normal().string();
  if (s.outDir.size() > 1 && s.outDir.back() == '/') s.outDir.pop_back();
  s.farmDir = (fs::path(s.outDir) / "farm").string();
  s.logsDir = (fs::path(s.farmDir) / "logs").string();
  s.cachePath = (fs::path(s.outDir) / "cache.pcache").string();
  s.frames = {scene.frameStart, scene.frameEnd};
  s.chunks = frameChunks(s.frames, o.chunk);
  s.sound = scene.soundEnabled;
  if (!scene.output.frames)
    throw InputError(scene.file,
                     "[output] frames = false: the farm has no frames to render (crumple "
                     "simulate makes the cache alone)");

  const std::vector<std::string> renderArgs = splitArguments(o.renderArgs);
  for (const char* own : {"--frames", "--out", "--movie", "--contact-sheet"})
    if (hasOption(renderArgs, own))
      throw InputError("--render-args", std::string(own) +
                                            " is the farm's to set (each array task renders its "
                                            "chunk into DIR/frames; finalize makes the movie)");
  if (o.movie && hasOption(renderArgs, "--no-png"))
    throw InputError("--render-args", "--no-png leaves the movie no frames (add --no-movie)");

  const std::string binary =
      fs::absolute(o.crumple.empty() ? selfExecutable() : o.crumple).lexically_normal().string();
  if (::access(binary.c_str(), X_OK) != 0 || fs::is_directory(binary))
    throw InputError("--crumple", binary + " is not an executable file");
  const std::string crumple = shellQuote(binary);
  const std::string sceneFile = shellQuote(fs::absolute(scene.file).lexically_normal().string());
  const std::string cache = shellQuote(s.cachePath);
  const std::string threads =
      o.cpusPerTask > 0 ? " --threads " + std::to_string(std::min(o.cpusPerTask, kMaxThreads)) : "";
  const std::string singleLog = sbatchPath(s.logsDir + "/") + "%x-%j.out";
  const std::string preamble = "#!/bin/bash\n# Written by `crumple farm slurm` for the shot " +
                               s.jobName + " (docs/FARM.md).\n";
  const std::string strict = "set -euo pipefail\n";

  s.simulate = preamble +
               "# Job 1 of 3: simulate the shot into its cache (and its sound events).\n" +
               sbatchHeader(s.jobName + "-simulate", singleLog, o) + strict + crumple +
               " simulate " + sceneFile + " --out " + shellQuote(s.outDir) + threads + "\n";

  const int tasks = static_cast<int>(s.chunks.size());
  s.render = preamble + "# Job 2 of 3, after the simulate job: render frames " +
             rangeText(s.frames) + " from the cache, " + std::to_string(tasks) +
             " array task(s) of up to " + std::to_string(o.chunk) + " frames each.\n" +
             sbatchHeader(s.jobName + "-render", sbatchPath(s.logsDir + "/") + "%x-%A_%a.out", o) +
             "#SBATCH --array=0-" + std::to_string(tasks - 1) +
             "\n#SBATCH --kill-on-invalid-dep=yes\n" + strict +
             "case \"${SLURM_ARRAY_TASK_ID:?not a Slurm array task}\" in\n";
  for (int i = 0; i < tasks; ++i)
    s.render.append("  ")
        .append(std::to_string(i))
        .append(") frames=")
        .append(rangeText(s.chunks[static_cast<std::size_t>(i)]))
        .append(" ;;\n");
  s.render += "  *) echo \"crumple farm: array task ${SLURM_ARRAY_TASK_ID} has no frames (0-" +
              std::to_string(tasks - 1) + ")\" >&2; exit 2 ;;\nesac\n";
  std::string extra;
  for (const auto& w : renderArgs) extra.append(" ").append(shellQuote(w));
  s.render += crumple + " render " + cache + " --frames=\"$frames\"" +
              (hasOption(renderArgs, "--threads") ? "" : threads) + extra + "\n";

  s.finalize =
      preamble +
      "# Job 3 of 3, after every render task: " + std::string(s.sound ? "the soundtrack, " : "") +
      (o.movie ? "the movie from the rendered frames" : "nothing but this note") + ".\n" +
      sbatchHeader(s.jobName + "-finalize", singleLog, o) + "#SBATCH --kill-on-invalid-dep=yes\n" +
      strict;
  if (s.sound) s.finalize += crumple + " sound " + cache + "\n";
  if (o.movie) s.finalize += crumple + " farm movie " + cache + "\n";
  s.finalize += "echo " +
                shellQuote("crumple farm: " + s.jobName + " done, frames " + rangeText(s.frames) +
                           " in " + s.outDir + "/frames") +
                "\n";
  return s;
}

std::string sbatchCommands(const SlurmScripts& s) {
  const auto line = [](const std::string& var, const std::string& script,
                       const std::string& after) {
    std::string text = var + "=$(";
    const auto argv = sbatchArgv("sbatch", script, after.empty() ? "" : "${" + after + "%%;*}");
    for (std::size_t i = 0; i < argv.size(); ++i)
      text += (i > 0 ? " " : "") + (i + 1 == argv.size() ? shellQuote(argv[i]) : argv[i]);
    return text + ")\n";
  };
  const fs::path dir(s.farmDir);
  return line("simulate", (dir / "simulate.sbatch").string(), "") +
         line("render", (dir / "render.sbatch").string(), "simulate") +
         line("finalize", (dir / "finalize.sbatch").string(), "render") +
         "echo \"simulate ${simulate%%;*} render ${render%%;*} finalize ${finalize%%;*}\"\n";
}

SlurmJobs submitSlurm(const SlurmScripts& s) {
  const std::string sbatch = findOnPath("sbatch");
  if (sbatch.empty())
    throw InputError("sbatch",
                     "not found on PATH: this machine cannot submit to Slurm (Debian: apt-get "
                     "install slurm-client); --dry-run prints the scripts without submitting");
  std::error_code ec;
  fs::create_directories(s.logsDir, ec);
  if (ec) throw InputError(s.logsDir, "cannot create the farm folder: " + ec.message());
  const std::pair<const char*, const std::string*> files[] = {{"simulate.sbatch", &s.simulate},
                                                              {"render.sbatch", &s.render},
                                                              {"finalize.sbatch", &s.finalize}};
  for (const auto& [name, text] : files) {
    const fs::path path = fs::path(s.farmDir) / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << *text;
    out.close();
    if (!out) throw InputError(path.string(), "cannot write the script");
    fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                    fs::perm_options::add, ec);
  }

  std::vector<std::string> submitted;
  const auto submit = [&](const char* name, const std::string& after) {
    const std::string script = (fs::path(s.farmDir) / name).string();
    const ProcessResult r = runCapturing(sbatchArgv(sbatch, script, after));
    // --parsable prints "<id>" or "<id>;<cluster>".
    std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
    const bool numeric = !id.empty() && std::all_of(id.begin(), id.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c)) != 0;
    });
    if (r.status == 0 && numeric) {
      submitted.push_back(id);
      return id;
    }
    std::string cancelled;
    if (!submitted.empty()) {
      std::vector<std::string> argv = {findOnPath("scancel")};
      if (!argv[0].empty()) {
        argv.insert(argv.end(), submitted.begin(), submitted.end());
        const bool ok = runCapturing(argv).status == 0;
        for (const auto& j : submitted) cancelled += " " + j;
        cancelled =
            (ok ? "; cancelled the job(s) submitted before:" : "; scancel failed for:") + cancelled;
      } else {
        for (const auto& j : submitted) cancelled += " " + j;
        cancelled = "; scancel is not on PATH, cancel these yourself:" + cancelled;
      }
    }
    throw InputError(script, "sbatch refused it (exit status " + std::to_string(r.status) +
                                 (r.status == 0 ? ", output '" + r.out + "'" : "") + ")" +
                                 cancelled);
  };
  SlurmJobs jobs;
  jobs.simulate = submit("simulate.sbatch", "");
  jobs.render = submit("render.sbatch", jobs.simulate);
  jobs.finalize = submit("finalize.sbatch", jobs.render);
  return jobs;
}

std::string makeShotMovie(const std::string& cachePath, std::string& note) {
  const cache::CacheReader reader(cachePath);
  if (reader.frameCount() == 0) throw InputError(cachePath, "the cache holds no frames");
  const int first = reader.readFrame(0).frame;
  const int last = first + static_cast<int>(reader.frameCount()) - 1;
  const fs::path dir = fs::path(cachePath).parent_path();
  const fs::path framesDir = dir / "frames";
  std::vector<int> missing;
  for (int f = first; f <= last; ++f)
    if (!fs::is_regular_file(framesDir / detail::frameFileName(f))) missing.push_back(f);
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < std::min<std::size_t>(missing.size(), 10); ++i)
      list += (i > 0 ? ", " : "") + std::to_string(missing[i]);
    if (missing.size() > 10) list += ", ...";
    throw InputError(framesDir.string(), std::to_string(missing.size()) + " of the frames " +
                                             std::to_string(first) + "-" + std::to_string(last) +
                                             " are not rendered: " + list);
  }
  if (findOnPath("ffmpeg").empty())
    throw InputError("ffmpeg", "not found on PATH: no movie (Debian: apt-get install ffmpeg)");
  const std::string movie = (dir / "preview.mp4").string();
  if (!detail::makeMovie(framesDir.string(), first, last, reader.header().fps,
                         (dir / "sound.wav").string(), movie, note))
    throw std::runtime_error(note);
  return movie;
}

}  // namespace crumple::pipeline
