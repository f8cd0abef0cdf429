#include "convert/converter.h"

namespace dynbench::convert::detail {

Track& Converter::track(std::uint64_t id, Kind kind, int model) {
  auto [it, inserted] = tracks_.try_emplace(id);
  Track& t = it->second;
  if (inserted) {
    t.id = id;
    t.kind = kind;
    t.model = model;
    t.skinned = model >= 0 && !reader_->models()[static_cast<std::size_t>(model)].joints.empty();
  }
  return t;
}

// Called for every record of a dynamic capturable in frame i (once per frame and capturable).
// Emits visibility keys through `key(track, frame, value)`.
template <typename Key>
void Converter::present(Track& t, std::size_t i, Key&& key) {
  if (t.lastPresent == i && t.appeared) return;  // a second record of the same capturable this frame
  if (!t.visible) {
    if (!t.appeared) {
      t.appeared = true;
      t.first = i;
      if (i > 0) key(t, 0, false);  // hidden from the start until it appears
    }
    key(t, i, true);
    t.visible = true;
    visibleNow_.push_back(&t);
  }
  t.lastPresent = i;
}

template <typename Key>
void Converter::endFrame(std::size_t i, Key&& key) {
  std::erase_if(visibleNow_, [&](Track* t) {
    if (i - t->lastPresent <= static_cast<std::size_t>(t->extraFrames)) return false;
    key(*t, i, false);
    t->visible = false;
    return true;
  });
}

template <typename Key>
void Converter::scanFrame(const CaptureFrame& frame, std::size_t i, Key&& key) {
  for (const auto& c : frame.cameras) present(track(c.id, Kind::kCamera, -1), i, key);
  for (const auto& c : frame.cuts) {
    Track& t = track(c.id, Kind::kCamera, -1);
    if (i > 0 && (t.cuts.empty() || t.cuts.back().time != times_[i])) t.cuts.push_back({times_[i - 1], times_[i], c.reason});
  }
  for (const auto& m : frame.models) present(track(m.id, Kind::kModel, m.model), i, key);
  for (const auto& l : frame.lights) {
    Track& t = track(l.id, Kind::kLight, -1);
    if (!t.appeared && !l.dynamic) {
      t.light = l;
      t.appeared = true;
      continue;
    }
    if (!t.appeared) {
      t.light = l;
      t.extraFrames = options_.lightRules.rule(l.modelType).extraFrames;
    } else if (l.color != t.light.color || l.range != t.light.range) {
      t.colorVaries = true;
    }
    if (l.dynamic) present(t, i, key);
  }
  for (const auto& p : frame.staticModels) {
    Track& t = track(p.id, Kind::kStaticModel, p.model);
    t.staticPose = p.pose;
    t.appeared = true;
  }
  endFrame(i, key);
}

Expected<void> Converter::passOne() {
  CaptureFrame frame;
  std::size_t i = 0;
  auto count = [](Track& t, std::size_t frame, bool) {
    ++t.visibilityKeys;
    t.lastKeyFrame = frame;
  };
  while (true) {
    auto more = reader_->next(frame);
    if (!more) return std::unexpected(more.error());
    if (!*more) break;
    if (frame.cameraSettings && !cameraChanged_) {
      cameraChanged_ = true;
      report_.warnings.push_back(fmt::format("{}: camera settings change at frame {}; the dataset keeps the first ones",
                                             options_.capture.string(), frame.number));
    }
    times_.push_back(static_cast<float>(frame.time));
    scanFrame(frame, i, count);
    if (options_.onProgress) options_.onProgress(1, i + 1, 0);
    ++i;
  }
  const std::size_t n = times_.size();
  for (auto& [id, t] : tracks_) t.lastSpan = std::min(n - 1, t.lastPresent + static_cast<std::size_t>(t.extraFrames));
  // Times must strictly increase for glTF samplers; equal capture times (a paused game) cannot be keyed.
  for (std::size_t k = 1; k < n; ++k)
    if (!(times_[k] > times_[k - 1]))
      return fail(ErrorCode::kInvalidData, "{}: frames {} and {} have the same time {} s (as float); glTF key times must increase",
                  options_.capture.string(), k - 1, k, times_[k]);
  return {};
}

Expected<void> Converter::passTwo() {
  auto opened = CaptureReader::open(options_.capture);
  if (!opened) return std::unexpected(opened.error());
  auto reader = std::move(*opened);
  for (auto& [id, t] : tracks_) {
    t.appeared = t.visible = false;
    t.lastPresent = 0;
    if (t.translationOffset) t.translation = RegionWriter(bin_, t.translationOffset);
    if (t.rotationOffset) t.rotation = RegionWriter(bin_, t.rotationOffset);
    if (t.visTimeOffset) t.visTime = RegionWriter(bin_, t.visTimeOffset);
    if (t.visValueOffset) t.visValue = RegionWriter(bin_, t.visValueOffset);
    if (t.scaleOffset) t.scale = RegionWriter(bin_, t.scaleOffset);
    if (t.colorOffset) t.color = RegionWriter(bin_, t.colorOffset);
    if (t.intensityOffset) t.intensity = RegionWriter(bin_, t.intensityOffset);
    if (t.rangeOffset) t.range = RegionWriter(bin_, t.rangeOffset);
    if (t.weightsOffset) t.weights = RegionWriter(bin_, t.weightsOffset);
    for (auto o : t.jointTranslationOffsets) t.jointTranslation.emplace_back(bin_, o);
    for (auto o : t.jointRotationOffsets) t.jointRotation.emplace_back(bin_, o);
  }
  visibleNow_.clear();
  auto key = [&](Track& t, std::size_t frame, bool value) {
    if (!visInputs_.contains(t.id)) return;
    t.visTime.put(times_[frame]);
    if (t.visValueOffset) t.visValue.put(static_cast<std::uint8_t>(value ? 1 : 0));
    if (t.scaleOffset) {
      const float s = value ? 1.0f : 0.0f;
      for (int k = 0; k < 3; ++k) t.scale.put(s);
    }
  };
  std::vector<Track*> active;
  CaptureFrame frame;
  for (std::size_t i = 0; i < times_.size(); ++i) {
    auto more = reader->next(frame);
    if (!more) return std::unexpected(more.error());
    if (!*more) return fail(ErrorCode::kIo, "{}: the capture changed while it was converted", options_.capture.string());
    // Held values follow this frame's records.
    for (const auto& c : frame.cameras) {
      Track& t = tracks_.at(c.id);
      t.heldTranslation = c.position;
      t.heldRotation = quatFromYawPitchRoll(radians(c.yaw), radians(c.pitch), radians(c.roll));
      if (!t.appeared) active.push_back(&t);
    }
    for (const auto& m : frame.models) {
      Track& t = tracks_.at(m.id);
      t.heldTranslation = translationOf(m.pose);
      t.heldRotation = rotationOf(m.pose);
      if (!t.appeared) active.push_back(&t);
    }
    for (const auto& l : frame.lights) {
      Track& t = tracks_.at(l.id);
      if (!l.dynamic) continue;
      t.heldTranslation = l.position;
      t.heldColor = l.color;
      t.heldRange = l.range;
      if (!t.appeared) active.push_back(&t);
    }
    for (const auto& v : frame.vertexFrames) {
      Track& t = tracks_.at(v.id);
      if (t.heldWeights.empty()) continue;  // a model without a mesh
      std::fill(t.heldWeights.begin(), t.heldWeights.end(), 0.0f);
      t.heldWeights[v.from] += static_cast<float>(1.0 - v.fraction);
      t.heldWeights[v.to] += static_cast<float>(v.fraction);
    }
    for (const auto& j : frame.joints) {
      Track& t = tracks_.at(j.id);
      // Model-space joints to parent-local: L_j = M_parent^-1 M_j (rigid, so exact).
      const auto& model = reader_->models()[static_cast<std::size_t>(t.model)];
      for (std::size_t k = 0; k < j.joints.size(); ++k) {
        const glm::dquat r = rotationOf(j.joints[k]);
        const glm::dvec3 p = translationOf(j.joints[k]);
        const int parent = model.joints[k].parent;
        if (parent < 0) {
          t.heldJointTranslation[k] = p;
          t.heldJointRotation[k] = r;
        } else {
          const glm::dquat rp = rotationOf(j.joints[static_cast<std::size_t>(parent)]);
          const glm::dvec3 pp = translationOf(j.joints[static_cast<std::size_t>(parent)]);
          t.heldJointTranslation[k] = glm::conjugate(rp) * (p - pp);
          t.heldJointRotation[k] = glm::normalize(glm::conjugate(rp) * r);
        }
      }
    }
    scanFrame(frame, i, key);
    // Every active track writes one key per frame of its span.
    std::erase_if(active, [&](Track* t) {
      if (i > t->lastSpan) return true;
      if (t->translationOffset) t->translation.put(std::array<float, 3>{static_cast<float>(t->heldTranslation.x),
                                                                         static_cast<float>(t->heldTranslation.y),
                                                                         static_cast<float>(t->heldTranslation.z)});
      if (t->weightsOffset)
        for (float w : t->heldWeights) t->weights.put(w);
      if (t->colorOffset) {
        const auto [color, intensity] = lightColorIntensity(t->heldColor, t->heldRange, t->light.falloff, t->light.modelType, t->lightShare, 0.0);
        t->color.put(std::array<float, 3>{static_cast<float>(color.r), static_cast<float>(color.g), static_cast<float>(color.b)});
        t->intensity.put(static_cast<float>(intensity));
        if (t->rangeOffset) t->range.put(static_cast<float>(t->heldRange));
      }
      if (t->rotationOffset) {
        t->heldRotation = nearest(t->lastRotation, t->heldRotation);
        t->lastRotation = t->heldRotation;
        t->rotation.put(std::array<float, 4>{static_cast<float>(t->heldRotation.x), static_cast<float>(t->heldRotation.y),
                                             static_cast<float>(t->heldRotation.z), static_cast<float>(t->heldRotation.w)});
      }
      for (std::size_t k = 0; k < t->jointTranslation.size(); ++k) {
        const glm::dvec3 p = t->heldJointTranslation[k];
        t->jointTranslation[k].put(std::array<float, 3>{static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
        glm::dquat r = t->heldJointRotation[k];
        r = nearest(t->lastJointRotation[k], r);
        t->heldJointRotation[k] = r;
        t->lastJointRotation[k] = r;
        t->jointRotation[k].put(std::array<float, 4>{static_cast<float>(r.x), static_cast<float>(r.y), static_cast<float>(r.z),
                                                     static_cast<float>(r.w)});
      }
      return i == t->lastSpan;
    });
    if (options_.onProgress) options_.onProgress(2, i + 1, times_.size());
  }
  for (auto& [id, t] : tracks_) {
    for (RegionWriter* w : {&t.translation, &t.rotation, &t.visTime, &t.visValue, &t.scale, &t.color, &t.intensity, &t.range, &t.weights})
      w->flush();
    for (auto& w : t.jointTranslation) w.flush();
    for (auto& w : t.jointRotation) w.flush();
  }
  return {};
}
}  // namespace dynbench::convert::detail
