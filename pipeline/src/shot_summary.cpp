// The shot's end: the soundtrack and the frames' extras for `run`, the
// warnings the frames add up to, and summary.json (with its text form).
#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "crumple/pipeline/sound.hpp"
#include "crumple/tear/candidates.hpp"
#include "json_writer.hpp"
#include "shot_detail.hpp"
#include "shot_runner.hpp"

namespace crumple::pipeline {

namespace {

// Above this mean edge-length error (c_mean) a crumpling-model shot warns:
// the model's target is 0.5 % (paper Table IV reaches 0.17-1.47 %).
constexpr double kLengthErrorWarning = 0.01;

}  // namespace

void ShotRunner::finish() {
  progress_->finish();
  writer_->close();
  if (tearStage_) {
    report_.tearSegments = tearStage_->tearing().segments();
    report_.tearStartKinds = tearStage_->tearing().startKinds();
  }
  if (soundEvents_) report_.soundResonatorMs = soundEvents_->resonatorMs();
  if (plan_.render && soundEvents_) {
    // `run`: the soundtrack too, before the movie that muxes it in.
    SoundOptions soundOptions;
    soundOptions.log = plan_.log;
    soundOptions.interactive = plan_.interactive;
    soundOptions.lockFolder = false;  // sound.wav goes beside the cache: the shot's locked folder
    const SoundReport made = makeSound(report_.cachePath, soundOptions);
    report_.soundPath = made.wavPath;
    report_.stages["sound"].totalMs += made.synthesisMs;
    report_.stages["sound"].frames += made.frames;
  }
  if (renderer_ && report_.framesRendered > 0)
    detail::finishFrames(report_.framesDir,
                         FrameRange{std::max(plan_.renderFirst, plan_.firstFrame), plan_.lastFrame},
                         scene_.fps, report_.outDir, plan_.rendering, report_.contactSheetPath,
                         report_.moviePath, report_.notes);
  report_.hybrid = plan_.crumpling;
  if (report_.framesSimulated > 0) report_.meanCMean /= report_.framesSimulated;
  if (plan_.crumpling && report_.maxCMean > kLengthErrorWarning) {
    char text[256];
    std::snprintf(
        text, sizeof text,
        "edge lengths deviate from the pattern by %.2f %% on average at frame %d (c_mean; the "
        "crumpling model aims below 0.5 %%): the paper stretches or shrinks visibly there",
        100.0 * report_.maxCMean, report_.maxCMeanFrame);
    report_.warnings.push_back(text);
  }
  addStabilityWarnings();
  if (report_.halvings > 0)
    report_.warnings.push_back("the elastic solve halved its substep " +
                               std::to_string(report_.halvings) +
                               " times; consider more [scene] substeps");
  writeSummary();
}

void ShotRunner::addStabilityWarnings() {
  ShotReport& report = report_;
  if (const auto& span = report.newtonRetried; span.first >= 0)
    report.warnings.push_back("the elastic solve needed " +
                              std::to_string(sim::kRetryIterationFactor) +
                              " times [sim] max_newton_iterations at frames " +
                              std::to_string(span.first) + "-" + std::to_string(span.last));
  if (const auto& span = report.selfContactDropped; span.first >= 0)
    report.warnings.push_back(
        "the elastic solve failed with self-contact and went on without it at frames " +
        std::to_string(span.first) + "-" + std::to_string(span.last) +
        ": the sheet may pass through itself there");
  if (report.elasticHeldStill > 0)
    report.warnings.push_back(
        "the self-contact guard held the whole sheet still on " +
        std::to_string(report.elasticHeldStill) + " animation steps at frames " +
        std::to_string(report.elasticHeldFirst) + "-" + std::to_string(report.elasticHeldLast) +
        ": not even 1/64 of the elastic step's move kept the crumpling model's mesh from "
        "passing through itself, and its handles lag there (docs/CRUMPLING.md \"A crossing "
        "that stops the whole sheet\")");
  for (const auto& h : report.handleLags) {
    if (h.frames == 0) continue;
    char text[400];
    std::snprintf(text, sizeof text,
                  "handle '%s' lags behind its node on %d frames from frame %d, up to %.3g mm "
                  "at frame %d: the sheet cannot follow there without stretching over [model] "
                  "max_edge_strain%s",
                  h.name.c_str(), h.frames, h.firstFrame, 1e3 * h.max, h.maxFrame,
                  report.elasticHeldStill > 0 ? " or passing through itself" : "");
    report.warnings.push_back(text);
  }
  for (const auto& [h, span] : report.beyondReach) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "handle '%s' is pulled beyond the sheet's reach at frames %d-%d (up to %.3g m "
                  "past it): it stops on the reach and lags behind its node there",
                  sheet_.rig->handles()[h].name.c_str(), span.first, span.last, span.most);
    report.warnings.push_back(text);
  }
}

