// `--engine embree`: dynbench's path tracer (path_tracer.h) as a render backend.
#include <atomic>
#include <chrono>
#include <future>
#include <thread>

#include <tbb/task_group.h>

#include "render/backend.h"
#include "render/path_tracer.h"

namespace dynbench::render {
namespace {

class EmbreeBackend final : public RenderBackend {
 public:
  explicit EmbreeBackend(std::unique_ptr<PathTracer> tracer) : tracer_(std::move(tracer)) {}

  Expected<void> render(const std::vector<FrameRequest>& requests, const FrameSink& done, const RowProgress& rows) override {
    // Each frame is written while the next one renders (a TBB task, so --threads still bounds
    // the cores in use): written in turn, one core compressed the EXR at each frame boundary while
    // the others had no rows left.
    tbb::task_group writing;
    FrameBuffers written;  // the frame the write task holds
    Expected<void> writeResult;
    auto finishWriting = [&]() -> Expected<void> {
      writing.wait();
      return writeResult;
    };
    for (std::size_t i = 0; i < requests.size(); ++i) {
      const FrameRequest& request = requests[i];
      // The frames stepped through unrendered first: the path tracer's scene keeps state between
      // frames (RenderJob::stepFrom).
      for (const SceneStep& step : request.stepsBefore)
        if (auto ok = tracer_->setTime(step.time, step.previousTime); !ok) {
          (void)finishWriting();
          return ok;
        }
      if (auto ok = tracer_->setTime(request.cameras.time, request.cameras.previousTime); !ok) {
        (void)finishWriting();
        return ok;
      }
      std::atomic<int> rowsDone{0};
      RenderStatistics stats;
      FrameBuffers buffers;
      auto renderFrame = [&] {
        buffers = tracer_->render(static_cast<std::uint64_t>(request.frame), request.cameras.camera, request.cameras.previous, &rowsDone,
                                  &stats);
        if (tracer_->settings().pairs)
          tracer_->renderChanges(static_cast<std::uint64_t>(request.frame), request.cameras.camera, request.cameras.previous, buffers, &stats);
      };
      if (rows) {
        // The frame renders on a worker thread while this one reports its rows, every 100 ms
        // until the frame ends. (It used to sleep 100 ms between reports whatever happened: every
        // frame then ended with both cores idle for 50 ms on average, 11 % of a 2-thread frame
        // of the colos segment at 320x180.)
        std::packaged_task<void()> task(renderFrame);
        const std::future<void> finished = task.get_future();
        std::thread worker(std::move(task));
        do rows(i, rowsDone.load());
        while (finished.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready);
        worker.join();
      } else {
        renderFrame();
      }
      statistics_.cameraSamples += stats.cameraSamples;
      statistics_.rays += stats.rays;
      statistics_.shadingPoints += stats.shadingPoints;
      statistics_.punctualEvaluated += stats.punctualEvaluated;
      statistics_.punctualInFrame += stats.punctualInFrame;
      buffers.frame = request.frame;
      buffers.time = request.cameras.time;
      buffers.camera = request.cameras.camera.frameCamera();
      if (tracer_->settings().jitter) buffers.camera.jitter = frames::jitterOffset(request.frame);
      if (auto ok = finishWriting(); !ok) return ok;  // the frame before, in request order
      written = std::move(buffers);
      writing.run([&] { writeResult = done(std::move(written)); });
    }
    return finishWriting();
  }

  RenderStatistics statistics() const override { return statistics_; }

 private:
  std::unique_ptr<PathTracer> tracer_;
  RenderStatistics statistics_;
};

}  // namespace

Expected<std::unique_ptr<RenderBackend>> createEmbreeBackend(const BackendContext& context) {
  auto tracer = PathTracer::create(context.scene, context.job.settings, context.warnings);
  if (!tracer) return std::unexpected(tracer.error());
  return std::make_unique<EmbreeBackend>(std::move(*tracer));
}

}  // namespace dynbench::render
