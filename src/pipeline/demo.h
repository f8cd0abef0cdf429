#pragma once
// `dynbench demo`: the whole chain on a seeded Cube 2 bot match. Capture, convert, a smooth
// fly-through of the same match as a second dataset (the contrast the thesis found against
// the ORCA fly-throughs), then per dataset stats, render, discard, and one report.
#include <filesystem>
#include <functional>
#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench::demo {

// What one run of the demo does: all of it, or one part of `demo --slurm`'s chain (each part reuses
// what the parts before it made).
enum class DemoPart {
  kAll,         // capture, convert, fly-through, then stats, render, discard, evaluate and report
  kDatasets,    // capture, convert and fly-through only
  kRenderTask,  // only task renderTask's frames of the renders (framesPerTask frame renders a task)
};

struct DemoOptions {
  std::filesystem::path output = "dynbench-demo";
  std::string map = "colos";
  int bots = 6;
  double seconds = 10.0;  // game time captured
  unsigned seed = 1;
  double fps = 24.0;      // stats, render and discard sample the datasets at this rate
  // Converged feature buffers (render --converge) of a window of renderFrames consecutive frames
  // in the middle of the match, at a resolution two cores render in about two minutes a dataset:
  // fewer pixels rather than less convergence, so Table 6.7 describes the match, not the noise.
  int width = 96, height = 54, samplesPerPixel = 16, bounces = 2;
  double tolerance = 0.5;
  int maxSamplesPerPixel = 512;
  int renderFrames = 48;
  // Temporal methods evaluated on each dataset: the window rendered again at this many samples per
  // pixel (the input a real-time method gets), scored against the converged frames.
  int inputSamplesPerPixel = 4;
  std::vector<std::string> methods{"none", "accumulate", "taa", "svgf"};
  int threads = 0;  // render threads (0: all cores)
  DemoPart part = DemoPart::kAll;
  int renderTask = 0, framesPerTask = 8;  // with kRenderTask
};

// The number of frame renders the demo makes (two datasets, reference and input, renderFrames
// each at most): what `demo --slurm` divides among its render tasks.
inline int demoFrameRenders(const DemoOptions& o) { return 2 * 2 * std::max(2, o.renderFrames); }

// One line per stage (for the terminal and logs).
using DemoLog = std::function<void(const std::string&)>;

// Returns the report's path (kAll), the fly-through dataset (kDatasets) or the output folder.
Expected<std::filesystem::path> runDemo(const DemoOptions& options, const DemoLog& log);

// The fly-through: the kind of camera the thesis compared against (the artist-placed paths of
// ORCA's Bistro and Emerald Square), over the same match. Its path is the bot's own longest
// stretch without a camera cut (so it stays where a player can be), smoothed by a moving average
// as wide as keeps every segment between consecutive poses out of static geometry; it is flown at
// constant speed over the dataset's whole duration, looking ahead along the path with gentle
// pitch, its heading smoothed until its turn rates are within ORCA's (Table 6.6).
struct FlythroughOptions {
  double rate = 60.0;           // poses per second in the CSV
  double metresPerUnit = 0.125;  // Cube 2: 8 units to the metre
  double speed = 2.5;           // m/s (ORCA's Table 6.4 rows: 0.3-3.7 m/s at 24 fps); less when the stretch is shorter
  double lookAhead = 4.0;       // m along the path
  double frameRate = 24.0;      // the rate the dataset is rendered at: its chords are checked, its turn rates bounded
  // Bounds on the per-frame yaw and pitch changes at frameRate (degrees, Table 6.6): the largest of
  // the thesis's three ORCA rows (yaw: Emerald Square's 0.511 and 0.095; pitch: Bistro Interior's
  // 0.053 and 0.004). The yaw's and the pitch's smoothing each widen until their two hold.
  double maxYawMean = 0.511, maxYawVariance = 0.095, maxPitchMean = 0.053, maxPitchVariance = 0.004;
};
struct FlythroughReport {
  double stretchStart = 0, stretchEnd = 0;  // s: the bot's cut-free stretch the path follows
  double stretchLength = 0, length = 0;     // scene units: the stretch, and the path flown
  double speed = 0;                         // scene units per second flown
  double smoothing = 0;                     // scene units: width of the path's moving average
  double headingWindow = 0, pitchWindow = 0;  // s: width of the yaw's and the pitch's moving averages
  // Per-frame changes at frameRate, degrees (Table 6.6's definitions, |wrapped difference|).
  double yawMean = 0, yawVariance = 0, pitchMean = 0, pitchVariance = 0;
  std::size_t poses = 0;
};
// Written as a merge-camera CSV pose log (time,x,y,z,qx,qy,qz,qw) at options.rate poses/s.
Expected<FlythroughReport> writeFlythroughCsv(const std::filesystem::path& dataset, const std::filesystem::path& csv,
                                              const FlythroughOptions& options = {});

}  // namespace dynbench::demo
