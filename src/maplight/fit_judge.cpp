#include "maplight/fit_judge.h"

#include <numeric>

#include "core/math.h"
#include "maplight/q3map2_model.h"

namespace dynbench::maplight {

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = a.size();
  if (n < 2) return 0.0;
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n, mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

void judgeRecovery(const Bsp& bsp, const std::vector<Sample>& fit, std::size_t knownLights, const Occluders& occluders, MapLighting& lighting) {
  // How much of the hidden lights' value has a fitted light near it.
  // Whether the lightmaps show a hidden light at all: q3map2's model of it gives at least one
  // lightmap unit (a byte at -gamma 1) on some fitted texel that is neither clipped nor at the
  // map's floor. Elsewhere the texels read the same with it or without it.
  const std::vector<MapLight> hidden = entityLights(bsp);
  std::vector<EmitterGroup> hiddenGroups;
  for (std::size_t i = 0; i < hidden.size(); ++i) hiddenGroups.push_back({hidden[i].source, hidden[i].color, {i}, {}});
  const std::vector<Column> hiddenColumns = groupColumns(fit, hiddenGroups, hidden, {}, occluders);
  double total = 0.0, found = 0.0, shown = 0.0, shownFound = 0.0;
  for (std::size_t h = 0; h < hidden.size(); ++h) {
    if (hidden[h].kind == MapLightKind::kSun) continue;
    total += hidden[h].value;
    bool inLightmaps = false;
    const Column& c = hiddenColumns[h];
    for (std::size_t k = 0; k < c.rows.size() && !inLightmaps; ++k)
      inLightmaps = !fit[c.rows[k]].floored && !fit[c.rows[k]].point && c.values[k] * luminance(hidden[h].color) >= kShownLightmapUnits;
    bool near = false;
    for (std::size_t i = knownLights; i < lighting.lights.size() && !near; ++i)
      near = glm::length(lighting.lights[i].position - hidden[h].position) <= kRecoveryRadius;
    found += near ? hidden[h].value : 0.0;
    shown += inLightmaps ? hidden[h].value : 0.0;
    shownFound += inLightmaps && near ? hidden[h].value : 0.0;
  }
  lighting.report.hiddenLightValue = total;
  lighting.report.recoveredShare = total > 0 ? found / total : 0.0;
  lighting.report.shownLightValue = shown;
  lighting.report.recoveredShownShare = shown > 0 ? shownFound / shown : 0.0;
}

void judgeLights(const std::vector<Sample>& heldOut, const std::vector<Sample>& gridSamples, const std::vector<EmitterGroup>& groups,
                 const std::vector<double>& weights, const MapLighting& unweighted, std::size_t knownLights, const Occluders& occluders,
                 MapLighting& lighting, const MapLightProgress& report) {
  const std::size_t groupCount = groups.size();
  // Judged on the held-out texels: the known emitters as q3map2 gives them, and the dataset's
  // lights (the known ones weighted, the fitted ones).
  report("held-out texels", 0, 1);
  std::vector<EmitterGroup> all = groups;
  std::vector<double> allWeights = weights;
  allWeights.resize(groupCount);
  for (std::size_t i = knownLights; i < lighting.lights.size(); ++i) {
    all.push_back({"fitted", lighting.lights[i].color, {i}, {}});
    allWeights.push_back(1.0);
  }
  std::vector<MapLight> heldLights = unweighted.lights;
  heldLights.insert(heldLights.end(), lighting.lights.begin() + static_cast<std::ptrdiff_t>(knownLights), lighting.lights.end());
  // The luminance q3map2's model gives each sample: of the known emitters alone (their strength as
  // q3map2 gives it), and of the dataset's lights (weighted, with the fitted ones).
  const auto modelLuminance = [&](const std::vector<Sample>& samples, std::vector<double>& knownLum, std::vector<double>& allLum) {
    const std::vector<Column> columnsHere = groupColumns(samples, all, heldLights, unweighted.surfaceLights, occluders);
    knownLum.assign(samples.size(), 0.0);
    allLum.assign(samples.size(), 0.0);
    for (std::size_t k = 0; k < all.size(); ++k) {
      const double lum = luminance(all[k].color);
      for (std::size_t q = 0; q < columnsHere[k].rows.size(); ++q) {
        const double v = columnsHere[k].values[q] * lum;  // q3map2's strength (a fitted light's own)
        allLum[columnsHere[k].rows[q]] += v * allWeights[k];
        if (k < groupCount) knownLum[columnsHere[k].rows[q]] += v;
      }
    }
  };
  std::vector<double> texel(heldOut.size()), knownLum, allLum;
  for (std::size_t i = 0; i < heldOut.size(); ++i) texel[i] = luminance(heldOut[i].value);
  modelLuminance(heldOut, knownLum, allLum);
  lighting.report.heldOutCorrelation = pearson(texel, allLum);
  lighting.report.knownCorrelation = pearson(texel, knownLum);
  const auto explained = [&](const std::vector<double>& model, double offset) {
    const double mean = std::accumulate(texel.begin(), texel.end(), 0.0) / static_cast<double>(texel.size());
    double total = 0, rest = 0;
    for (std::size_t i = 0; i < texel.size(); ++i) {
      total += (texel[i] - mean) * (texel[i] - mean);
      rest += (texel[i] - model[i] - offset) * (texel[i] - model[i] - offset);
    }
    return total > 0 ? 1.0 - rest / total : 0.0;
  };
  lighting.report.knownExplained = explained(knownLum, 0.0);
  lighting.report.totalExplained = explained(allLum, weights.back());
  report("held-out texels", 1, 1);

  // Judged on the light grid, which the fit never sees: q3map2's record of the same lights at
  // points of the map's open space, where players move (gridPointLight).
  std::vector<double> gridLum;
  for (const Sample& s : gridSamples) gridLum.push_back(luminance(s.value));
  lighting.report.gridPoints = gridSamples.size();
  if (gridSamples.size() >= 16) {
    report("light grid", 0, 1);
    modelLuminance(gridSamples, knownLum, allLum);
    lighting.report.gridCorrelation = pearson(gridLum, allLum);
    lighting.report.gridKnownCorrelation = pearson(gridLum, knownLum);
    report("light grid", 1, 1);
  }
}

}  // namespace dynbench::maplight
