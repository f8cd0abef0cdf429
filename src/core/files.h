#pragma once
// File helpers: whole-file reads and atomic writes (temporary name, then rename), so that an
// interrupted run never leaves a half-written output that looks complete.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"

namespace dynbench {

Expected<std::string> readWholeFile(const std::filesystem::path& path);

// Writes `contents` to `<path>.tmp-<pid>` and renames it over `path`. Creates parent folders.
Expected<void> writeFileAtomic(const std::filesystem::path& path, std::string_view contents);
// Whether `a` and `b` both exist and `a` was modified after `b` (an output newer than its source).
bool isNewerThan(const std::filesystem::path& a, const std::filesystem::path& b);

// Size in bytes, or an error naming the file.
Expected<std::uint64_t> fileSize(const std::filesystem::path& path);

// A temporary sibling name for `path` for writers that cannot go through writeFileAtomic.
std::filesystem::path temporarySibling(const std::filesystem::path& path);

// Moves a finished temporary file into place.
Expected<void> commitTemporary(const std::filesystem::path& temporary,
                               const std::filesystem::path& path);

// `text` with A-Z as a-z and every other byte kept: for names the formats compare without case,
// in ASCII (file extensions; id Tech 3's paths, shader names and entity values).
std::string asciiLowercase(std::string text);
// The extension of `path` (with its dot), in lower case: ".gltf" for "Map.GLTF".
std::string lowercaseExtension(const std::filesystem::path& path);

// An advisory lock (flock(2)) on a file, held until the object goes or the process ends, however
// it ends (a SIGKILL too: the kernel drops it with the descriptor). Each FileLock opens the file
// anew, so two exclude each other in one process as in two.
class FileLock {
 public:
  // Waits until no other process holds `file` (created if missing; its folder must exist).
  static Expected<FileLock> wait(const std::filesystem::path& file);
  // The lock if no other process holds it, std::nullopt if one does.
  static Expected<std::optional<FileLock>> tryTake(const std::filesystem::path& file);
  // Replaces the file's contents with `text` (who holds it, for another process's message).
  void note(std::string_view text) const;

  FileLock(FileLock&& other) noexcept;
  FileLock& operator=(FileLock&&) = delete;
  ~FileLock();

 private:
  explicit FileLock(int descriptor) : descriptor_(descriptor) {}
  int descriptor_ = -1;
};

// True when `path` names a file this process may execute.
bool isExecutable(const std::filesystem::path& path);
// `name` looked up in $PATH (as a shell would); empty when it is not there.
std::filesystem::path findOnPath(const std::string& name);

}  // namespace dynbench
