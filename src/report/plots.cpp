#include "report/plots.h"

#include <algorithm>
#include <fstream>

#include "core/files.h"
#include "core/process.h"
#include "report/stats_output.h"

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

Expected<void> runGnuplot(const fs::path& script) {
  auto run = runProcess({.argv = {"gnuplot", script.string()}});
  if (!run)
    return fail(ErrorCode::kExternalTool, "{}; install Debian's gnuplot-nox (scripts/setup.sh does)", run.error().message);
  if (!run->succeeded())
    return fail(ErrorCode::kExternalTool, "gnuplot failed on {}: {}", script.string(), run->tail.empty() ? "(no output)" : run->tail);
  return {};
}

// One gnuplot run for several line figures over one CSV (columns named by its header), each as
// PNG and SVG; `plot` holds gnuplot's plot command with {data} standing for the CSV's path.
struct LineFigure {
  std::string name, title, ylabel, plot;
};

Expected<std::vector<fs::path>> writeLineFigures(const fs::path& dir, const std::string& stem, const std::string& csv,
                                                 const std::vector<LineFigure>& figures) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create folder: {}", dir.string(), ec.message());
  const fs::path data = temporarySibling(dir / (stem + "_series.csv"));
  if (auto ok = writeFileAtomic(data, csv); !ok) return std::unexpected(ok.error());
  const std::string d = quoted(data.string());
  std::vector<fs::path> written;
  std::vector<std::pair<fs::path, fs::path>> moves;
  std::string script = "set datafile separator ','\nset key autotitle columnhead\nset grid\nset xlabel 'frame'\n";
  for (const auto& figure : figures) {
    for (const auto& [terminal, ext] : {std::pair{"pngcairo noenhanced size 1200,450 font ',10'", ".png"},
                                        std::pair{"svg noenhanced size 1200,450 dynamic font ',10'", ".svg"}}) {
      const fs::path target = dir / (stem + "_" + figure.name + ext);
      const fs::path tmp = temporarySibling(target);
      std::string plot = figure.plot;
      for (std::size_t at; (at = plot.find("{data}")) != std::string::npos;) plot.replace(at, 6, d);
      script += fmt::format("set terminal {}\nset output {}\nset title {}\nset ylabel {}\n{}\nunset output\n", terminal,
                            quoted(tmp.string()), quoted(figure.title), quoted(figure.ylabel), plot);
      moves.push_back({tmp, target});
    }
  }
  const fs::path scriptPath = temporarySibling(dir / (stem + "_plots.gp"));
  auto cleanup = [&] {
    fs::remove(data, ec);
    fs::remove(scriptPath, ec);
    for (const auto& [tmp, target] : moves) fs::remove(tmp, ec);
  };
  if (auto ok = writeFileAtomic(scriptPath, script); !ok) {
    cleanup();
    return std::unexpected(ok.error());
  }
  if (auto ok = runGnuplot(scriptPath); !ok) {
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

}  // namespace

Expected<std::vector<fs::path>> writeRotationPlots(const metrics::CameraMotion& motion, const std::string& title,
                                                   const fs::path& dir, const std::string& stem) {
  return writeRotationPlotsFromCsv(cameraSeriesCsv(motion), title, dir, stem);
}

Expected<std::vector<fs::path>> writeRotationPlotsFromCsv(const std::string& csv, const std::string& title, const fs::path& dir,
                                                          const std::string& stem) {
  return writeLineFigures(
      dir, stem, csv,
      {{"rotation_per_axis", title + ": change in pitch, yaw and roll per frame (Fig. A.1)", "degrees / frame",
        "plot {data} using 1:12 with lines lw 1.5 title 'pitch', {data} using 1:11 with lines lw 1.5 title 'yaw', "
        "{data} using 1:13 with lines lw 1.5 title 'roll'"},
       {"rotation_geodesic", title + ": geodesic change in rotation per frame (Fig. A.2)", "degrees / frame",
        "plot {data} using 1:10 with lines lw 1.5 title 'geodesic rotation'"}});
}

Expected<std::vector<fs::path>> writeDiscardPlot(const std::vector<discard::FramePercentages>& frames, const std::string& title,
                                                 const fs::path& dir, const std::string& stem) {
  std::string csv = "frame,frustum,world position,shading normal,direct radiance,indirect radiance\n";
  for (const auto& f : frames)
    csv += fmt::format("{},{},{},{},{},{}\n", f.frame, f.frustum, f.position, f.normal, f.direct, f.indirect);
  std::string plot = "plot ";
  for (int column = 2; column <= 6; ++column)
    plot += fmt::format("{}{{data}} using 1:{} with lines lw 1.5 title columnhead", column > 2 ? ", " : "", column);
  return writeLineFigures(dir, stem, csv, {{"discard", title + ": discarded pixels per frame (Eq. 3.4)", "% of the image", plot}});
}

Expected<std::vector<fs::path>> writeMethodsPlot(const std::vector<std::pair<std::string, std::vector<double>>>& series, const fs::path& dir,
                                                 const std::string& stem) {
  std::size_t length = 0;
  std::string csv = "frame in window";
  for (const auto& [label, values] : series) {
    std::string name = label;
    std::replace(name.begin(), name.end(), ',', ' ');
    csv += "," + name;
    length = std::max(length, values.size());
  }
  csv += "\n";
  for (std::size_t k = 0; k < length; ++k) {
    csv += std::to_string(k);
    for (const auto& [label, values] : series) csv += k < values.size() ? fmt::format(",{}", values[k]) : std::string(",");
    csv += "\n";
  }
  std::string plot = "set xlabel 'frame in the rendered window'\nset datafile missing ''\nplot ";
  for (std::size_t column = 0; column < series.size(); ++column)
    plot += fmt::format("{}{{data}} using 1:{} with lines lw 1.5 dt {} title columnhead", column ? ", " : "", column + 2, 1 + column / 8);
  plot += "\nset xlabel 'frame'";
  return writeLineFigures(dir, stem, csv, {{"methods_flip", "ꟻLIP per frame of each temporal method (lower is better)", "mean ꟻLIP", plot}});
}

}  // namespace dynbench::report
