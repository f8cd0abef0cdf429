#include "maplight/pak.h"

#include <algorithm>

#include <zip.h>

#include "core/files.h"

namespace dynbench::maplight {

struct GameFiles::Archive {
  std::filesystem::path path;
  zip_t* zip = nullptr;
  ~Archive() {
    if (zip) zip_discard(zip);
  }
};

GameFiles::~GameFiles() = default;
GameFiles::GameFiles(GameFiles&&) noexcept = default;
GameFiles& GameFiles::operator=(GameFiles&&) noexcept = default;

Expected<GameFiles> GameFiles::open(const std::filesystem::path& baseFolder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(baseFolder, ec))
    return fail(ErrorCode::kIo, "{}: not a folder (expected the game's base folder with its .pk3 archives)", baseFolder.string());
  std::vector<std::filesystem::path> paks;
  for (const auto& entry : std::filesystem::directory_iterator(baseFolder, ec))
    if (lowercaseExtension(entry.path()) == ".pk3") paks.push_back(entry.path());
  if (paks.empty()) return fail(ErrorCode::kIo, "{}: no .pk3 archives in it", baseFolder.string());
  std::sort(paks.begin(), paks.end());
  GameFiles files;
  for (const auto& path : paks) {
    int status = 0;
    zip_t* zip = zip_open(path.c_str(), ZIP_RDONLY, &status);
    if (!zip) {
      zip_error_t error;
      zip_error_init_with_code(&error, status);
      std::string message = zip_error_strerror(&error);
      zip_error_fini(&error);
      return fail(ErrorCode::kIo, "{}: cannot open it as a zip archive: {}", path.string(), message);
    }
    auto archive = std::make_unique<Archive>();
    archive->path = path;
    archive->zip = zip;
    const zip_int64_t count = zip_get_num_entries(zip, 0);
    for (zip_int64_t i = 0; i < count; ++i)
      if (const char* name = zip_get_name(zip, static_cast<zip_uint64_t>(i), 0))
        files.entries_[asciiLowercase(name)] = {files.archives_.size(), i};
    files.archives_.push_back(std::move(archive));
  }
  return files;
}

bool GameFiles::contains(const std::string& path) const { return entries_.contains(asciiLowercase(path)); }

std::string GameFiles::archiveOf(const std::string& path) const {
  const auto found = entries_.find(asciiLowercase(path));
  return found == entries_.end() ? std::string() : archives_[found->second.first]->path.filename().string();
}

Expected<std::string> GameFiles::read(const std::string& path) const {
  const auto found = entries_.find(asciiLowercase(path));
  if (found == entries_.end()) return fail(ErrorCode::kIo, "{}: not in the game's archives", path);
  const Archive& archive = *archives_[found->second.first];
  const auto index = static_cast<zip_uint64_t>(found->second.second);
  zip_stat_t stat;
  zip_stat_init(&stat);
  if (zip_stat_index(archive.zip, index, 0, &stat) != 0 || !(stat.valid & ZIP_STAT_SIZE))
    return fail(ErrorCode::kIo, "{}: {}: cannot read its size", archive.path.string(), path);
  zip_file_t* file = zip_fopen_index(archive.zip, index, 0);
  if (!file) return fail(ErrorCode::kIo, "{}: {}: cannot open it: {}", archive.path.string(), path, zip_strerror(archive.zip));
  std::string bytes(static_cast<std::size_t>(stat.size), '\0');
  const zip_int64_t got = zip_fread(file, bytes.data(), stat.size);
  zip_fclose(file);
  if (got < 0 || static_cast<zip_uint64_t>(got) != stat.size)
    return fail(ErrorCode::kIo, "{}: {}: read {} of {} bytes", archive.path.string(), path, got, stat.size);
  return bytes;
}

std::vector<std::string> GameFiles::list(const std::string& folder, const std::string& suffix) const {
  const std::string prefix = asciiLowercase(folder), end = asciiLowercase(suffix);
  std::vector<std::string> paths;
  for (auto it = entries_.lower_bound(prefix); it != entries_.end() && it->first.starts_with(prefix); ++it)
    if (it->first.size() >= end.size() && it->first.ends_with(end)) paths.push_back(it->first);
  return paths;
}

}  // namespace dynbench::maplight
