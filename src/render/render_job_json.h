#pragma once
// A render job as one JSON document (docs/cli.md, "Job files"): what `dynbench render --job FILE`
// reads and what a Slurm array task runs (pipeline/cluster_jobs.cpp writes DIR/slurm/render-job.json),
// so the job is spelled once, here, instead of as command-line options parsed back.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "render/render_job.h"

namespace dynbench::render {

inline constexpr int kRenderJobVersion = 1;  // the document's "dynbench_render_job"

// Every field of the job (the frames included), with the paths as they are in the job.
nlohmann::json renderJobJson(const RenderJob& job);

// The job a document describes. Keys left out take RenderJob's defaults but "dataset" and "output",
// which are required; an unknown key, a wrong type or a value out of range is an error naming
// `source` and the JSON pointer. Relative paths are taken relative to the working directory.
Expected<RenderJob> parseRenderJob(const nlohmann::json& document, const std::filesystem::path& source);
Expected<RenderJob> readRenderJob(const std::filesystem::path& path);
// Writes the document through a temporary name.
Expected<void> writeRenderJob(const RenderJob& job, const std::filesystem::path& path);

}  // namespace dynbench::render
