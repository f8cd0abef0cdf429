#pragma once
// The light fit's step 3a (maplight/fit.h): where a fitted light may be. Candidates on a lattice in
// the map's open space, and along the normals of the residual's hot spots. Internal to maplight.
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "maplight/bsp.h"
#include "maplight/fit_visibility.h"
#include "maplight/lightmap_samples.h"

namespace dynbench::maplight {

// Whether a point lies in open space: at least kCandidateClearance from every surface, inside the map's
// sealed hull (rays in 14 directions all end on the front of a surface or on the sky).
bool inOpenSpace(const glm::dvec3& p, const Occluders& occluders);

// Lattice points in open space, the lattice as fine as maxCandidates allows.
std::vector<glm::dvec3> openSpaceLattice(const Bsp& bsp, const Occluders& occluders, int maxCandidates, std::size_t& spacing);

// Candidates where the lightmaps point at a light. A point light near a surface makes a hot spot
// at the foot of its perpendicular, so each peak of the residual (the texels less the known
// emitters and the constant) gets candidates along its normal. The lattice alone misses lights in
// spaces about as narrow as its spacing: oa_ctf2's dim lights (value 60) hang in corridors where
// its 64-unit-clear band holds few lattice points. Peaks: the samples in falling order of residual,
// each at least kPeakSeparation from every brighter one, down to a quarter of full light.
std::vector<glm::dvec3> hotSpotCandidates(const std::vector<Sample>& samples, const std::vector<double>& residual, const Occluders& occluders,
                                          std::size_t maxPeaks);

}  // namespace dynbench::maplight
