#pragma once
// SHA-256 of files, for the suite's record of every dataset and frame (`suite verify`). OpenSSL's
// libcrypto (Debian libssl-dev) computes it; this is the one place dynbench talks to it.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

namespace dynbench {

// One SHA-256 fed in parts (OpenSSL's EVP interface), for data too large to hold at once.
class Sha256Stream {
 public:
  Sha256Stream();
  ~Sha256Stream();
  Sha256Stream(const Sha256Stream&) = delete;
  Sha256Stream& operator=(const Sha256Stream&) = delete;
  void update(const void* bytes, std::size_t size);
  // The digest as 64 lower-case hex digits; empty when OpenSSL failed on the way. Ends the stream.
  std::string hex();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The file's SHA-256 as 64 lower-case hex digits; an error names the file.
Expected<std::string> sha256File(const std::filesystem::path& path);

// The SHA-256 of bytes, as 64 lower-case hex digits (empty only if OpenSSL itself fails).
std::string sha256Text(std::string_view bytes);

// The SHA-256 of a set of files under `root` as `sha256sum` lists them: the digest of the text of
// one line "<file's SHA-256>  <path relative to root, '/'-separated>\n" per file, in the byte
// order of the paths. So `(cd ROOT && LC_ALL=C sort FILE-LIST | xargs -d '\n' sha256sum) | sha256sum`
// gives the same digest. An error names the first file that cannot be read.
Expected<std::string> sha256Listing(const std::filesystem::path& root, std::vector<std::string> relativePaths);

}  // namespace dynbench
