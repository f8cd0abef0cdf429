#pragma once
// The VR head camera (the thesis's Eternal Valley VR, §5.5): a person in a headset moving through
// the replayed match. The body travels the fly-through's path (camera/flythrough.h: one of the
// bot's cut-free stretches, smoothed clear of static geometry, at a constant speed): smooth
// locomotion, the way the thesis's Oculus sample walked, which carries the headset's play space
// along the path and turns it with the path's heading. Inside the play space the head moves as a
// real person's did: its rotation and its offset from where it started (sway, steps, crouches)
// come from a recorded head trace (data/vr-head/, or any CSV in merge-camera's format), resampled
// to the dataset's poses (positions linearly, rotations by slerp), the trace's heading at its start
// turned onto the path's, and the offset scaled from metres to the map's units by the capture's
// own scale (its `k` record: Cube 2 8 units to the metre, OpenArena 32). A head never ends inside
// geometry: its offset from the body is cut short `clearance` before the first static surface, and
// where a chord between poses or frames would still pass through a wall the offsets around it
// shrink until none does (the body's own path is clear, so this ends).
//
// Because the body's path and speed are the fly-through's, a VR dataset and the fly-through of the
// same match differ only by what the head adds: the within-match pair that isolates head motion.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camera/flythrough.h"
#include "camera/merge_camera.h"
#include "core/error.h"
#include "metrics/camera_motion.h"

namespace dynbench::camera {

// A head trace: a CSV pose log (time,x,y,z,qx,qy,qz,qw; metres, OpenXR's right-handed Y-up stage
// frame, the head looking along -Z), read strictly: at least two poses, times increasing, each
// quaternion of unit length within 1e-3 (a recorder's quaternions are unit; one that is not is a
// column mix-up, not something to normalise away). Errors name file:line.
inline constexpr double kHeadTraceUnitTolerance = 1e-3;
Expected<std::vector<CameraPoseKey>> readHeadTrace(const std::filesystem::path& csv);

// The trace's pose at time t (seconds, the trace's own clock; clamped to its ends): position
// linear, rotation slerped along the shorter arc between the two poses around t.
CameraPoseKey headPoseAt(const std::vector<CameraPoseKey>& trace, double t);

struct VrCameraOptions {
  std::filesystem::path trace;       // the head trace (readHeadTrace)
  double traceStart = 0.0;           // s into the trace where the dataset's first frame is
  double metresPerUnit = 0.125;      // scene units to metres: the capture's `k` (Cube 2: 0.125)
  double clearance = 0.15;           // m: the least distance kept between a head and a static surface
  FlythroughOptions body;            // the body's path (its rate is the poses' rate, its frameRate the dataset's)
};

struct VrCameraReport {
  FlythroughReport body;             // the path the body travels
  std::string traceSha256;           // of the trace file
  double traceStart = 0, traceSeconds = 0;  // s: where in the trace, and how much of it, the dataset uses
  double headingTurn = 0;            // degrees: the turn that put the trace's starting heading onto the path's
  std::size_t poses = 0;
  std::size_t clamped = 0;           // poses whose offset a wall cut short
  std::size_t shrunk = 0;            // poses whose offset was shrunk because a chord crossed a wall
  double meanOffset = 0, maxOffset = 0;  // m: the head's distance from the body, as written
};

// The head's poses as a merge-camera CSV pose log, at options.body.rate poses a second.
Expected<VrCameraReport> writeVrCameraCsv(const std::filesystem::path& dataset, const std::filesystem::path& csv,
                                          const VrCameraOptions& options);

// The VR camera as a dataset: the CSV merged into a copy of `dataset` (merge-camera), then that
// dataset's camera measured as `stats` measures it (Tables 6.4-6.6 at options.body.frameRate).
struct VrCameraDataset {
  VrCameraReport report;
  metrics::CameraMotionSummary motion;  // scene units and degrees per frame
};
Expected<VrCameraDataset> makeVrCameraDataset(const std::filesystem::path& dataset, const std::filesystem::path& output,
                                              const std::filesystem::path& csv, const VrCameraOptions& options);
// One line for logs.
std::string describe(const VrCameraReport& report);
// The `vr-camera --json` document (docs/cli.md).
nlohmann::json vrCameraJson(const VrCameraDataset& made, const std::filesystem::path& dataset, const std::filesystem::path& output,
                            const std::filesystem::path& csv, const VrCameraOptions& options);

}  // namespace dynbench::camera
