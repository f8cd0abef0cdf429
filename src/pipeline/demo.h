#pragma once
// `dynbench demo`: the whole chain on a seeded Cube 2 bot match. Capture, convert, a smooth
// fly-through of the same match as a second dataset (the contrast the thesis found against
// the ORCA fly-throughs), then per dataset stats, render, discard, and one report.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench::demo {

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
  int flythroughKeys = 4;  // key points of the fly-through's spline
  // Temporal methods evaluated on each dataset: the window rendered again at this many samples per
  // pixel (the input a real-time method gets), scored against the converged frames.
  int inputSamplesPerPixel = 4;
  std::vector<std::string> methods{"none", "accumulate", "taa", "svgf"};
};

// One line per stage (for the terminal and logs).
using DemoLog = std::function<void(const std::string&)>;

// Returns the report's path.
Expected<std::filesystem::path> runDemo(const DemoOptions& options, const DemoLog& log);

// A smooth fly-through over the camera path of `dataset`: a Catmull-Rom spline through `keys`
// of its camera positions, evenly spaced in time, level, turning towards the spline's horizontal
// direction at most 30 degrees per second. Written as a merge-camera CSV pose log (time,x,y,z,qx,qy,qz,qw) at `rate` poses/s.
Expected<void> writeFlythroughCsv(const std::filesystem::path& dataset, const std::filesystem::path& csv, int keys, double rate);

}  // namespace dynbench::demo
