#include "maplight/light_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

#include <tbb/parallel_for.h>

#include "core/math.h"
#include "maplight/fit_candidates.h"
#include "maplight/nnls.h"

namespace dynbench::maplight {

namespace {
// Steps a fitted light may take at one scale of the refinement before the scale halves.
constexpr int kRefineStepsPerScale = 8;
}  // namespace

double dot(const Column& c, const std::vector<double>& dense) {
  double s = 0;
  for (std::size_t k = 0; k < c.rows.size(); ++k) s += c.values[k] * dense[c.rows[k]];
  return s;
}

LightSystem::LightSystem(const std::vector<Column>& columns, std::size_t rows, std::size_t texelRows, std::vector<glm::dvec3> groupColors)
    : columns_(columns), rows_(rows), texelRows_(texelRows), groupColors_(std::move(groupColors)), dense_(rows, 0.0) {}

double LightSystem::texelSum(const Column& c) const {
  double sum = 0.0;
  for (std::size_t k = 0; k < c.rows.size(); ++k)
    if (c.rows[k] < texelRows_) sum += c.values[k];
  return sum;
}

double LightSystem::colorOf(std::size_t column, int channel) const {
  const glm::dvec3 color = column < groupColors_.size() ? groupColors_[column] : glm::dvec3(1.0);
  return channel == 3 ? luminance(color) : color[channel];
}

void LightSystem::add(std::size_t j) {
  const Column& cj = columns_[j];
  for (std::size_t k = 0; k < cj.rows.size(); ++k) dense_[cj.rows[k]] = cj.values[k];
  std::vector<double> row(chosen_.size() + 1);
  for (std::size_t a = 0; a < chosen_.size(); ++a) {
    row[a] = dot(columns_[chosen_[a]], dense_);
    gramRows_[a].push_back(row[a]);
  }
  row[chosen_.size()] = cj.norm2;
  for (std::uint32_t i : cj.rows) dense_[i] = 0.0;
  gramRows_.push_back(std::move(row));
  columnSums_.push_back(texelSum(cj));
  chosen_.push_back(j);
}

void LightSystem::remove(const std::vector<char>& drop) {
  std::vector<std::size_t> keep;
  for (std::size_t a = 0; a < chosen_.size(); ++a)
    if (!drop[a]) keep.push_back(a);
  std::vector<std::vector<double>> rows;
  std::vector<double> sums;
  std::vector<std::size_t> cols;
  for (std::size_t a : keep) {
    std::vector<double> row;
    for (std::size_t b : keep) row.push_back(gramRows_[a][b]);
    rows.push_back(std::move(row));
    sums.push_back(columnSums_[a]);
    cols.push_back(chosen_[a]);
  }
  gramRows_ = std::move(rows);
  columnSums_ = std::move(sums);
  chosen_ = std::move(cols);
}

void LightSystem::replace(std::size_t a, std::size_t j) {
  const Column& cj = columns_[j];
  for (std::size_t k = 0; k < cj.rows.size(); ++k) dense_[cj.rows[k]] = cj.values[k];
  for (std::size_t b = 0; b < chosen_.size(); ++b)
    if (b != a) gramRows_[a][b] = gramRows_[b][a] = dot(columns_[chosen_[b]], dense_);
  for (std::uint32_t i : cj.rows) dense_[i] = 0.0;
  gramRows_[a][a] = cj.norm2;
  columnSums_[a] = texelSum(cj);
  chosen_[a] = j;
}

std::vector<double> LightSystem::solve(const std::vector<double>& y, int channel) const {
  const std::size_t m = chosen_.size() + 1;
  std::vector<double> gram(m * m, 0.0), atb(m, 0.0);
  for (std::size_t a = 0; a < chosen_.size(); ++a) {
    const double ca = colorOf(chosen_[a], channel);
    for (std::size_t b = 0; b < chosen_.size(); ++b) gram[a * m + b] = gramRows_[a][b] * ca * colorOf(chosen_[b], channel);
    gram[a * m + m - 1] = gram[(m - 1) * m + a] = columnSums_[a] * ca;
    atb[a] = dot(columns_[chosen_[a]], y) * ca;
  }
  gram[(m - 1) * m + m - 1] = static_cast<double>(texelRows_);
  atb[m - 1] = std::accumulate(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(texelRows_), 0.0);
  return nnls(gram, atb).x;
}

double LightSystem::residual(const std::vector<double>& y, const std::vector<double>& x, int channel, std::vector<double>& out) const {
  out.assign(rows_, 0.0);
  for (std::size_t i = 0; i < rows_; ++i) out[i] = i < texelRows_ ? y[i] - x.back() : y[i];
  for (std::size_t a = 0; a < chosen_.size(); ++a) {
    const Column& c = columns_[chosen_[a]];
    const double w = x[a] * colorOf(chosen_[a], channel);
    for (std::size_t k = 0; k < c.rows.size(); ++k) out[c.rows[k]] -= w * c.values[k];
  }
  double s = 0;
  for (double v : out) s += v * v;
  return s;
}

void chooseLights(LightSystem& system, const std::vector<Column>& columns, const std::vector<double>& target, double signal,
                  std::vector<double>& residual, double error, const MapLightFitOptions& options, const MapLightProgress& report) {
  const std::size_t groupCount = system.groupCount();
  std::vector<char> taken(columns.size(), 0);
  std::fill(taken.begin(), taken.begin() + static_cast<std::ptrdiff_t>(groupCount), 1);
  std::vector<double> scores(columns.size());
  while (static_cast<int>(system.chosen().size() - groupCount) < options.maxLights) {
    tbb::parallel_for(std::size_t(0), columns.size(), [&](std::size_t j) {
      scores[j] = taken[j] || columns[j].norm2 <= 0 ? 0.0 : dot(columns[j], residual) / std::sqrt(columns[j].norm2);
    });
    std::size_t best = columns.size();
    double bestScore = 0.0;
    for (std::size_t j = 0; j < columns.size(); ++j)
      if (scores[j] > bestScore) {
        bestScore = scores[j];
        best = j;
      }
    if (best == columns.size()) break;
    system.add(best);
    taken[best] = 1;
    std::vector<double> nextResidual;
    const std::vector<double> next = system.solve(target, 3);
    const double nextError = system.residual(target, next, 3, nextResidual);
    std::vector<char> drop(system.chosen().size(), 0);
    if (error - nextError < options.minimumGain * signal) {
      drop.back() = 1;
      system.remove(drop);
      break;
    }
    residual = std::move(nextResidual);
    error = nextError;
    // candidates NNLS set to zero leave the set (they may be chosen again); groups stay
    for (std::size_t a = groupCount; a < system.chosen().size(); ++a)
      if (!(next[a] > 0)) {
        drop[a] = 1;
        taken[system.chosen()[a]] = 0;
      }
    system.remove(drop);
    report("fitting lights", system.chosen().size() - groupCount, static_cast<std::size_t>(options.maxLights));
  }
}

std::size_t refineLights(LightSystem& system, std::vector<Column>& columns, std::vector<glm::dvec3>& candidates, const std::vector<double>& target,
                         double spacing, const std::vector<Sample>& fit, const Occluders& occluders, const MapLightProgress& report) {
  const std::size_t groupCount = system.groupCount();
  const std::vector<double> held = system.solve(target, 3);
  std::vector<double> residual;
  system.residual(target, held, 3, residual);
  std::size_t refined = 0;
  for (std::size_t a = groupCount; a < system.chosen().size(); ++a) {
    const double w = held[a];
    if (!(w > 0)) continue;
    std::vector<double> without = residual;  // the residual without this light
    {
      const Column& c = columns[system.chosen()[a]];
      for (std::size_t k = 0; k < c.rows.size(); ++k) without[c.rows[k]] += w * c.values[k];
    }
    double withoutNorm = 0;
    for (double v : without) withoutNorm += v * v;
    glm::dvec3 position = candidates[system.chosen()[a] - groupCount];
    const Column* current = &columns[system.chosen()[a]];
    double currentWeight = w, currentDot = dot(*current, without);
    double currentError = withoutNorm - 2.0 * currentWeight * currentDot + currentWeight * currentWeight * current->norm2;
    Column best;
    bool moved = false;
    // Positions already tried for this light. A tried position's error was at least the error
    // then held, which only falls, so the strict test below never picks it again: skipping it
    // (the step back to where the light came from, above all) leaves the search's path as it was.
    std::set<std::array<double, 3>> tried;
    // A pattern search: at each scale the light keeps stepping to its best axis neighbour
    // while that lowers the residual (up to kRefineStepsPerScale steps), then the scale halves.
    for (const double step : {spacing / 2, spacing / 4, spacing / 8, spacing / 16}) {
      for (int stepsTaken = 0; stepsTaken < kRefineStepsPerScale; ++stepsTaken) {
        std::vector<glm::dvec3> trials;
        for (int axis = 0; axis < 3; ++axis)
          for (const double sign : {-1.0, 1.0}) {
            glm::dvec3 p = position;
            p[axis] += sign * step;
            if (tried.insert({p.x, p.y, p.z}).second) trials.push_back(p);
          }
        std::vector<Column> trialColumns(trials.size());
        std::vector<char> usable(trials.size(), 0);
        tbb::parallel_for(std::size_t(0), trials.size(), [&](std::size_t t) {
          if (!inOpenSpace(trials[t], occluders)) return;
          trialColumns[t] = candidateColumn(trials[t], fit, occluders, std::numeric_limits<double>::infinity());
          usable[t] = trialColumns[t].norm2 > 0;
        });
        bool improved = false;
        for (std::size_t t = 0; t < trials.size(); ++t) {
          if (!usable[t]) continue;
          const double d = dot(trialColumns[t], without);
          const double weight = std::max(0.0, d / trialColumns[t].norm2);
          const double error = withoutNorm - 2.0 * weight * d + weight * weight * trialColumns[t].norm2;
          if (error < currentError) {
            currentError = error;
            currentWeight = weight;
            position = trials[t];
            best = std::move(trialColumns[t]);
            current = &best;
            moved = improved = true;
          }
        }
        if (!improved) break;
      }
    }
    if (!moved) continue;
    // the moved light: a new column (and candidate position) in place of the old one
    candidates.push_back(position);
    columns.push_back(std::move(best));
    const std::size_t j = columns.size() - 1;
    system.replace(a, j);
    const Column& cj = columns[j];
    residual = std::move(without);
    for (std::size_t k = 0; k < cj.rows.size(); ++k) residual[cj.rows[k]] -= currentWeight * cj.values[k];
    ++refined;
    report("refining lights", a - groupCount + 1, system.chosen().size() - groupCount);
  }
  return refined;
}

namespace {

// The chosen columns' weights fitted per channel (the constant last in each).
std::array<std::vector<double>, 3> channelWeights(const LightSystem& system, const std::vector<Sample>& fit) {
  std::array<std::vector<double>, 3> perChannel;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> y(system.rows());
    for (std::size_t i = 0; i < system.rows(); ++i) y[i] = fit[i].value[c];
    perChannel[static_cast<std::size_t>(c)] = system.solve(y, c);
  }
  return perChannel;
}

}  // namespace

