#pragma once
// Paper Table III: the isometry projection (Sec. 6.3, paper::IsometryProjector)
// against a hard-constraint Shape-Up projection (Bouaziz et al. 2012,
// paper::ShapeUpProjector) on the same inputs: S_P as the crumpling model hands
// it to the projection at chosen frames of the hybrid samples.
#include <ostream>
#include <string>
#include <vector>

namespace crumple::bench {

struct ProjectionComparisonRow {
  std::string input;  // "<sample> frame <N>"
  int triangles = 0;
  double cInit = 0.0;                                  // c_mean before either projection (fraction)
  double oursMs = 0.0, oursCMean = 0.0, oursDm = 0.0;  // median ms; c_mean after; d_m (m)
  // Ours as the paper's Phase I + II alone (lengthSweeps = 0); the row above
  // is ours as the crumpling model runs it (with its length sweeps).
  double oursPaperMs = 0.0, oursPaperCMean = 0.0, oursPaperDm = 0.0;
  double shapeUpMs = 0.0, shapeUpCMean = 0.0, shapeUpDm = 0.0;
  int shapeUpIterations = 0;
  // Shape-Up stopped as soon as its c_mean is at most ours (oursCMean): median
  // ms and iterations; shapeUpMatched false when its iteration cap came first.
  double shapeUpMatchMs = 0.0;
  int shapeUpMatchIterations = 0;
  bool shapeUpMatched = false;
};

// Runs each named hybrid sample (samples/NAME under sourceDir), captures the
// projection inputs, and times both projections on each (median of `runs`).
// `progress` (may be null) gets one line per input.
std::vector<ProjectionComparisonRow> compareProjections(const std::vector<std::string>& samples,
                                                        int runs, const std::string& sourceDir,
                                                        std::ostream* progress);
// The rows as a Markdown table beside the paper's Table III.
std::string projectionComparisonMarkdown(const std::vector<ProjectionComparisonRow>& rows);
// The rows as CSV with a header line. Throws std::runtime_error when it cannot write.
void writeProjectionComparisonCsv(const std::string& path,
                                  const std::vector<ProjectionComparisonRow>& rows);

}  // namespace crumple::bench
