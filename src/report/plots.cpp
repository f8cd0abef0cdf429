#include "report/plots.h"

#include <algorithm>
#include <cmath>
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
  ProcessOptions options;
  options.argv = {"gnuplot", script.string()};
  auto run = runProcess(options);
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
                                                 const std::vector<LineFigure>& figures, int height = 450) {
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
    for (const auto& [terminal, ext] : {std::pair{fmt::format("pngcairo noenhanced size 1200,{} font ',10'", height), ".png"},
                                        std::pair{fmt::format("svg noenhanced size 1200,{} dynamic font ',10'", height), ".svg"}}) {
      const fs::path target = dir / (stem + (figure.name.empty() ? std::string() : "_" + figure.name) + ext);
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
  std::string csv = "frame";
  for (const auto& column : discard::kTable67Columns) csv += fmt::format(",{}", column.label);
  csv += "\n";
  for (const auto& f : frames) {
    csv += std::to_string(f.frame);
    for (const auto& column : discard::kTable67Columns) csv += fmt::format(",{}", f.*column.member);
    csv += "\n";
  }
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
    csv += ',';
    csv += name;
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

Expected<std::vector<fs::path>> writeScatterPlot(const std::vector<ScatterPoint>& points, const std::string& xLabel, const std::string& yLabel,
                                                 const std::string& title, const fs::path& dir, const std::string& stem) {
  std::string csv = "dataset,x,y\n";
  for (const ScatterPoint& p : points) {
    std::string label = p.label;
    std::replace(label.begin(), label.end(), ',', ' ');
    csv += fmt::format("{},{},{}\n", label, p.x, p.y);
  }
  const std::string plot = fmt::format(
      "set xlabel {}\nplot {{data}} using 2:3 with points pt 7 ps 1.2 notitle, {{data}} using 2:3:1 with labels offset 0.6,0.6 left font ',8' "
      "notitle\nset xlabel 'frame'",
      quoted(xLabel));
  return writeLineFigures(dir, stem, csv, {{"", title, yLabel, plot}}, 700);
}

namespace {

// A CSV column name without the separator.
std::string columnName(std::string name) {
  std::replace(name.begin(), name.end(), ',', ' ');
  return name;
}

std::string cell(double v) { return std::isfinite(v) ? fmt::format("{}", v) : std::string(); }

}  // namespace

Expected<std::vector<fs::path>> writeComparisonPlots(const std::vector<ComparisonSeries>& series, const fs::path& dir,
                                                     const std::string& stem) {
  std::vector<fs::path> pngs;
  auto keepPngs = [&](const std::vector<fs::path>& written) {
    for (const auto& p : written)
      if (p.extension() == ".png") pngs.push_back(p);
  };
  // Rotation per frame, overlaid, and its cumulative distribution (cut frames left out).
  std::vector<const ComparisonSeries*> rotating;
  for (const auto& s : series)
    if (!s.rotation.empty()) rotating.push_back(&s);
  if (!rotating.empty()) {
    std::size_t length = 0;
    std::string csv = "frame", cdf;
    std::vector<std::vector<double>> sorted;
    for (const auto* s : rotating) {
      csv += ',';
      csv += columnName(s->name);
      cdf += fmt::format("{}{},{} share", cdf.empty() ? "" : ",", columnName(s->name), columnName(s->name));
      length = std::max(length, s->rotation.size());
      std::vector<double> values;
      for (double v : s->rotation)
        if (std::isfinite(v)) values.push_back(v);
      std::sort(values.begin(), values.end());
      sorted.push_back(std::move(values));
    }
    csv += "\n";
    cdf += "\n";
    for (std::size_t k = 0; k < length; ++k) {
      csv += std::to_string(k);
      for (const auto* s : rotating) {
        csv += ',';
        if (k < s->rotation.size()) csv += cell(s->rotation[k]);
      }
      csv += "\n";
    }
    std::size_t longest = 0;
    for (const auto& v : sorted) longest = std::max(longest, v.size());
    for (std::size_t k = 0; k < longest; ++k) {
      for (std::size_t d = 0; d < sorted.size(); ++d) {
        const auto& v = sorted[d];
        cdf += d ? "," : "";
        cdf += k < v.size() ? fmt::format("{},{}", v[k], static_cast<double>(k + 1) / static_cast<double>(v.size())) : std::string(",");
      }
      cdf += "\n";
    }
    std::string plot = "set datafile missing ''\nplot ";
    for (std::size_t d = 0; d < rotating.size(); ++d) plot += fmt::format("{}{{data}} using 1:{} with lines lw 1.2 title columnhead", d ? ", " : "", d + 2);
    auto written = writeLineFigures(dir, stem, csv,
                                    {{"rotation", "Geodesic change in camera rotation per frame, every dataset (cut frames left out)", "degrees / frame", plot}});
    if (!written) return std::unexpected(written.error());
    keepPngs(*written);
    std::string cdfPlot = "set datafile missing ''\nset xlabel 'degrees / frame'\nset logscale x\nset key bottom right\nplot ";
    for (std::size_t d = 0; d < rotating.size(); ++d)
      cdfPlot += fmt::format("{}{{data}} using {}:{} with steps lw 1.5 title columnhead({})", d ? ", " : "", 2 * d + 1, 2 * d + 2, 2 * d + 1);
    cdfPlot += "\nunset logscale x\nset xlabel 'frame'\nset key default";
    written = writeLineFigures(dir, stem + "_cdf", cdf,
                               {{"rotation_cdf", "Share of frames turning at most x degrees (cumulative distribution, cut frames left out)", "share of frames", cdfPlot}});
    if (!written) return std::unexpected(written.error());
    keepPngs(*written);
  }
  // Discard per frame, one panel per feature, every dataset overlaid.
  std::vector<const ComparisonSeries*> discarding;
  for (const auto& s : series)
    if (!s.discard.empty()) discarding.push_back(&s);
  if (!discarding.empty()) {
    std::size_t length = 0;
    std::string csv = "frame in window";
    for (std::size_t f = 0; f < discard::kTable67Columns.size(); ++f)
      for (const auto* s : discarding) csv += fmt::format(",{} {}", columnName(s->name), discard::kTable67Columns[f].label);
    for (const auto* s : discarding) length = std::max(length, s->discard.size());
    csv += "\n";
    for (std::size_t k = 0; k < length; ++k) {
      csv += std::to_string(k);
      for (std::size_t f = 0; f < discard::kTable67Columns.size(); ++f)
        for (const auto* s : discarding) {
          if (k >= s->discard.size() || s->discard[k].cut) {
            csv += ",";
            continue;
          }
          const auto& p = s->discard[k];
          csv += ',';
          csv += cell(p.*discard::kTable67Columns[f].member);
        }
      csv += "\n";
    }
    std::string plot = "set datafile missing ''\nset multiplot layout 5,1\nset xlabel 'frame pair in the rendered window'\n";
    for (std::size_t f = 0; f < discard::kTable67Columns.size(); ++f) {
      plot += fmt::format("set title '{} discard per frame, every dataset (cut pairs left out)'\nplot ", discard::kTable67Columns[f].label);
      for (std::size_t d = 0; d < discarding.size(); ++d)
        plot += fmt::format("{}{{data}} using 1:{} with lines lw 1.2 title {}", d ? ", " : "", 2 + f * discarding.size() + d, quoted(discarding[d]->name));
      plot += "\n";
    }
    plot += "unset multiplot\nset xlabel 'frame'";
    auto written = writeLineFigures(dir, stem, csv, {{"discard", "", "% of the image", plot}}, 1500);
    if (!written) return std::unexpected(written.error());
    keepPngs(*written);
  }
  // Table 6.7 as grouped bars: x is the feature, one bar per dataset, the 95 % interval where known.
  std::vector<const ComparisonSeries*> means;
  for (const auto& s : series)
    if (s.mean) means.push_back(&s);
  if (!means.empty()) {
    std::string csv = "feature";
    for (const auto* s : means) csv += fmt::format(",{}{},low,high", columnName(s->name), s->published ? " (published)" : "");
    csv += "\n";
    for (std::size_t f = 0; f < discard::kTable67Columns.size(); ++f) {
      csv += std::to_string(f);
      for (const auto* s : means) {
        const auto& m = *s->mean;
        const auto& column = discard::kTable67Columns[f];
        const double v = m.*column.member;
        const std::optional<discard::Interval> interval = column.interval ? m.*column.interval : std::nullopt;
        csv += fmt::format(",{},{},{}", v, interval ? interval->low : v, interval ? interval->high : v);
      }
      csv += "\n";
    }
    const double width = 0.8 / static_cast<double>(means.size());
    std::string plot = fmt::format("set style fill solid 0.7 border -1\nset boxwidth {}\nset xrange [-0.5:4.5]\nset yrange [0:*]\nset xlabel ''\n", width);
    plot += "set xtics ('frustum' 0, 'world position' 1, 'shading normal' 2, 'direct radiance' 3, 'indirect radiance' 4)\nset key outside right\nplot ";
    for (std::size_t d = 0; d < means.size(); ++d) {
      const double offset = (static_cast<double>(d) - 0.5 * static_cast<double>(means.size() - 1)) * width;
      const std::size_t c = 2 + 3 * d;
      // boxerrorbars with five columns: x, y, ylow, yhigh, box width.
      plot += fmt::format("{}{{data}} using ($1+{}):{}:{}:{}:({}) with boxerrorbars title columnhead({})", d ? ", " : "", offset, c, c + 1, c + 2,
                          width, c);
    }
    plot += "\nset xtics autofreq\nunset xrange\nunset yrange\nset key default\nset xlabel 'frame'";
    auto written = writeLineFigures(dir, stem, csv, {{"table67", "Table 6.7: discarded pixels, % of the image (bars: mean; whiskers: 95 % interval)", "% of the image", plot}});
    if (!written) return std::unexpected(written.error());
    keepPngs(*written);
  }
  return pngs;
}

}  // namespace dynbench::report
