#pragma once
// Camera rotation plots drawn by gnuplot (Debian gnuplot-nox): the thesis's Figure A.1 (change in
// pitch, yaw and roll per frame) and Figure A.2 (geodesic change in rotation per frame), each as
// PNG and SVG. gnuplot is the one place this module talks to; its errors come back as Error.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "discard/discard.h"
#include "metrics/camera_motion.h"

namespace dynbench::report {

// Writes <dir>/<stem>_rotation_per_axis.{png,svg} (A.1) and <dir>/<stem>_rotation_geodesic.{png,svg}
// (A.2). Returns the paths written.
Expected<std::vector<std::filesystem::path>> writeRotationPlots(const metrics::CameraMotion& motion,
                                                                const std::string& title,
                                                                const std::filesystem::path& dir,
                                                                const std::string& stem);

// Figures A.1 and A.2 from a camera series CSV as `dynbench stats --series` writes it.
Expected<std::vector<std::filesystem::path>> writeRotationPlotsFromCsv(const std::string& csv, const std::string& title,
                                                                       const std::filesystem::path& dir, const std::string& stem);

// Writes <dir>/<stem>_discard.{png,svg}: the per-frame discard percentages of each feature.
// Per-frame ꟻLIP of every dataset's temporal methods on one axis (x: the frame's position in its
// dataset's window, so datasets of different frame numbers line up). `series`: (label, values).
Expected<std::vector<std::filesystem::path>> writeMethodsPlot(const std::vector<std::pair<std::string, std::vector<double>>>& series,
                                                              const std::filesystem::path& dir, const std::string& stem);

// Every dataset on the same axes (the report's comparison section): `name`, its per-frame geodesic
// rotation with cut frames left out (NaN), its per-frame discard, and its Table 6.7 mean; published
// rows have only the mean (and no intervals).
struct ComparisonSeries {
  std::string name;
  std::vector<double> rotation;                      // degrees per frame; NaN: no value (cut, frame 0)
  std::vector<discard::FramePercentages> discard;    // per frame
  std::optional<discard::FramePercentages> mean;     // Table 6.7
  bool published = false;
};
// Writes <dir>/<stem>_rotation, _rotation_cdf, _discard and _table67 (.png and .svg): rotation per
// frame overlaid, its cumulative distribution, each feature's discard per frame overlaid (one panel
// per feature), and Table 6.7 as grouped bars with the radiance columns' 95 % intervals. Figures
// whose data no series has are skipped. Returns the PNGs written, in that order.
Expected<std::vector<std::filesystem::path>> writeComparisonPlots(const std::vector<ComparisonSeries>& series,
                                                                  const std::filesystem::path& dir, const std::string& stem);

// A scatter plot's point: one dataset.
struct ScatterPoint {
  std::string label;
  double x = 0, y = 0;
};
// Writes <dir>/<stem>.png and .svg: the points, each labelled, on axes xLabel and yLabel.
Expected<std::vector<std::filesystem::path>> writeScatterPlot(const std::vector<ScatterPoint>& points, const std::string& xLabel,
                                                              const std::string& yLabel, const std::string& title,
                                                              const std::filesystem::path& dir, const std::string& stem);

Expected<std::vector<std::filesystem::path>> writeDiscardPlot(const std::vector<discard::FramePercentages>& frames,
                                                              const std::string& title, const std::filesystem::path& dir,
                                                              const std::string& stem);

}  // namespace dynbench::report
