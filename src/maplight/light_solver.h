#pragma once
// The light fit's step 3b (maplight/fit.h): which candidates become lights, and how strong each
// light is. Non-negative least squares over the known groups (each with a weight, q3map2's strength
// being 1), the chosen candidates and a constant; candidates chosen greedily on luminance, then each
// moved off the lattice where that fits better. Internal to maplight.
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "maplight/fit.h"
#include "maplight/fit_visibility.h"
#include "maplight/lightmap_samples.h"
#include "maplight/q3map2_model.h"

namespace dynbench::maplight {

// A sparse column's product with a dense vector over all samples.
double dot(const Column& c, const std::vector<double>& dense);

// The chosen columns of the fit and their Gram matrix, kept as columns come and go (a column's
// products with the others are computed once), so a greedy step costs one pass over the candidates,
// not over the set squared. The unknowns are the chosen columns' weights and, last, a constant over
// the texel rows (bounced light and ambient in the lightmaps, which the fit absorbs and drops).
class LightSystem {
 public:
  // `columns` holds every column, the known groups' first (their colours `groupColors`), then the
  // candidates' (white); it may grow while the system lives. Of the `rows` samples, the first
  // `texelRows` are texels (the constant's rows), the rest light grid points.
  LightSystem(const std::vector<Column>& columns, std::size_t rows, std::size_t texelRows, std::vector<glm::dvec3> groupColors);

  std::size_t rows() const { return rows_; }
  std::size_t groupCount() const { return groupColors_.size(); }
  const std::vector<std::size_t>& chosen() const { return chosen_; }

  void add(std::size_t column);
  // Leaves out the chosen columns whose `drop` is set (indices into chosen()).
  void remove(const std::vector<char>& drop);
  // Chosen column `a` becomes column `column` (a light moved), its products computed again.
  void replace(std::size_t a, std::size_t column);

  // The weights of the chosen columns, then the constant, for target `y` in `channel` (3: luminance).
  std::vector<double> solve(const std::vector<double>& y, int channel) const;
  // y less the weighted columns and the constant, into `out`; returns its sum of squares.
  double residual(const std::vector<double>& y, const std::vector<double>& x, int channel, std::vector<double>& out) const;

 private:
  // The fit's own constant is over the texels alone.
  double texelSum(const Column& c) const;
  // A column's colour: its group's, white for a candidate. `channel` 3 is luminance.
  double colorOf(std::size_t column, int channel) const;

  const std::vector<Column>& columns_;
  std::size_t rows_, texelRows_;
  std::vector<glm::dvec3> groupColors_;
  std::vector<std::size_t> chosen_;            // column indices; the constant is the last unknown
  std::vector<std::vector<double>> gramRows_;  // gramRows_[a][b] = column a . column b, a, b in chosen (colourless)
  std::vector<double> columnSums_;             // column a . the constant's column of ones
  std::vector<double> dense_;                  // scratch: one column spread over all rows, else zero
};

// Candidates (columns after the groups') added greedily while each lowers the luminance residual
// by at least options.minimumGain of `signal`, up to options.maxLights; a candidate NNLS sets to 0
// leaves the set (it may be chosen again). `residual` and `error` are the system's as it comes in
// and are updated.
void chooseLights(LightSystem& system, const std::vector<Column>& columns, const std::vector<double>& target, double signal,
                  std::vector<double>& residual, double error, const MapLightFitOptions& options, const MapLightProgress& report);

// The lattice is coarse (up to ~170 units on large maps), so each fitted light then moves among its
// neighbours at half, a quarter, an eighth and a sixteenth of the lattice `spacing` (in open
// space), its weight re-solved in closed form with the others held, while that lowers the
// residual. A moved light's column and position are appended to `columns` and `candidates`.
// Returns the lights moved.
std::size_t refineLights(LightSystem& system, std::vector<Column>& columns, std::vector<glm::dvec3>& candidates, const std::vector<double>& target,
                         double spacing, const std::vector<Sample>& fit, const Occluders& occluders, const MapLightProgress& report);

// After the choice and the refinement, whose columns have no end: each chosen candidate ended at
// q3map2's envelope of its strength by KHR's window (MapLight::range), as the dataset renders it, and
// the weights solved again with the ended columns. The envelope follows the strength and the
// strength the window, so the two are solved in turns: kEndRounds of them (the envelope moves with
// the square root of the strength, which changes by a few per cent after the first). An ended
// column and its position are appended to `columns` and `candidates`. Returns each chosen column's
// range (as chosen(); 0 for the groups).
inline constexpr int kEndRounds = 3;
std::vector<double> endLights(LightSystem& system, std::vector<Column>& columns, std::vector<glm::dvec3>& candidates, const std::vector<Sample>& fit,
                              const Occluders& occluders, const MapLightProgress& report);

// Colours and strengths: the same set fitted per channel. A group's weight is the luminance fit's
// (its colour is the map's): its lights and surface lights in `lighting` are scaled by it (a
// two-sided emitter by its front's; the back's is reported). Each chosen candidate with light
// becomes a fitted light at its position, its colour its channels' ratio, its range `ranges`'. Returns the luminance
// fit's weights (the chosen columns', then the constant).
std::vector<double> setStrengths(const LightSystem& system, const std::vector<double>& target, const std::vector<Sample>& fit,
                                 const std::vector<EmitterGroup>& groups, const std::vector<glm::dvec3>& candidates,
                                 const std::vector<double>& ranges, MapLighting& lighting);

}  // namespace dynbench::maplight
