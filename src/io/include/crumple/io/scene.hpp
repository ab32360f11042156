#pragma once
// The scene file (scene.toml, parsed with toml++): what one shot is.
// All lengths are converted to metres on parse (scene `units`), angles to
// radians. Unknown keys and bad values throw crumple::InputError naming the
// file, the line and the key (docs/ARCHITECTURE.md "Invariants everyone keeps").
// The simulation's parameters are parsed straight into the modules' own
// structs (sim::SimParams, sim::Material, paper::CrumpleParams,
// tear::TearingParams, sound::EventParams: header-only, their defaults
// written once there); what is io's own (where things are, what runs, what
// is rendered and written) is declared here.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/paper/params.hpp"
#include "crumple/sim/material.hpp"
#include "crumple/sim/params.hpp"
#include "crumple/sound/params.hpp"
#include "crumple/tear/params.hpp"

namespace crumple::io {

// A paper material preset (assets/papers/*.toml): the material the
// simulator runs (raw physical numbers; it derives stretch and bending
// stiffness from them) and what the preset adds to it.
struct PaperPreset {
  // name (e.g. "office-70gsm"), thickness (m), density (kg/m^3, grammage /
  // thickness), Young's modulus (Pa), Poisson ratio
  sim::Material material;
  std::string file;                   // where it was read from
  double grammage = 0.0;              // kg/m^2
  Vec3 frontColor{0.92, 0.92, 0.90};  // linear RGB albedo of the printed side
  Vec3 backColor{0.92, 0.92, 0.90};
};

struct SheetSpec {
  enum class Kind { Rectangle, PatternMesh, Outline };
  Kind kind = Kind::Rectangle;
  double width = 0.0;   // m (Rectangle; Outline: its bounding box's)
  double height = 0.0;  // m (Rectangle; Outline: its bounding box's)
  // Outline: the pattern's polygon (m, counter-clockwise after parsing,
  // simple, inside [0, width] x [0, height]), meshed to max_edge.
  std::vector<Vec2> outline;
  std::string patternMesh;   // mesh node name in the animation file (PatternMesh)
  long patternMeshLine = 0;  // scene file line of pattern_mesh (for errors)
  double maxEdge = 0.0;      // m: simulation mesh resolution; 0 = min(width, height) / 16
  // Placement of the pattern in the world: x = origin + u * uAxis + v * vAxis.
  Vec3 origin = Vec3::Zero();
  Vec3 uAxis = Vec3::UnitX();
  Vec3 vAxis = -Vec3::UnitZ();  // default: lying flat, front side facing +Y (up)
};

struct HandleSpec {
  std::string name;                  // unique handle name (defaults to node)
  std::string node;                  // animated node in the animation file
  long nodeLine = 0;                 // scene file line of `node` (for errors)
  std::optional<Vec2> patternPoint;  // m; nullopt = sheet point nearest the node at the first frame
  long patternLine = 0;              // scene file line of `pattern` (for errors)
  // Tangent-plane control (thesis 2.3.1): the node's rotation drives 2-4
  // neighbour vertices. tangentVertices 0 = automatic (2 at a corner, 3 on a
  // border, 4 inside).
  bool tangentControl = false;
  int tangentVertices = 0;
  // A finger's contact patch instead of tangent-plane vertices (m; 0 =
  // the vertices): the node holds the points of the sheet at this radius
  // around the handle, softly (model::HandleRig, sim::Grip).
  double patchRadius = 0.0;
  std::optional<double> releaseTime;  // s: the handle lets go at this time
};

struct CameraSpec {
  // Either a camera node of the animation file or a fixed camera from the scene.
  std::string node;   // non-empty = take the camera from this animation node
  long nodeLine = 0;  // scene file line of `node` (for errors)
  Vec3 position{0.0, 0.3, 0.6};
  Vec3 lookAt = Vec3::Zero();
  Vec3 up = Vec3::UnitY();
  double yfov = 0.6981317007977318;  // rad (40 degrees); focal_mm + sensor_mm override it
  // True when the scene gave fov_deg or focal_mm: then yfov overrides the
  // field of view of an animation-file camera (node).
  bool fovExplicit = false;
  int width = 640;
  int height = 480;
  // Depth of field (the path tracer only): f-number, 0 = pinhole. The focal
  // length follows from the field of view and the sensor width:
  // f = sensorWidth / aspect / (2 tan(yfov / 2)).
  double fStop = 0.0;
  double sensorWidth = 0.036;  // m
  // m along the view axis; 0 = the distance to look_at (fixed camera) or 1 m.
  double focusDistance = 0.0;
  // Motion blur (the path tracer only; docs/RENDERING.md "Motion blur"): the
  // shutter is open from shutterOpen to shutterClose, in frames relative to
  // the frame's time, -1 <= open < close <= 1 (e.g. -0.25, 0.25: a centred
  // 180-degree shutter). Both 0: no motion blur, and the cache stores no
  // sub-frame motion.
  double shutterOpen = 0.0;
  double shutterClose = 0.0;
  long shutterLine = 0;  // scene file line of `shutter` (for errors)
  bool motionBlur() const { return shutterClose > shutterOpen; }
};

struct LightSpec {
  enum class Kind { Directional, Point, Area };
  std::string name;
  Kind kind = Kind::Directional;
  Vec3 direction{-0.4, -1.0, -0.3};  // Directional: direction the light travels; Area: its normal
  Vec3 position = Vec3::Zero();      // Point, Area (centre)
  Vec3 color{1.0, 1.0, 1.0};
  double intensity = 1.0;
  double angle = 0.0;   // rad, Directional: angular diameter of the sun disc (type "sun")
  Vec2 size{0.1, 0.1};  // m, Area: side lengths
  bool shadow = false;  // the key light casts the paper's shadow in the preview
};

// Uniform light from the surroundings: radiance color * intensity.
struct EnvironmentSpec {
  Vec3 color{0.80, 0.82, 0.86};
  double intensity = 0.25;
};

// How the paper looks (render only).
struct PaperLookSpec {
  std::string texture;   // resolved path of a PNG (alpha < 0.5 cuts the paper); empty = ruled
  long textureLine = 0;  // scene file line of `texture` (for errors)
  Vec2 textureSize = Vec2::Zero();          // m; zero = the pattern's bounding box
  std::optional<double> transmittance;      // default: render::paperTransmittance(thickness)
  double creaseAngle = 0.5235987755982988;  // rad: sharper edges split the shading normals
};

// A prop: an opaque diffuse mesh that is rendered (contacts come later).
// Either a mesh node of the animation file (moving with the node), or a box.
struct PropSpec {
  std::string name;
  std::string node;  // mesh node of the animation file; empty = box
  long nodeLine = 0;
  Vec3 boxSize{0.1, 0.1, 0.1};   // m (box)
  Vec3 position = Vec3::Zero();  // m, centre of the box
  Vec3 color{0.6, 0.6, 0.6};
};

// A collider the sheet must stay outside of (docs/CONTACTS.md). Plane: the solid half
// below `position` along -normal; box: centred on `position`, axis-aligned
// (without a node); sphere: centred on `position`; mesh: the triangles of an
// animation-file node, moving with the node.
// A box or sphere with a `node` follows that node (any node, e.g. a finger;
// it need not hold a mesh): `position` is then an offset in the node's local
// frame and the solid moves rigidly with the node's world pose (position and
// rotation; a box's axes turn with the node).
struct ColliderSpec {
  enum class Kind { Plane, Box, Sphere, Mesh };
  std::string name;
  Kind kind = Kind::Plane;
  Vec3 position = Vec3::Zero();     // m; world, or the node's local frame when `node` is set
  Vec3 normal = Vec3::UnitY();      // plane (unit)
  Vec3 size = Vec3::Constant(0.1);  // m, box side lengths
  double radius = 0.05;             // m, sphere
  // Coulomb coefficient of paper on this collider, resolved on parse: an
  // explicit `friction` key, else SceneSpec::friction[material].
  double friction = 0.3;
  // The [friction] entry this collider is made of: "default" when the scene
  // gives neither material nor friction, "custom" for an explicit friction
  // without a material (with both, the name is kept and friction wins).
  std::string material = "default";
  std::string node;   // mesh (required), box and sphere (optional): animation-file node
  long nodeLine = 0;  // scene file line of `node` (for errors)
};

// [contact]: how the sheet meets itself (docs/CONTACTS.md).
struct ContactSpec {
  // Self-contact of the sheet. Auto: tested only while the sheet is folded
  // (its triangle normals spread more than 60 degrees from their mean); On:
  // at every step; Off: never.
  enum class Self { Off, On, Auto };
  Self self = Self::Auto;
};

// [sound]'s own keys: where the soundtrack is heard from, the sound
// database and the WAV file's format (the events' keys fill
// sound::EventParams).
struct SoundtrackSpec {
  std::optional<Vec3> listener;  // world (m); default: the camera
  std::string database;          // sound database folder, resolved; empty: the default
  long databaseLine = 0;         // scene file line of `database` (for errors)
  int channels = 2;              // 1 or 2
  int sampleRate = 48000;        // 48000 or 44100
  bool floatSamples = false;     // 32-bit float instead of 24-bit PCM
};

struct GroundSpec {
  bool enabled = false;
  double height = 0.0;  // m, world Y of the plane
  double size = 2.0;    // m, side of the square drawn
  Vec3 color{0.55, 0.50, 0.45};
};

struct OutputSpec {
  std::string dir;  // empty = out/<scene name>/ relative to the working directory
  bool frames = true;
};

struct ModelSpec {
  // Elastic: plain FEM on the fixed [sheet] mesh. Hybrid: the crumpling model
  // of Schreck et al. 2015 (flat/curved regions, singular vertices).
  enum class Type { Elastic, Hybrid };
  Type type = Type::Elastic;  // default when the scene has no [model] table
  long typeLine = 0;          // scene file line of `type` (or [model]), 0 = absent (for errors)
};

struct SceneSpec {
  std::string file;           // scene.toml path as given
  std::string dir;            // folder holding it (relative paths resolve here)
  std::string name;           // [scene] name, default: folder name
  std::string animationFile;  // resolved path, may be empty (no handles then)
  double metresPerUnit = 1.0;
  double fps = 24.0;
  int frameStart = 1;
  int frameEnd = 48;  // inclusive
  int substeps = 4;
  std::uint64_t seed = 1;
  // [scene] frame_budget_s: the cost guard's budget of CPU seconds for one frame
  // (docs/RELIABILITY.md "The cost guard"). Unset (nullopt): derived from the
  // shot's own frame times; 0: the cost guard is off.
  std::optional<double> frameBudget;
  SheetSpec sheet;
  // [paper] preset; by default the preset whose numbers are sim::Material's.
  std::string paperPreset = sim::Material{}.name;
  PaperPreset paper;  // resolved preset
  std::vector<HandleSpec> handles;
  CameraSpec camera;
  std::vector<LightSpec> lights;  // default: a key (with shadow) and a fill
  EnvironmentSpec environment;
  GroundSpec ground;
  PaperLookSpec look;  // [paper] texture, texture_size, transmittance, crease_deg
  std::vector<PropSpec> props;
  std::vector<ColliderSpec> colliders;  // [[colliders]]: contacts run only when there are some
  // [friction]: Coulomb coefficients of paper on named materials (material
  // name -> mu >= 0). Always holds "default" (a collider without material or
  // friction) and "paper" (paper on paper, used by self-contact), 0.3 each
  // unless the scene overrides them; the scene may add more ("wood", ...).
  std::map<std::string, double> friction;
  ContactSpec contact;  // [contact]
  // [tear]: tearing (thesis 3.3; docs/TEARING.md). Off unless the table is
  // present (or enabled = true). Lengths have fixed units (their key names
  // say which).
  bool tearEnabled = false;
  tear::TearingParams tearing;
  // [sound]: the soundtrack (thesis Chapter 4; docs/SOUND.md). Off unless
  // the table is present (or enabled = true): `simulate` then detects the
  // sound events and stores them in the cache, `run` also writes sound.wav.
  bool soundEnabled = false;
  sound::EventParams soundEvents;
  SoundtrackSpec soundtrack;
  OutputSpec output;
  sim::SimParams sim;  // [sim]: gravity, damping, Newton iterations
  ModelSpec model;     // [model] type
  // [model]'s parameters of the hybrid crumpling model (paper Table VI;
  // thesis 2.3.3), in SI units whatever [scene] units says; meaningful for
  // ModelSpec::Type::Hybrid only.
  paper::CrumpleParams crumpling;
  std::string sourceText;  // the scene file's text, kept for the cache header

