#pragma once
// An id Tech 3 game's data: the .pk3 (zip) archives of its base folder, searched as the engine
// searches them (ioquake3's FS_AddGameDirectory: the archives in name order, a later archive's file
// replacing an earlier one's). libzip is used in src/maplight/pak.cpp alone.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench::maplight {

class GameFiles {
 public:
  // The *.pk3 files of `baseFolder` (e.g. /usr/lib/openarena/baseoa). An error names the archive
  // that cannot be read.
  static Expected<GameFiles> open(const std::filesystem::path& baseFolder);
  ~GameFiles();
  GameFiles(GameFiles&&) noexcept;
  GameFiles& operator=(GameFiles&&) noexcept;

  bool contains(const std::string& path) const;
  // A file's bytes from the archive the engine would take it from (paths compare without case).
  Expected<std::string> read(const std::string& path) const;
  // The paths under `folder` ending in `suffix` (both without case), sorted, each once.
  std::vector<std::string> list(const std::string& folder, const std::string& suffix) const;
  // "pak1-maps.pk3": the archive a path comes from (for messages and the cache's key).
  std::string archiveOf(const std::string& path) const;

  struct Archive;

 private:
  GameFiles() = default;
  std::vector<std::unique_ptr<Archive>> archives_;
  // lower-case path -> (archive index, entry index)
  std::map<std::string, std::pair<std::size_t, long long>> entries_;
};

}  // namespace dynbench::maplight
