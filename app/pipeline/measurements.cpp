#include "app/pipeline/measurements.hpp"

namespace wingman::app {

slam::SensorBatch take_samples(SensorSamples& samples, const SensorRequest& wanted,
                               const std::vector<int>& cam_uav, int k, double t) {
  slam::SensorBatch batch;
  if (wanted.gps) batch.gps = samples.gps(k, t);
  for (std::size_t j = 0; j < cam_uav.size(); ++j) {
    const int cam = static_cast<int>(j);
    if (wanted.altimeter[j])
      if (auto a = samples.altimeter(cam_uav[j], k, t)) batch.altimeter.emplace_back(cam, *a);
    if (wanted.range[j])
      if (auto r = samples.range(cam_uav[j], k, t)) batch.range.emplace_back(cam, *r);
  }
  return batch;
}

}  // namespace wingman::app
