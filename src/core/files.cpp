#include "core/files.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

namespace dynbench {

Expected<std::string> readWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::kIo, "{}: cannot open: {}", path.string(), std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) return fail(ErrorCode::kIo, "{}: cannot read (not a regular file?)", path.string());
  std::string data(static_cast<std::size_t>(size), '\0');
  in.seekg(0, std::ios::beg);
  in.read(data.data(), size);
  if (!in) return fail(ErrorCode::kIo, "{}: read failed after {} bytes", path.string(), in.gcount());
  return data;
}

std::filesystem::path temporarySibling(const std::filesystem::path& path) {
  auto tmp = path;
  tmp += fmt::format(".tmp-{}", ::getpid());
  return tmp;
}

Expected<void> commitTemporary(const std::filesystem::path& temporary,
                               const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;  // not `ec`: the reason reported is the rename's
    std::filesystem::remove(temporary, ignored);
    return fail(ErrorCode::kIo, "{}: cannot move finished file into place: {}", path.string(),
                ec.message());
  }
  return {};
}

bool isNewerThan(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code e1, e2;
  const auto ta = std::filesystem::last_write_time(a, e1), tb = std::filesystem::last_write_time(b, e2);
  return !e1 && !e2 && ta > tb;
}

Expected<void> writeFileAtomic(const std::filesystem::path& path, std::string_view contents) {
  std::error_code ec;
  if (path.has_parent_path()) {
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot create folder: {}", path.parent_path().string(), ec.message());
  }
  const auto tmp = temporarySibling(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return fail(ErrorCode::kIo, "{}: cannot write: {}", tmp.string(), std::strerror(errno));
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      return fail(ErrorCode::kIo, "{}: write failed", tmp.string());
    }
  }
  return commitTemporary(tmp, path);
}

Expected<std::uint64_t> fileSize(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: {}", path.string(), ec.message());
  return static_cast<std::uint64_t>(size);
}

std::string asciiLowercase(std::string text) {
  // Not std::tolower, whose result depends on the C locale.
  for (char& c : text)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return text;
}

std::string lowercaseExtension(const std::filesystem::path& path) { return asciiLowercase(path.extension().string()); }

bool isExecutable(const std::filesystem::path& path) { return ::access(path.c_str(), X_OK) == 0; }

std::filesystem::path findOnPath(const std::string& name) {
  const char* env = std::getenv("PATH");
  const std::string dirs = env ? env : "/usr/bin:/bin";
  for (std::size_t start = 0; start <= dirs.size();) {
    const auto end = std::min(dirs.find(':', start), dirs.size());
    const std::filesystem::path candidate = std::filesystem::path(dirs.substr(start, end - start)) / name;
    if (isExecutable(candidate)) return candidate;
    start = end + 1;
  }
  return {};
}

namespace {

Expected<int> openLockFile(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return fail(ErrorCode::kIo, "{}: cannot open the lock file: {}", file.string(), std::strerror(errno));
  return fd;
}

}  // namespace

Expected<FileLock> FileLock::wait(const std::filesystem::path& file) {
  auto fd = openLockFile(file);
  if (!fd) return std::unexpected(fd.error());
  int status = 0;
  while ((status = ::flock(*fd, LOCK_EX)) != 0 && errno == EINTR) {}
  if (status != 0) {
    const int error = errno;
    ::close(*fd);
    return fail(ErrorCode::kIo, "{}: cannot lock: {}", file.string(), std::strerror(error));
  }
  return FileLock(*fd);
}

Expected<std::optional<FileLock>> FileLock::tryTake(const std::filesystem::path& file) {
  auto fd = openLockFile(file);
  if (!fd) return std::unexpected(fd.error());
  if (::flock(*fd, LOCK_EX | LOCK_NB) == 0) return std::optional<FileLock>(FileLock(*fd));
  const int error = errno;
  ::close(*fd);
  if (error == EWOULDBLOCK) return std::optional<FileLock>();
  return fail(ErrorCode::kIo, "{}: cannot lock: {}", file.string(), std::strerror(error));
}

void FileLock::note(std::string_view text) const {
  if (::ftruncate(descriptor_, 0) != 0 || ::pwrite(descriptor_, text.data(), text.size(), 0) < 0) {}  // a courtesy only
}

FileLock::FileLock(FileLock&& other) noexcept : descriptor_(std::exchange(other.descriptor_, -1)) {}

FileLock::~FileLock() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

}  // namespace dynbench