  // Animation time (s) of frame `frame`: frame / fps, the DCC convention
  // (frame 0 at t = 0). See docs/SCENE.md "Time".
  double frameTime(int frame) const { return static_cast<double>(frame) / fps; }
};

// Parse a scene file. Resolves the paper preset (see paperPresetDirs) and the
// animation file path; does not load the animation.
SceneSpec loadScene(const std::string& path);
// Parse scene text; sourceName names it in errors, baseDir resolves paths.
// checkFiles = false skips the existence check of the animation file (the
// renderers re-parse a cached scene whose animation need not travel with it).
SceneSpec parseScene(std::string_view text, const std::string& sourceName,
                     const std::string& baseDir, bool checkFiles = true);
// SCENE may be a scene.toml or a folder holding one.
std::string resolveScenePath(const std::string& sceneOrFolder);

class AnimationScene;
// Check that every node the scene names exists in the loaded animation file:
// handle nodes, the camera node (which must hold a camera), the pattern mesh
// and mesh colliders and props (which must hold triangles), and the nodes box
// and sphere colliders follow (any node). Throws InputError at the scene file's
// line, e.g. "scene.toml:12: 'handles[0].node': drape.glb: no node named ...".
void checkAnimationNodes(const SceneSpec& scene, const AnimationScene& animation);

// Load one preset file; errors name the file, line and key.
PaperPreset loadPaperPreset(const std::string& path);
// Directories searched for "<preset>.toml": $CRUMPLE_ASSETS/papers, then the
// source tree's assets/papers (compiled in as CRUMPLE_SOURCE_ASSETS).
std::vector<std::string> paperPresetDirs();

}  // namespace crumple::io
