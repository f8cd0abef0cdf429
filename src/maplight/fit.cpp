// fitMapLighting: the steps fit.h lists, in order, each in the file named after it:
//   1. samples: lightmap_samples.h (the texels and the light grid's points),
//   2. the known emitters and q3map2's model of their light: known_emitters.h, q3map2_model.h
//      (visibility: fit_visibility.h),
//   3. candidates (fit_candidates.h) and the greedy non-negative fit (light_solver.h),
//   4. the judging (fit_judge.h).
#include "maplight/fit.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/parallel_for.h>

#include "core/math.h"
#include "maplight/fit_candidates.h"
#include "maplight/fit_judge.h"
#include "maplight/fit_visibility.h"
#include "maplight/known_emitters.h"
#include "maplight/light_solver.h"
#include "maplight/lightmap_samples.h"
#include "maplight/q3map2_model.h"

namespace dynbench::maplight {

namespace {

// The lightmaps' signal, the texels' luminance variance (times their count): it sets when the
// greedy fit stops, the grid's rows or not.
double texelSignal(const std::vector<double>& target, std::size_t texelRows) {
  double signal = 0.0;
  const auto texelsEnd = target.begin() + static_cast<std::ptrdiff_t>(texelRows);
  const double mean = std::accumulate(target.begin(), texelsEnd, 0.0) / static_cast<double>(texelRows);
  for (auto t = target.begin(); t != texelsEnd; ++t) signal += (*t - mean) * (*t - mean);
  return signal;
}

}  // namespace

Expected<MapLighting> fitMapLighting(const GameFiles& files, const std::string& map, const MapLightFitOptions& options,
                                     const MapLightProgress& progress) {
  const MapLightProgress report = [&](const std::string& step, std::size_t done, std::size_t total) {
    if (progress) progress(step, done, total);
  };
  const std::string path = "maps/" + map + ".bsp";
  auto bytes = files.read(path);
  if (!bytes) return std::unexpected(bytes.error());
  auto bsp = parseBsp(*bytes, files.archiveOf(path) + ":" + path);
  if (!bsp) return std::unexpected(bsp.error());
  auto scripts = ShaderScripts::read(files);
  if (!scripts) return std::unexpected(scripts.error());
  const Occluders occluders = buildOccluders(*bsp, *scripts);

  MapLighting result;
  result.map = map;
  MapLightFitReport& r = result.report;
  r.gamma = gammaOf(*bsp);

  // 2a. The known emitters, in groups: each light entity, each sun, each surface-light shader.
  std::vector<EmitterGroup> groups = knownEmitters(*bsp, *scripts, files, options.hideEntityLights, result);

  // 1. The lightmap texels (the fit's and the judge's samples are regular subsets of them, below).
  r.floorBytes = minimumLightBytes(*bsp, r.gamma);
  const LightmapTexels texels = lightmapTexels(*bsp, *scripts, r.gamma, r.floorBytes);
  r.texels = texels.texels;
  r.clippedTexels = texels.clipped;
  r.flooredTexels = texels.floored;

  // The light grid as fit data, on the lattice's even points (the odd ones judge the lights below).
  // Its directed light has no floor and each point says where its light mainly comes from, so it
  // shows lights a lightmap floor hides. Where the lightmaps are not floored they are the better
  // data: fitted on every map, the grid cost oa_dm3 (0.914 -> 0.878 held out, 256 lights, 3 min)
  // and oa_bases3's recovery (96 -> 87 %); integrations/openarena/README.md has the figures.
  const LightGrid& grid = bsp->lightGrid;
  const bool floorHidesMost = 2 * texels.floored > texels.texels;
  r.gridFitted = options.gridFit == GridFit::kAlways || (options.gridFit == GridFit::kWhereFloored && floorHidesMost);
  const std::vector<Sample> gridRows = r.gridFitted ? gridFitRows(grid, options.gridFitSamples, r.floorBytes, r.gamma) : std::vector<Sample>{};
  // The grid's bounced light takes a constant of its own: a group with no emitters, its column set below.
  const std::size_t gridConstant = groups.size();
  if (!gridRows.empty()) groups.push_back({"the light grid's bounced light (a constant)", glm::dvec3(1.0), {}, {}});
  const std::size_t knownLights = result.lights.size(), groupCount = groups.size();

  const int stride =
      std::max(2, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(texels.texels) / std::max(options.fitSamples, 1)))));
  std::vector<Sample> fit = texelSubset(texels.unclipped, stride, 0);
  const std::vector<Sample> heldOut = texelSubset(texels.unclipped, stride, stride / 2);
  r.fitSamples = fit.size();
  const std::size_t texelRows = fit.size();  // the texels come first, then the grid's points
  fit.insert(fit.end(), gridRows.begin(), gridRows.end());
  r.gridFitPoints = gridRows.size();
  r.heldOutSamples = heldOut.size();
  if (texelRows < 16) return fail(ErrorCode::kUnsupported, "{}: {} lightmap texels to fit; the map has no lightmaps to recover lights from", path, texelRows);

  // 2b. The known emitters' light at the samples, q3map2's model.
  report("known emitters", 0, 1);
  std::vector<Column> columns = groupColumns(fit, groups, result.lights, result.surfaceLights, occluders);
  if (!gridRows.empty()) {
    Column& c = columns[gridConstant];
    for (std::size_t i = texelRows; i < fit.size(); ++i) {
      c.rows.push_back(static_cast<std::uint32_t>(i));
      c.values.push_back(1.0f);
    }
    c.norm2 = static_cast<double>(gridRows.size());
  }
  report("known emitters", 1, 1);

  // 3. The fit, on luminance: the known groups and the constant first.
  std::vector<glm::dvec3> groupColors;
  for (const EmitterGroup& g : groups) groupColors.push_back(g.color);
  LightSystem system(columns, fit.size(), texelRows, std::move(groupColors));
  std::vector<double> target(fit.size()), residual;
  for (std::size_t i = 0; i < fit.size(); ++i) target[i] = luminance(fit[i].value);
  const double signal = texelSignal(target, texelRows);
  for (std::size_t k = 0; k < groupCount; ++k) system.add(k);
  const double error = system.residual(target, system.solve(target, 3), 3, residual);

  // 3a. Candidates and their columns, after the groups': the lattice, then the residual's hot spots.
  std::vector<glm::dvec3> candidates = openSpaceLattice(*bsp, occluders, options.maxCandidates, r.latticeSpacing);
  r.latticeCandidates = candidates.size();
  if (options.hotSpotPeaks > 0) {
    const std::vector<glm::dvec3> hot = hotSpotCandidates(fit, residual, occluders, static_cast<std::size_t>(options.hotSpotPeaks));
    candidates.insert(candidates.end(), hot.begin(), hot.end());
  }
  r.candidates = candidates.size();
  columns.resize(groupCount + candidates.size());
  std::atomic<std::size_t> done{0};
  tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t j) {
    columns[groupCount + j] = candidateColumn(candidates[j], fit, occluders, std::numeric_limits<double>::infinity());
    const std::size_t finished = ++done;
    if (finished % 64 == 0) report("candidate lights", finished, candidates.size());
  });
  report("candidate lights", candidates.size(), candidates.size());

  // 3b. Candidates chosen greedily, moved off the lattice, ended at their envelopes, and the weights
  // solved together again.
  chooseLights(system, columns, target, signal, residual, error, options, report);
  if (options.refine)
    r.refinedLights = refineLights(system, columns, candidates, target, static_cast<double>(r.latticeSpacing), fit, occluders, report);
  const std::vector<double> ranges = endLights(system, columns, candidates, fit, occluders, report);
  MapLighting unweighted;  // q3map2's own strengths, for judging the fit on held-out texels below
  unweighted.lights = result.lights;
  unweighted.surfaceLights = result.surfaceLights;
  const std::vector<double> weights = setStrengths(system, target, fit, groups, candidates, ranges, result);
  r.fittedLights = result.lights.size() - knownLights;
  // The known point lights end as the dataset ends them too (the lightmaps were baked with q3map2's
  // hard cut, which `unweighted` keeps): KHR's window at their envelope. A linear light is written
  // as the inverse-square light of its value (writeAdapterLights), so it takes that one's envelope.
  for (std::size_t i = 0; i < knownLights; ++i)
    if (result.lights[i].kind != MapLightKind::kSun) result.lights[i].range = inverseSquareEnvelope(result.lights[i].value);

  // 4. The judging, on what the fit never saw.
  if (options.hideEntityLights) judgeRecovery(*bsp, fit, knownLights, occluders, result);
  if (!options.judgeOnHeldOut) return result;
  // The grid's points that judge: none of those fitted; none empty, clipped or with the ambient at
  // the map's floor (_minlight raises the grid's ambient too).
  const std::vector<Sample> gridSamples = gridJudgeSamples(grid, r.gridFitted, options.gridSamples, r.floorBytes, r.gamma);
  judgeLights(heldOut, gridSamples, groups, weights, unweighted, knownLights, occluders, result, report);
  return result;
}

}  // namespace dynbench::maplight
