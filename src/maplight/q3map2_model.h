#pragma once
// The light fit's step 2b (maplight/fit.h): q3map2's model of a light at the samples
// (light.c, LightContributionToSample and LightContributionToPoint), visibility included, as the
// sparse columns the fit solves with. Internal to maplight.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "maplight/fit.h"
#include "maplight/fit_visibility.h"
#include "maplight/known_emitters.h"
#include "maplight/lightmap_samples.h"

namespace dynbench::maplight {

// One emitter group's or candidate light's light at the samples it reaches: rows (sample indices)
// and values (lightmap units per unit colour), and the values' sum of squares.
struct Column {
  std::vector<std::uint32_t> rows;
  std::vector<float> values;
  double norm2 = 0.0;
};

// Every group's light at every sample (q3map2's model, lightmap units per unit colour, visibility
// included) as sparse columns.
std::vector<Column> groupColumns(const std::vector<Sample>& samples, const std::vector<EmitterGroup>& groups, const std::vector<MapLight>& lights,
                                 const std::vector<SurfaceEmitter>& surfaces, const Occluders& occluders);

// A candidate point light of V = 1 at `position`: its light at every sample, visibility included,
// ended by KHR's window at `range` (MapLight::range). Infinite: no end, for the choice of candidates,
// which comes before their strengths and so their envelopes are known (0 would be q3map2's envelope
// of V = 1, 87 units).
Column candidateColumn(const glm::dvec3& position, const std::vector<Sample>& samples, const Occluders& occluders, double range);

}  // namespace dynbench::maplight
