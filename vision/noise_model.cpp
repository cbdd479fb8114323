#include "vision/noise_model.hpp"

namespace wingman::vision {

DetectorNoise& FrontendNoiseModel::of(DetectorKind k) {
  switch (k) {
    case DetectorKind::Akaze: return akaze;
    case DetectorKind::Sift: return sift;
    case DetectorKind::GfttOrb: return gftt_orb;
    case DetectorKind::Orb: break;
  }
  return orb;
}

const DetectorNoise& FrontendNoiseModel::of(DetectorKind k) const {
  return const_cast<FrontendNoiseModel*>(this)->of(k);
}

}  // namespace wingman::vision
