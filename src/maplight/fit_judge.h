#pragma once
// The light fit's step 4 (maplight/fit.h): the lights judged on what the fit never saw: held-out
// lightmap texels and the map's light grid (luminance correlation with q3map2's model of them), and,
// with the map's light entities hidden, how many of them a fitted light found. Internal to maplight.
#include <cstddef>
#include <vector>

#include "maplight/bsp.h"
#include "maplight/fit.h"
#include "maplight/fit_visibility.h"
#include "maplight/known_emitters.h"
#include "maplight/lightmap_samples.h"

namespace dynbench::maplight {

// Pearson's correlation of two series of equal length (0 for fewer than 2 or a constant one).
double pearson(const std::vector<double>& a, const std::vector<double>& b);

// With the entity lights hidden: their total value (suns left out) and the share of it with a
// fitted light (lighting.lights from knownLights on) within kRecoveryRadius; the same of the
// hidden lights the fitted samples `fit` show (MapLightFitReport::shownLightValue).
void judgeRecovery(const Bsp& bsp, const std::vector<Sample>& fit, std::size_t knownLights, const Occluders& occluders, MapLighting& lighting);

// The known emitters as q3map2 gives them (`unweighted`: lighting's lights and surface lights before
// the fit's weights) and the dataset's lights (the groups weighted by `weights`, the constant last,
// and the fitted lights from knownLights on) against the held-out texels and the light grid's
// `gridSamples` (MapLightFitReport's correlations and explained shares).
void judgeLights(const std::vector<Sample>& heldOut, const std::vector<Sample>& gridSamples, const std::vector<EmitterGroup>& groups,
                 const std::vector<double>& weights, const MapLighting& unweighted, std::size_t knownLights, const Occluders& occluders,
                 MapLighting& lighting, const MapLightProgress& report);

}  // namespace dynbench::maplight