std::vector<double> endLights(LightSystem& system, std::vector<Column>& columns, std::vector<glm::dvec3>& candidates, const std::vector<Sample>& fit,
                              const Occluders& occluders, const MapLightProgress& report) {
  const std::size_t groupCount = system.groupCount();
  std::vector<double> ranges(system.chosen().size(), 0.0);
  for (int round = 0; round < kEndRounds; ++round) {
    const std::array<std::vector<double>, 3> perChannel = channelWeights(system, fit);
    const std::size_t lights = system.chosen().size() - groupCount;
    std::vector<Column> ended(lights);
    tbb::parallel_for(std::size_t(0), lights, [&](std::size_t k) {
      const std::size_t a = groupCount + k;
      MapLight light;  // q3map2's value V is the largest channel's (its colour's largest channel is 1)
      light.value = std::max({perChannel[0][a], perChannel[1][a], perChannel[2][a], 0.0});
      ranges[a] = light.value > 0 ? lightEnvelope(light) : 0.0;
      // a light the fit weighs 0 keeps its column: it gives no light and becomes no light
      if (ranges[a] > 0) ended[k] = candidateColumn(candidates[system.chosen()[a] - groupCount], fit, occluders, ranges[a]);
    });
    for (std::size_t k = 0; k < lights; ++k) {
      const std::size_t a = groupCount + k;
      if (!(ranges[a] > 0)) continue;
      candidates.push_back(candidates[system.chosen()[a] - groupCount]);
      columns.push_back(std::move(ended[k]));
      system.replace(a, columns.size() - 1);
    }
    report("ending lights", static_cast<std::size_t>(round) + 1, kEndRounds);
  }
  return ranges;
}