// summary.json, and for a farm's log (not a terminal) the same JSON on one
// final `SUMMARY {...}` line after the PROGRESS lines.
void ShotRunner::writeSummary() const {
  const std::string json = summaryJson(scene_, report_);
  detail::writeTextAtomically(report_.summaryPath, json);
  const bool terminal = plan_.interactive < 0
                            ? plan_.log != nullptr && ::isatty(::fileno(plan_.log)) != 0
                            : plan_.interactive != 0;
  if (plan_.log != nullptr && !terminal) {
    std::fprintf(plan_.log, "SUMMARY %s\n", json.c_str());
    std::fflush(plan_.log);
  }
}

namespace {

// The simulation step's stages (ms over the shot).
double stepMs(const ShotReport& r) {
  double step = 0.0;
  for (const char* name : {"elastic", "geometric", "cones", "rebuild", "isometry", "contacts"})
    if (const auto it = r.stages.find(name); it != r.stages.end()) step += it->second.totalMs;
  return step;
}

}  // namespace

double ShotReport::contactShareOfStep() const {
  const double step = stepMs(*this);
  return step > 0.0 ? (contactMs + selfContactMs) / step : 0.0;
}

double ShotReport::airShareOfStep() const {
  const double step = stepMs(*this);
  return step > 0.0 ? airMs / step : 0.0;
}

std::string summaryText(const ShotReport& r) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "%d frames simulated (%zu vertices, %zu triangles), %d rendered\n",
                r.framesSimulated, r.vertices, r.triangles, r.framesRendered);
  out += line;
  for (const auto& [name, cost] : r.stages) {
    std::snprintf(line, sizeof line, "  %-13s %9.2f ms/frame over %ld frames\n", name.c_str(),
                  cost.msPerFrame(), cost.frames);
    out += line;
  }
  std::snprintf(line, sizeof line,
                "  newton   %.2f iterations/substep, %ld halvings; max handle error %.3g m, max "
                "edge strain %.3g\n",
                r.substeps > 0 ? static_cast<double>(r.newtonIterations) / r.substeps : 0.0,
                r.halvings, r.maxHandleError, r.maxStrain);
  out += line;
  if (r.contactsOn) {
    const double frames = std::max(1, r.framesSimulated - 1);
    std::snprintf(line, sizeof line,
                  "  contacts %.2f ms/frame colliders + %.2f ms/frame self-contact (%s, ran in %ld "
                  "substeps): %.1f %% of the step; deepest vertex %.3f thicknesses in (frame %d)\n",
                  r.contactMs / frames, r.selfContactMs / frames, r.selfContactMode.c_str(),
                  r.selfContactSteps, 100.0 * r.contactShareOfStep(), r.maxContactDepth,
                  r.maxContactDepthFrame);
    out += line;
  }
  if (r.airOn) {
    std::snprintf(line, sizeof line, "  air      %.2f ms/frame: %.1f %% of the step\n",
                  r.airMs / std::max(1, r.framesSimulated - 1), 100.0 * r.airShareOfStep());
    out += line;
  }
  if (r.tearingOn) {
    const double frames = std::max(1, r.framesSimulated - 1);
    if (r.tearStartKinds.empty()) {
      std::snprintf(line, sizeof line, "  tearing  %.2f ms/frame: nothing tore\n",
                    r.tearMs / frames);
    } else {
      std::snprintf(line, sizeof line,
                    "  tearing  %.2f ms/frame: %zu tear(s), the first at frame %d, %zu tip "
                    "advances\n",
                    r.tearMs / frames, r.tearStartKinds.size(), r.firstTearFrame,
                    r.tearAdvances.size());
    }
    out += line;
  }
  if (r.soundOn) {
    std::snprintf(line, sizeof line,
                  "  sound    %ld crumpling, %ld friction, %ld tearing event(s)\n",
                  r.soundEvents[0], r.soundEvents[1], r.soundEvents[2]);
    out += line;
  }
  out += "  cache:   " + r.cachePath + "\n";
  if (!r.soundPath.empty()) out += "  sound:   " + r.soundPath + "\n";
  if (!r.framesDir.empty()) out += "  frames:  " + r.framesDir + "/\n";
  if (!r.contactSheetPath.empty()) out += "  contact sheet: " + r.contactSheetPath + "\n";
  if (!r.moviePath.empty()) out += "  movie:   " + r.moviePath + "\n";
  out += "  summary: " + r.summaryPath + "\n";
  for (const auto& n : r.notes) out += "  note: " + n + "\n";
  for (const auto& w : r.warnings) out += "  warning: " + w + "\n";
  return out;
}

