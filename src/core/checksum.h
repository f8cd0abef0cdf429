#pragma once
// SHA-256 of files, for the suite's record of every dataset and frame (`suite verify`). OpenSSL's
// libcrypto (Debian libssl-dev) computes it; this is the one place dynbench talks to it.
#include <filesystem>
#include <string>

#include "core/error.h"

namespace dynbench {

// The file's SHA-256 as 64 lower-case hex digits; an error names the file.
Expected<std::string> sha256File(const std::filesystem::path& path);

}  // namespace dynbench
