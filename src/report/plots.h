#pragma once
// Camera rotation plots drawn by gnuplot (Debian gnuplot-nox): the thesis's Figure A.1 (change in
// pitch, yaw and roll per frame) and Figure A.2 (geodesic change in rotation per frame), each as
// PNG and SVG. gnuplot is the one place this module talks to; its errors come back as Error.
#include <filesystem>
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

Expected<std::vector<std::filesystem::path>> writeDiscardPlot(const std::vector<discard::FramePercentages>& frames,
                                                              const std::string& title, const std::filesystem::path& dir,
                                                              const std::string& stem);

}  // namespace dynbench::report
