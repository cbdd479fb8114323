// The frontend's pixel noise as the estimator should assume it, per detector: the white spread of
// an accepted correspondence about its true projection, and the constant part each track keeps
// (docs/frontend.md, noise model). `wingman calibrate-frontend` measures it on a rendered dataset
// against the true correspondences; assets/frontend/noise_model.yaml is its output on a shipped
// scene, and rendered runs that leave pixel_sigma `auto` take their figures from it.
#pragma once

#include <array>
#include <string>

#include "geometry/settings.hpp"
#include "vision/features.hpp"

namespace wingman::vision {

struct DetectorNoise {
  double pixel_sigma = 0;         // px per axis: scatter of a track's pixels about its mean
  double pixel_offset_sigma = 0;  // px per axis: the difference of two cameras' track offsets
  // What the figures were measured on; observations 0: this detector was not calibrated.
  int observations = 0, tracks = 0;
  double track_offset_rms = 0;    // px per axis, of one camera's track means
  double median_error_px = 0, p95_error_px = 0;  // of the error's norm

  bool calibrated() const { return observations > 0; }

  template <class V>
  void visit(V& v) {
    v("pixel_sigma", pixel_sigma, geometry::in(0, 1000, true));
    v("pixel_offset_sigma", pixel_offset_sigma, geometry::in(0, 1000));
    v("observations", observations, geometry::ge(1));
    v("tracks", tracks, geometry::ge(1));
    v("track_offset_rms", track_offset_rms, geometry::in(0, 1000));
    v("median_error_px", median_error_px, geometry::in(0, 1000));
    v("p95_error_px", p95_error_px, geometry::in(0, 1000));
  }
};

// Every detector the model has figures for, in the order the model file lists them.
inline constexpr std::array<DetectorKind, 4> kDetectorKinds = {DetectorKind::Orb, DetectorKind::Akaze,
                                                                DetectorKind::Sift, DetectorKind::GfttOrb};

struct FrontendNoiseModel {
  std::string made_by;  // the command that wrote it
  DetectorNoise orb, akaze, sift, gftt_orb;

  const DetectorNoise& of(DetectorKind k) const;
  DetectorNoise& of(DetectorKind k);

  template <class V>
  void visit(V& v) {
    v("made_by", made_by);
    v.section("detectors", [&](auto& d) {
      d.section("orb", [&](auto& s) { orb.visit(s); });
      d.section("akaze", [&](auto& s) { akaze.visit(s); });
      d.section("sift", [&](auto& s) { sift.visit(s); });
      d.section("gftt_orb", [&](auto& s) { gftt_orb.visit(s); });
    });
  }
};

}  // namespace wingman::vision
