#include "report/plots.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include "core/files.h"
#include "report/stats_output.h"

extern char** environ;

namespace dynbench::report {
namespace {

namespace fs = std::filesystem;

// gnuplot strings are single-quoted; a quote inside is doubled.
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "''";
    else out += c;
  }
  return out + "'";
}

Expected<void> runGnuplot(const fs::path& script, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::string program = "gnuplot", scriptArg = script.string();
  char* argv[] = {program.data(), scriptArg.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    return fail(ErrorCode::kExternalTool, "cannot run gnuplot ({}); install Debian's gnuplot-nox (scripts/setup.sh does)",
                std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    auto text = readWholeFile(log);
    return fail(ErrorCode::kExternalTool, "gnuplot failed on {}: {}", script.string(), text ? *text : std::string("(no output)"));
  }
  return {};
}

}  // namespace

Expected<std::vector<fs::path>> writeRotationPlots(const metrics::CameraMotion& motion, const std::string& title,
                                                   const fs::path& dir, const std::string& stem) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create folder: {}", dir.string(), ec.message());
  const fs::path data = temporarySibling(dir / (stem + "_series.csv"));
  if (auto ok = writeFileAtomic(data, cameraSeriesCsv(motion)); !ok) return std::unexpected(ok.error());

  struct Figure {
    std::string name, ylabel, plot;
  };
  const std::string d = quoted(data.string());
  const std::vector<Figure> figures = {
      {"rotation_per_axis", "degrees / frame",
       fmt::format("plot {0} using 1:12 with lines lw 1.5 title 'pitch', {0} using 1:11 with lines lw 1.5 title 'yaw', "
                   "{0} using 1:13 with lines lw 1.5 title 'roll'",
                   d)},
      {"rotation_geodesic", "degrees / frame", fmt::format("plot {} using 1:10 with lines lw 1.5 title 'geodesic rotation'", d)},
  };
  std::vector<fs::path> written;
  std::vector<std::pair<fs::path, fs::path>> moves;
  std::string script = "set datafile separator ','\nset key autotitle columnhead\nset grid\nset xlabel 'frame'\n";
  for (const auto& figure : figures) {
    for (const auto& [terminal, ext] : {std::pair{"pngcairo size 1200,450 font ',10'", ".png"},
                                        std::pair{"svg size 1200,450 dynamic font ',10'", ".svg"}}) {
      const fs::path target = dir / (stem + "_" + figure.name + ext);
      const fs::path tmp = temporarySibling(target);
      script += fmt::format("set terminal {}\nset output {}\nset title {}\nset ylabel {}\n{}\nunset output\n", terminal,
                            quoted(tmp.string()),
                            quoted(title + (figure.name == "rotation_per_axis" ? ": change in pitch, yaw and roll per frame (Fig. A.1)"
                                                                               : ": geodesic change in rotation per frame (Fig. A.2)")),
                            quoted(figure.ylabel), figure.plot);
      moves.push_back({tmp, target});
    }
  }
  const fs::path scriptPath = temporarySibling(dir / (stem + "_plots.gp"));
  const fs::path logPath = temporarySibling(dir / (stem + "_plots.log"));
  auto cleanup = [&] {
    fs::remove(data, ec);
    fs::remove(scriptPath, ec);
    fs::remove(logPath, ec);
    for (const auto& [tmp, target] : moves) fs::remove(tmp, ec);
  };
  if (auto ok = writeFileAtomic(scriptPath, script); !ok) {
    cleanup();
    return std::unexpected(ok.error());
  }
  if (auto ok = runGnuplot(scriptPath, logPath); !ok) {
    cleanup();
    return std::unexpected(ok.error());
  }
  for (const auto& [tmp, target] : moves) {
    if (auto ok = commitTemporary(tmp, target); !ok) {
      cleanup();
      return std::unexpected(ok.error());
    }
    written.push_back(target);
  }
  cleanup();
  return written;
}

}  // namespace dynbench::report
