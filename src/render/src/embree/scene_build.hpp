#pragma once
// Private to the path tracer: the Embree device and its errors, and the
// per-render scene build: the render geometry turned into FrameData (meshes,
// shading arrays, lights, camera) and an Embree scene (BVH) over its buffers.
#include <embree3/rtcore.h>

#include <memory>
#include <mutex>
#include <string>

#include "../render_geometry.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "frame_data.hpp"

namespace crumple::render::pt {

// Releases an Embree scene.
struct SceneDeleter {
  void operator()(RTCSceneTy* s) const { rtcReleaseScene(s); }
};
// An owned Embree scene.
using ScenePtr = std::unique_ptr<RTCSceneTy, SceneDeleter>;

// Owns the Embree device and records the last error Embree reported on it.
class EmbreeDevice {
 public:
  // Creates the device; its BVH builds use crumple::threadCount() threads.
  // Throws std::runtime_error naming Embree's error when it cannot.
  EmbreeDevice();
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  // The device handle.
  RTCDevice get() const { return device_.get(); }
  // Throws std::runtime_error when Embree reports an error (`where` names the call).
  void check(const char* where);

 private:
  // Releases an Embree device.
  struct DeviceDeleter {
    void operator()(RTCDeviceTy* d) const { rtcReleaseDevice(d); }
  };
  // Records Embree's error message (called by Embree on any thread).
  static void onError(void* user, RTCError code, const char* message);

  std::mutex errorMutex_;
  std::string lastError_;
  std::unique_ptr<RTCDeviceTy, DeviceDeleter> device_;  // last: released first
};

// The path tracer's data of one frame, from its render geometry: the sheet
// (drawn triangles and tear-patch pieces, with their shading data), the
// ground square, the props with triangles, the lights and the camera.
// References the scene's texture and tear atlas.
FrameData buildFrameData(const RenderScene& scene, const mesh::SheetMesh& sheet,
                         const detail::RenderGeometry& geometry, const PathTraceSettings& settings);

// The Embree scene (BVH) over f's meshes, sharing their buffers (f must
// outlive it); the sheet gets the alpha-cut filter when `cutSheet`.
ScenePtr buildScene(EmbreeDevice& device, FrameData& f, bool cutSheet);

}  // namespace crumple::render::pt
