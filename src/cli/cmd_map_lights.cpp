// `dynbench map-lights MAP`: an id Tech 3 map's static lights, the ones its BSP names and the
// stripped ones fitted to its lightmaps (src/maplight/fit.h), with how well they reproduce them.
#include <memory>

#include "cli/commands.h"
#include "core/progress.h"
#include "maplight/fit.h"

namespace dynbench::cli {
namespace {

struct MapLightsCli {
  std::string map, data = "/usr/lib/openarena/baseoa", adapterLights, gridFit = "where-floored";
  bool hideEntityLights = false;
  maplight::MapLightFitOptions options;
};

Expected<void> runMapLights(const MapLightsCli& cli) {
  auto files = maplight::GameFiles::open(cli.data);
  if (!files) return std::unexpected(files.error());
  maplight::MapLightFitOptions options = cli.options;
  options.hideEntityLights = cli.hideEntityLights;
  options.gridFit = cli.gridFit == "always" ? maplight::GridFit::kAlways : cli.gridFit == "never" ? maplight::GridFit::kNever : maplight::GridFit::kWhereFloored;
  std::unique_ptr<Progress> bar;
  auto lighting = maplight::fitMapLighting(*files, cli.map, options, stepProgress("map-lights", bar));
  bar.reset();
  if (!lighting) return std::unexpected(lighting.error());
  const auto& r = lighting->report;
  fmt::print("{}: {} lightmap texels ({} clipped, at 254 or 255, left out), gamma {}\n", cli.map, r.texels, r.clippedTexels, r.gamma);
  if (r.floorBytes != glm::dvec3(0.0))
    fmt::print("  {} texels at the map's _minlight floor (bytes {} {} {}), fitted as they read\n", r.flooredTexels, r.floorBytes.r,
               r.floorBytes.g, r.floorBytes.b);
  fmt::print("  known emitters: {} light entities, {} suns, {} surface-light pieces; {} shaders with q3map_skylight (not modelled)\n",
             r.entityLights, r.suns, r.surfaceEmitters, r.skyLightShaders);
  fmt::print("  fit: {} texels, {} candidates ({} on a {}-unit lattice, {} at hot spots), {} lights fitted ({} moved off the lattice), constant {:.2f} {:.2f} {:.2f} (dropped)\n",
             r.fitSamples, r.candidates, r.latticeCandidates, r.latticeSpacing, r.candidates - r.latticeCandidates, r.fittedLights, r.refinedLights, r.constant.r, r.constant.g, r.constant.b);
  if (r.gridFitted)
    fmt::print("  light grid: {} points (the lattice's even half) fitted beside the texels, the directed light alone where the ambient is clipped or at the floor\n",
               r.gridFitPoints);
  if (!options.judgeOnHeldOut) {
    fmt::print("  not judged (--no-judge): no held-out texel or light grid figures\n");
  } else {
    fmt::print("  held-out texels ({}): correlation {:.3f} (known emitters alone {:.3f}); variance explained {:.3f} (known alone {:.3f})\n",
               r.heldOutSamples, r.heldOutCorrelation, r.knownCorrelation, r.totalExplained, r.knownExplained);
    if (r.gridPoints > 0)
      fmt::print("  light grid ({} points{}): correlation {:.3f} (known emitters alone {:.3f})\n", r.gridPoints,
                 r.gridFitPoints > 0 ? ", the lattice's other half, not fitted" : ", never fitted", r.gridCorrelation, r.gridKnownCorrelation);
    else
      fmt::print("  light grid: no usable points (none, or every one clipped or at the floor)\n");
  }
  if (cli.hideEntityLights)
    fmt::print("  hidden entity lights: {:.0f} of light value, {:.1f} % of it with a fitted light within {} units; the lightmaps show {:.0f} of it "
               "(at least {} unit on a texel neither clipped nor at the floor), {:.1f} % of that recovered\n",
               r.hiddenLightValue, 100.0 * r.recoveredShare, maplight::kRecoveryRadius, r.shownLightValue, maplight::kShownLightmapUnits,
               100.0 * r.recoveredShownShare);
  for (const auto& [name, weight] : r.groupWeights) fmt::print("  {}: weight {:.3f}\n", name, weight);
  if (!cli.adapterLights.empty())
    if (auto written = maplight::writeAdapterLights(cli.adapterLights, *lighting); !written) return written;
  return {};
}

}  // namespace

StepProgress stepProgress(const std::string& label, std::unique_ptr<Progress>& bar) {
  return [&bar, label, step = std::string()](const std::string& s, std::size_t done, std::size_t total) mutable {
    if (s != step) {
      bar = std::make_unique<Progress>(label + ": " + s, total, "");
      step = s;
    }
    bar->update(done);
  };
}

void addMapLightsCommand(CLI::App& app, CommandRun& run) {
  auto cli = std::make_shared<MapLightsCli>();
  auto* cmd = app.add_subcommand("map-lights", "An id Tech 3 map's static lights: those its BSP names and the stripped ones fitted to its lightmaps");
  cmd->footer("Example: dynbench map-lights oa_dm1\n         dynbench map-lights kaos --hide-entity-lights   (how well the fit recovers the map's real lights)");
  cmd->add_option("MAP", cli->map, "The map's name (maps/MAP.bsp in the game's archives)")->required();
  cmd->add_option("--data", cli->data, "The game's base folder with its .pk3 archives")->capture_default_str();
  cmd->add_flag("--hide-entity-lights", cli->hideEntityLights, "Fit without the map's light entities (to measure recovery)");
  cmd->add_option("--max-lights", cli->options.maxLights, "Fitted lights at most")->capture_default_str()->check(CLI::Range(0, 4096));
  cmd->add_option("--minimum-gain", cli->options.minimumGain, "Stop when a light explains less than this share of the signal")->capture_default_str();
  cmd->add_option("--fit-samples", cli->options.fitSamples, "Lightmap texels fitted")->capture_default_str();
  cmd->add_option("--max-candidates", cli->options.maxCandidates, "Candidate light positions on the lattice at most")->capture_default_str();
  cmd->add_option("--hot-spot-peaks", cli->options.hotSpotPeaks, "Peaks of the lightmaps' residual that add candidates along their normals (0: the lattice alone)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--grid-samples", cli->options.gridSamples, "Light grid points the lights are judged on at most")->capture_default_str()->check(CLI::Range(16, 1000000));
  cmd->add_flag("!--no-judge", cli->options.judgeOnHeldOut,
                "Fit only, as a capture's cached fit does: no held-out or light grid figures (the same lights, about a fifth less time)");
  cmd->add_option("--grid-fit", cli->gridFit, "When the light grid is fit data beside the lightmaps: where the map's lightmap floor hides most texels, never, always")
      ->capture_default_str()
      ->check(CLI::IsMember({"where-floored", "never", "always"}));
  cmd->add_option("--adapter-lights", cli->adapterLights, "Write the lights file the OpenArena capture adapter reads");
  cmd->callback([cli, &run] { run = [cli] { return runMapLights(*cli); }; });
}

}  // namespace dynbench::cli
