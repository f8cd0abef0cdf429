#pragma once
// A map's fitted lights are a property of its BSP: fitted once, kept in a cache folder under the
// BSP's SHA-256 and the fit's version, and read by every later capture of the map.
#include <filesystem>
#include <string>

#include "core/error.h"
#include "maplight/fit.h"

namespace dynbench::maplight {

// Bumped whenever the fit or the file's meaning changes, so that older cached files are not used.
// Version 9: point lights end at q3map2's envelope, by KHR's window (MapLight::range; 8: no end).
// Version 8: visibility traced by maplight/triangle_bvh.h, the same on every CPU (7: Embree).
inline constexpr int kFitVersion = 9;

// $XDG_CACHE_HOME/dynbench/map-lights, else $HOME/.cache/dynbench/map-lights.
std::filesystem::path defaultCacheFolder();

// The adapter lights file (writeAdapterLights) of `map` from the game's archives in `baseFolder`
// (e.g. /usr/lib/openarena/baseoa): the cached one, or a new fit written to the cache. An empty
// path when the archives have no such map (the game itself then says so).
Expected<std::filesystem::path> cachedAdapterLights(const std::filesystem::path& baseFolder, const std::string& map,
                                                    const std::filesystem::path& cacheFolder, const MapLightProgress& progress = {});

}  // namespace dynbench::maplight
