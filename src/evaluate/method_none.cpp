// `none`: the noisy input as it is, the floor every temporal method should beat.
#include "evaluate/method.h"

namespace dynbench::evaluate {
namespace {

class NoneMethod final : public TemporalMethod {
 public:
  std::string name() const override { return kNoneMethod; }
  nlohmann::json parameters() const override { return nlohmann::json::object(); }
  void reset() override {}
  Expected<MethodOutput> process(const frames::FeatureFrame& frame) override { return MethodOutput{frameRadiance(frame), 0.0}; }
};

}  // namespace

std::unique_ptr<TemporalMethod> makeNoneMethod() { return std::make_unique<NoneMethod>(); }

}  // namespace dynbench::evaluate