std::vector<double> setStrengths(const LightSystem& system, const std::vector<double>& target, const std::vector<Sample>& fit,
                                 const std::vector<EmitterGroup>& groups, const std::vector<glm::dvec3>& candidates,
                                 const std::vector<double>& ranges, MapLighting& lighting) {
  const std::size_t groupCount = system.groupCount();
  const std::vector<double> weights = system.solve(target, 3);

  const std::array<std::vector<double>, 3> perChannel = channelWeights(system, fit);
  for (int c = 0; c < 3; ++c) lighting.report.constant[c] = perChannel[static_cast<std::size_t>(c)].back();
  for (std::size_t k = 0; k < groupCount; ++k) {
    lighting.report.groupWeights.push_back({groups[k].name, weights[k]});
    for (std::size_t li : groups[k].lights) lighting.lights[li].value *= weights[k];
    // the dataset's emitter takes its front's weight; the back's is reported
    if (groups[k].side != EmitterSide::kBack)
      for (std::size_t ei : groups[k].surfaces) lighting.surfaceLights[ei].value *= weights[k];
  }
  for (std::size_t a = groupCount; a < system.chosen().size(); ++a) {
    const glm::dvec3 v(perChannel[0][a], perChannel[1][a], perChannel[2][a]);
    const double peak = std::max({v.r, v.g, v.b});
    if (!(peak > 0)) continue;
    MapLight l;
    l.position = candidates[system.chosen()[a] - groupCount];
    l.color = v / peak;
    l.value = peak;
    l.range = ranges[a];
    l.source = "fitted";
    lighting.lights.push_back(l);
  }
  return weights;
}

}  // namespace dynbench::maplight