std::string summaryJson(const io::SceneSpec& scene, const ShotReport& r) {
  JsonWriter j;
  j.beginObject();
  j.key("scene").value(scene.name);
  j.key("scene_file").value(scene.file);
  j.key("cache").value(r.cachePath);
  j.key("frames_dir").value(r.framesDir);
  j.key("frames_simulated").value(r.framesSimulated);
  j.key("frames_rendered").value(r.framesRendered);
  j.key("vertices").value(r.vertices);
  j.key("triangles").value(r.triangles);
  j.key("substeps_per_frame").value(scene.substeps);
  const sim::Material& paper = scene.paper.material;
  j.key("paper").beginObject();
  j.key("preset").value(paper.name);
  j.key("thickness_m").value(paper.thickness);
  j.key("areal_density_kg_m2").value(paper.arealDensity());
  j.key("stretch_stiffness_N_m").value(paper.stretchStiffness());
  j.key("bending_stiffness_N_m").value(paper.bendingStiffness());
  j.endObject();
  // What ran: a scene pays only for what it uses (docs/ARCHITECTURE.md "Invariants everyone
  // keeps").
  j.key("ran").beginObject();
  j.key("elastic").value(true);
  j.key("crumpling_model").value(r.hybrid);
  j.key("contacts").value(!scene.colliders.empty());
  j.key("self_contact").value(r.selfContactSteps > 0);
  j.key("tearing").value(r.tearingOn);
  j.key("air").value(r.airOn);
  j.key("sound").value(r.soundOn);
  j.key("render_osmesa").value(r.framesRendered > 0 && r.renderBackend == "osmesa");
  j.key("render_embree").value(r.framesRendered > 0 && r.renderBackend == "embree");
  j.endObject();
  j.key("ms_per_frame").beginObject();
  for (const auto& [name, cost] : r.stages) j.key(name).value(cost.msPerFrame());
  j.endObject();
  if (r.contactsOn) {
    // What contacts cost (detection, penalties' setup and the
    // failsafe; the Newton iterations they add are the elastic stage's) and
    // the deepest any free vertex went, measured at every frame.
    const double frames = std::max(1, r.framesSimulated - 1);
    j.key("contacts").beginObject();
    j.key("colliders").value(static_cast<long long>(scene.colliders.size()));
    j.key("self_contact_mode").value(r.selfContactMode);
    j.key("self_contact_substeps").value(static_cast<long long>(r.selfContactSteps));
    j.key("collider_ms_per_frame").value(r.contactMs / frames);
    j.key("self_contact_ms_per_frame").value(r.selfContactMs / frames);
    j.key("share_of_step").value(r.contactShareOfStep());
    j.key("contacts_per_frame")
        .value(static_cast<double>(r.contactSamples) / std::max(1, r.framesSimulated));
    j.key("max_depth_thicknesses").value(r.maxContactDepth);
    j.key("max_depth_frame").value(r.maxContactDepthFrame);
    j.endObject();
  }
  if (r.airOn) {
    // What the air's terms cost in the elastic step (docs/AIR.md "Cost").
    j.key("air").beginObject();
    j.key("ms_per_frame").value(r.airMs / std::max(1, r.framesSimulated - 1));
    j.key("share_of_step").value(r.airShareOfStep());
    j.endObject();
  }
  if (r.soundOn) {
    // The sound events in the cache, and the soundtrack `run` made.
    j.key("sound").beginObject();
    j.key("crumpling_events").value(static_cast<long long>(r.soundEvents[0]));
    j.key("friction_events").value(static_cast<long long>(r.soundEvents[1]));
    j.key("tearing_events").value(static_cast<long long>(r.soundEvents[2]));
    const auto events = r.stages.find("sound events");
    j.key("ms_per_frame").value(events != r.stages.end() ? events->second.msPerFrame() : 0.0);
    j.key("resonator_ms_per_frame").value(r.soundResonatorMs / std::max(1, r.framesSimulated));
    j.key("wav").value(r.soundPath);  // empty: `simulate` (crumple sound makes it)
    j.endObject();
  }
  if (r.tearingOn) {
    // The tears: where each started and how far it ran.
    const double frames = std::max(1, r.framesSimulated - 1);
    j.key("tearing").beginObject();
    j.key("ms_per_frame").value(r.tearMs / frames);
    j.key("bake_ms_per_frame").value(r.tearBakeMs / frames);
    j.key("first_tear_frame").value(r.firstTearFrame);
    j.key("tip_advances").value(static_cast<long long>(r.tearAdvances.size()));
    j.key("crumpling_model_cuts").value(r.tearGeometricCuts);
    j.key("curved_regions_flattened").value(r.tearRegionsFlattened);
    j.key("handover_frame").value(r.tearHandoverFrame);
    j.key("tears").beginArray();
    for (std::size_t t = 0; t < r.tearStartKinds.size(); ++t) {
      j.beginObject();
      j.key("started_at").value(tear::candidateKindName(r.tearStartKinds[t]));
      double length = 0.0, detail = 0.0;
      for (const auto& seg : r.tearSegments)
        if (seg.tear == static_cast<int>(t)) {
          length += tear::pathLength(seg.cut);
          detail += tear::pathLength(seg.detail);
        }
      j.key("cut_length_m").value(length);
      j.key("detail_length_m").value(detail);
      j.endObject();
    }
    j.endArray();
    j.endObject();
  }
  j.key("newton_iterations").value(static_cast<long long>(r.newtonIterations));
  j.key("substep_halvings").value(static_cast<long long>(r.halvings));
  j.key("max_handle_error").value(r.maxHandleError);
  j.key("max_edge_strain").value(r.maxStrain);
  if (r.hybrid) {
    // Paper Table IV measures, as fractions (c_mean 0.005 = 0.5 %).
    j.key("crumpling").beginObject();
    j.key("c_mean_mean").value(r.meanCMean);
    j.key("c_mean_max").value(r.maxCMean);
    j.key("n_comp_max").value(r.maxNComp);
    j.key("singular_vertices").value(r.singularVertices);
    j.key("interior_singular_vertices").value(r.interiorSingularVertices);
    j.key("max_triangles").value(static_cast<long long>(r.maxTriangles));
    j.key("elastic_retries").value(static_cast<long long>(r.elasticRetries));
    j.key("strain_limit_steps").value(static_cast<long long>(r.strainLimitRuns));
    j.key("strain_limit_carried_steps").value(static_cast<long long>(r.strainLimitCarried));
    j.key("elastic_steps_held_still").value(static_cast<long long>(r.elasticHeldStill));
    j.key("elastic_held_first_frame").value(static_cast<long long>(r.elasticHeldFirst));
    j.key("elastic_held_last_frame").value(static_cast<long long>(r.elasticHeldLast));
    // Handles held back so the sheet does not stretch (strain_limit.hpp).
    j.key("handle_lag_frames").value(static_cast<long long>(r.lagFrames));
    j.key("max_handle_lag").value(r.maxHandleLag);
    j.key("max_handle_lag_frame").value(static_cast<long long>(r.maxHandleLagFrame));
    j.key("max_handle_lag_vertex").value(static_cast<long long>(r.maxHandleLagVertex));
    j.key("handle_lags").beginArray();
    for (const auto& h : r.handleLags) {
      if (h.frames == 0) continue;
      j.beginObject();
      j.key("handle").value(h.name);
      j.key("frames").value(static_cast<long long>(h.frames));
      j.key("first_frame").value(static_cast<long long>(h.firstFrame));
      j.key("max_lag").value(h.max);
      j.key("max_lag_frame").value(static_cast<long long>(h.maxFrame));
      j.endObject();
    }
    j.endArray();
    j.endObject();
  }
  j.key("warnings").beginArray();
  for (const auto& w : r.warnings) j.value(w);
  j.endArray();
  j.key("error").value(r.error);
  j.endObject();
  return j.str() + "\n";
}

}  // namespace crumple::pipeline
