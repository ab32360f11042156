#pragma once
// Sound-source events and their resonators (thesis 4.3.2; docs/SOUND.md).
// Every simulated frame, the sheet is searched for
// - crumpling events: connected patches of a regular grid, laid on the
//   pattern and carried onto the surface (Fig. 4.10), whose mean curvature
//   changed sign by more than a threshold since the previous frame;
// - friction events: connected sets of vertices touching something, with
//   their mean sliding speed;
// - tearing events: tear tips that advanced, with their speed (4.4).
// Each crumpling or friction event sets resonators vibrating: the sheet
// around it up to the ridges (dihedral angle above a_max), the free
// borders, the held points and the contacts (Fig. 4.11), one resonator per
// region it reaches, each sized by l_r (its mean ruling length) and l_c
// (its free curved border length; 0: constrained) (Fig. 4.12).
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sound/event_types.hpp"
#include "crumple/sound/params.hpp"

namespace crumple::sound {

// One frame of the simulated sheet as the events see it.
struct SheetFrame {
  const mesh::SheetMesh* mesh = nullptr;  // positions, pattern, triangles, regions
  // The crumpling model's rulings (vertex pairs of the mesh); empty otherwise.
  std::vector<std::array<int, 2>> rulings;
  // The crumpling model's regions: its flat regions are planar, so their
  // borders are never free (thesis 4.3.2: flat regions are constrained).
  // Otherwise (the elastic model) every border is judged by its bend.
  bool developableRegions = false;
  std::vector<int> heldVertices;  // handles holding the sheet
  struct Touch {
    int vertex = -1;
    double slideSpeed = 0.0;  // m/s
  };
  std::vector<Touch> contacts;
  struct TipAdvance {
    int tear = -1;
    Vec2 from = Vec2::Zero();  // pattern (m)
    Vec2 to = Vec2::Zero();
  };
  std::vector<TipAdvance> tearAdvances;  // made since the previous frame
  double time = 0.0;                     // s: the frame's (tip speeds between advances)
  double frameDuration = 0.0;            // s since the previous frame
};

// The frame-to-frame detector: keeps the curvature grid's previous values.
class EventDetector {
 public:
  // Throws std::invalid_argument for a non-positive step, threshold,
  // radius or a_max outside (0, pi).
  explicit EventDetector(const EventParams& params = {});

  // The events of this frame, in a fixed order (crumpling, friction,
  // tearing; each by position in the grid, vertex or tear): deterministic.
  // The first frame has no crumpling events (no previous curvature).
  // Throws std::invalid_argument for a malformed frame.
  std::vector<SoundEvent> detect(const SheetFrame& frame);

  const EventParams& params() const { return params_; }
  // The grid's step and size, fixed at the first frame.
  double gridStep() const { return step_; }
  int gridPoints() const { return nx_ * ny_; }
  // Mean curvature (1/m) at each grid point after the last detect(), row by
  // row from the pattern's lower left; nullopt where it is undefined (off
  // the sheet, across a tear, at its border).
  const std::vector<std::optional<double>>& curvature() const { return previous_; }
  // Checkpoint and resume (docs/CHECKPOINT.md): the grid and its last curvatures, and
  // each tear's last advance. restoreState throws CorruptDataError for a
  // malformed state.
  void saveState(StateWriter& out) const;
  void restoreState(StateReader& in);
  // Wall time spent so far (ms): all of detect(), and of it the resonators.
  double detectMs() const { return detectMs_; }
  double resonatorMs() const { return resonatorMs_; }

 private:
  EventParams params_;
  double step_ = 0.0;
  Vec2 origin_ = Vec2::Zero();
  int nx_ = 0, ny_ = 0;
  std::vector<std::optional<double>> previous_;
  std::map<int, double> lastAdvance_;  // tear -> the time of its last advance
  double detectMs_ = 0.0, resonatorMs_ = 0.0;
};

// Thesis 4.3.2 "Resonator estimation" on its own: the resonators that
// `seedTriangles` set vibrating. `blocked[v]` marks held and touching
// vertices; an edge with such an end, a dihedral angle above a_max or on the
// sheet's border stops the growth, and a border edge with such an end is
// not free. (A friction event's own growth passes touching vertices:
// EventDetector::detect.)
std::vector<Resonator> findResonators(const SheetFrame& frame,
                                      const std::vector<int>& seedTriangles,
                                      const std::vector<char>& blocked, const EventParams& params);

}  // namespace crumple::sound
