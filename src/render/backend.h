#pragma once
// Renderer backends behind one small interface. A backend turns frame requests (a frame index and
// its cameras) into feature-buffer frames; the render job (render_job.cpp) does everything around
// that once for all backends: which frames, resuming, writing through frames/, progress. Adding a
// backend is one file with a factory, plus its line in renderBackends() (backend.cpp).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "frames/feature_frame.h"
#include "render/render_job.h"

namespace dynbench::render {

// A frame the job steps the scene through without rendering it: (its time, its previous frame's).
struct SceneStep {
  double time = 0.0, previousTime = 0.0;
};

struct FrameRequest {
  long frame = 0;
  FrameCameras cameras;
  // The frames of the job's stepping (RenderJob::stepFrom) before this one that are not rendered
  // (already complete, or before the part this job renders), in order: a backend whose scene keeps
  // state from frame to frame sets it to each before this frame, as if it had rendered them.
  std::vector<SceneStep> stepsBefore;
};

// Receives each finished frame, in request order, one call at a time; an error stops the backend.
// It may be called from another thread, while the next frame renders and reports its rows.
using FrameSink = std::function<Expected<void>(frames::FeatureFrame&&)>;
// (request index, rows of that frame finished): for progress; may be called from another thread.
using RowProgress = std::function<void(std::size_t, int)>;

class RenderBackend {
 public:
  virtual ~RenderBackend() = default;
  virtual Expected<void> render(const std::vector<FrameRequest>& requests, const FrameSink& done, const RowProgress& rows) = 0;
  // Work done so far (the Embree path tracer counts its rays; external renderers may not).
  virtual RenderStatistics statistics() const { return {}; }
};

struct BackendContext {
  const scene::Scene& scene;
  const RenderJob& job;
  int cameraNode = -1;
  std::vector<std::string>& warnings;
};

using BackendFactory = Expected<std::unique_ptr<RenderBackend>> (*)(const BackendContext&);

struct BackendEntry {
  const char* name;         // --engine NAME, and "engine" in the sidecar's render record
  const char* description;  // for --help
  BackendFactory create;
};

// Every backend this build has, the default first.
const std::vector<BackendEntry>& renderBackends();
// Their names, in that order.
std::vector<std::string> backendNames();
// The backend named `name`, or a usage error listing the names.
Expected<const BackendEntry*> findBackend(const std::string& name);

// The backends' factories (one file each).
Expected<std::unique_ptr<RenderBackend>> createEmbreeBackend(const BackendContext& context);
Expected<std::unique_ptr<RenderBackend>> createCyclesBackend(const BackendContext& context);

}  // namespace dynbench::render
