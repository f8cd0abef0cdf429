#include "maplight/cache.h"

#include <cstdlib>

#include "core/checksum.h"
#include "core/files.h"

namespace dynbench::maplight {

std::filesystem::path defaultCacheFolder() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "dynbench" / "map-lights";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "dynbench" / "map-lights";
  return std::filesystem::temp_directory_path() / "dynbench-map-lights";
}

Expected<std::filesystem::path> cachedAdapterLights(const std::filesystem::path& baseFolder, const std::string& map,
                                                    const std::filesystem::path& cacheFolder, const MapLightProgress& progress) {
  auto files = GameFiles::open(baseFolder);
  if (!files) return std::unexpected(files.error());
  const std::string path = "maps/" + map + ".bsp";
  if (!files->contains(path)) return std::filesystem::path();
  auto bytes = files->read(path);
  if (!bytes) return std::unexpected(bytes.error());
  const auto file = cacheFolder / fmt::format("{}-{}-v{}.txt", map, sha256Text(*bytes).substr(0, 16), kFitVersion);
  std::error_code ec;
  if (std::filesystem::is_regular_file(file, ec)) return file;
  std::filesystem::create_directories(cacheFolder, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create the map-light cache folder: {}", cacheFolder.string(), ec.message());
  // One fit per map at a time: a second process that needs the same map (two captures of it, Slurm
  // tasks on one node) waits for the first's file instead of fitting it again beside it.
  const auto lock = FileLock::wait(std::filesystem::path(file).concat(".lock"));
  if (!lock) return std::unexpected(lock.error());
  if (std::filesystem::is_regular_file(file, ec)) return file;
  MapLightFitOptions options;
  options.judgeOnHeldOut = false;  // the file holds the lights alone
  auto lighting = fitMapLighting(*files, map, options, progress);
  if (!lighting) return std::unexpected(lighting.error());
  if (auto written = writeAdapterLights(file, *lighting); !written) return std::unexpected(written.error());
  return file;
}

}  // namespace dynbench::maplight
