#include "convert/converter.h"

#include "core/files.h"

namespace dynbench::convert::detail {

std::string Converter::datasetReadme() const {
  const auto& s = reader_->settings();
  std::string licences;
  std::ifstream in(options_.capture / "LICENSES.txt");
  if (in) licences.assign(std::istreambuf_iterator<char>(in), {});
  std::string out = fmt::format("# {}\n\nA dynamic benchmark dataset for temporal rendering, made by dynbench {} (`dynbench convert`) "
                                "from a capture.\n\n", stem_, kVersion);
  out += fmt::format("- source: {}\n- capture: {}\n- map: {}\n", s.source.empty() ? "not stated" : s.source,
                     options_.capture.filename().string().empty() ? options_.capture.string() : options_.capture.filename().string(),
                     s.mapName.empty() ? "-" : s.mapName);
  out += fmt::format("- frames: {}, {:.3f} s to {:.3f} s\n", times_.size(), times_.front(), times_.back());
  out += fmt::format("- capturables: {}; nodes {}, meshes {}, skins {}, lights {}, animation channels {}\n", report_.capturables,
                     doc_["nodes"].size(), report_.meshes, report_.skins, report_.lights, report_.channels);
  out += fmt::format("- length unit: {} m\n", s.metresPerUnit);
  out += "\nLayout (thesis §5.1): WorldOrigo > StaticObjects (map, static map models, static lights) and DynamicObjects "
         "(cameras, rigid and skinned models, dynamic lights). Objects that appear and disappear are switched with "
         "KHR_node_visibility (STEP keys through KHR_animation_pointer) and, for meshes, a scale-0 STEP channel. "
         "See dynbench's docs/dataset.md.\n";
  out += "\n## Licences of the assets\n\n";
  out += licences.empty() ? "The capture states none (no LICENSES.txt in the capture directory). Check the licences of the "
                            "models and textures before publishing this dataset.\n"
                          : licences;
  return out;
}

// The environment image beside the dataset and the root extension that names it (docs/dataset.md).
Expected<json> Converter::environment() {
  json ext = {{"projection", "equirectangular"}, {"units", "cd/m2"}, {"intensity", 1.0}};
  fs::path target;
  if (options_.environment) {
    const std::string ext2 = lowercaseExtension(*options_.environment);
    if (ext2 != ".hdr" && ext2 != ".exr")
      return fail(ErrorCode::kUsage, "--env {}: expected an .hdr or .exr image", options_.environment->string());
    auto header = readImageHeader(*options_.environment);
    if (!header) return std::unexpected(header.error());
    if (header->width != 2 * header->height)
      report_.warnings.push_back(fmt::format("--env {}: {}x{} is not 2:1; is it equirectangular?", options_.environment->string(),
                                             header->width, header->height));
    target = outDir_ / (stem_ + "_environment" + ext2);
    std::error_code ec;
    fs::copy_file(*options_.environment, target, fs::copy_options::overwrite_existing, ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot copy the environment: {}", target.string(), ec.message());
    ext["source"] = options_.environment->filename().string();
  } else {
    const SkyImage& sky = *sky_;
    target = outDir_ / (stem_ + "_sky.hdr");
    if (auto ok = writeImage(target, FloatImage{sky.width, sky.height, 3, sky.rgb, {}, {}, {}}); !ok) return std::unexpected(ok.error());
    ext["source"] = "dynbench Preetham sky";
    ext["sky"] = {{"model", !skyParameters_.dome ? (skyParameters_.sunDisc ? "ESRA sun disc alone, no sky dome" : "black: no sky dome, no sun")
                            : skyParameters_.sunDisc ? "Preetham 1999 + ESRA sun"
                                                     : "Preetham 1999, no sun disc"},
                  {"turbidity", skyParameters_.turbidity}, {"sun_disc", skyParameters_.sunDisc},
                  {"sun_elevation_degrees", skyParameters_.sunElevationDegrees}, {"sun_azimuth_degrees", skyParameters_.sunAzimuthDegrees},
                  {"sun_direction", vec(sky.sunDirection)}, {"sun_illuminance_lux", sky.sunIlluminanceLux},
                  {"zenith_luminance_cd_m2", sky.zenithLuminance}};
  }
  ext["light_calibration"] = calibration_;  // how the lights' candela relate to this sky (docs/dataset.md)
  report_.written.push_back(target);
  ext["uri"] = uriPath(target.filename().string());
  return ext;
}

Expected<void> Converter::writeOutputs() {
  json document = doc_;
  auto environmentExtension = environment();
  if (!environmentExtension) return std::unexpected(environmentExtension.error());
  document["extensions"]["DYNBENCH_environment"] = std::move(*environmentExtension);
  if (!lights_.empty()) document["extensions"]["KHR_lights_punctual"] = {{"lights", lights_}};
  std::vector<std::string> used{"DYNBENCH_environment"};
  if (!lights_.empty()) used.push_back("KHR_lights_punctual");
  if (usesVisibility_) used.push_back("KHR_node_visibility");
  if (usesVisibility_ || usesAnimationPointer_) used.push_back("KHR_animation_pointer");
  if (usesEmissiveStrength_) used.push_back("KHR_materials_emissive_strength");
  if (!used.empty()) document["extensionsUsed"] = used;
  for (const char* key : {"images", "textures", "materials", "meshes", "skins"})
    if (document.contains(key) && document[key].empty()) document.erase(key);
  if (!document.contains("images")) document.erase("samplers");
  document["buffers"] = {{{"byteLength", report_.binBytes}}};
  report_.nodes = document["nodes"].size();
  report_.materials = document.contains("materials") ? document["materials"].size() : 0;
  report_.frames = times_.size();

  const fs::path readme = outDir_ / (stem_ + ".README.md");
  if (auto ok = writeFileAtomic(readme, datasetReadme()); !ok) return std::unexpected(ok.error());
  report_.written.push_back(readme);
  auto written = writeDataset(std::move(document), binPath_, report_.binBytes, options_.output, options_.glb);
  if (!written) return std::unexpected(written.error());
  report_.written.insert(report_.written.end(), written->begin(), written->end());
  return {};
}
}  // namespace dynbench::convert::detail
