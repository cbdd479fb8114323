// A camera's shutter and image sensor (`uavs[i].camera.shutter`, `.sensor`; docs/rendering.md,
// Camera). The defaults are the paper's ideal camera: a global shutter with no exposure time and a
// noiseless sensor that passes the rendered image through. Plain data; render/ turns it into
// frames (render/shutter.hpp, render/sensor.hpp).
#pragma once

#include <algorithm>

#include "geometry/settings.hpp"

namespace wingman::sim {

struct ShutterSpec {
  enum class Type { Global, Rolling };
  enum class Readout { TopToBottom, BottomToTop };
  Type type = Type::Global;
  // s the shutter is open; the frame integrates the moving scene over it (motion blur). 0: an
  // instant. With a physical sensor it also sets the brightness (auto_exposure may drive it).
  double exposure = 0;
  // Rolling shutter: s between the starts of consecutive rows. Row r is exposed around
  // t + (r - (h - 1) / 2) * line_delay (top to bottom), so the middle row is at the frame's time.
  double line_delay = 0;
  Readout readout = Readout::TopToBottom;
  // Images averaged over the exposure (odd: the middle one is at mid-exposure, where depth and
  // the labels are taken); with subframe_motion_px above 0, the most.
  int subframes = 31;
  // px of image motion per image: a frame takes as many images as the image motion predicted over
  // its exposure needs (one when it is under half of this; render/shutter.hpp subframes_for),
  // capped at `subframes`. 0: always `subframes` images.
  double subframe_motion_px = 0.5;
  // Rolling shutter: 0 draws a frame in one pass, each vertex with the pose of the row it lands on
  // (exact on geometry tessellated finer than the image motion over the readout bends it);
  // n > 0 draws bands of n rows with one pose each (1: every row its own pose, the reference; more
  // is off by up to n / 2 line delays).
  int rows_per_band = 0;

  template <class V>
  void visit(V& v) {
    v.choice("type", type, {{"global", Type::Global}, {"rolling", Type::Rolling}});
    v("exposure", exposure, geometry::in(0, 1));
    v("line_delay", line_delay, geometry::in(0, 1e-3));
    v.choice("readout", readout, {{"top_to_bottom", Readout::TopToBottom}, {"bottom_to_top", Readout::BottomToTop}});
    v("subframes", subframes, geometry::in(1, 255));
    v.check("subframes", subframes % 2 == 1, "must be odd, so that one image lies at mid-exposure");
    v("subframe_motion_px", subframe_motion_px, geometry::in(0, 100));
    v("rows_per_band", rows_per_band, geometry::in(0, 16384));
    v.check("line_delay", type == Type::Global || line_delay > 0, "must be above 0 for a rolling shutter");
  }
  bool rolling() const { return type == Type::Rolling && line_delay > 0; }
};

// Auto-exposure: after each frame the exposure (then the gain, once exposure is at its maximum)
// moves a fraction `rate` of the way, in log terms, toward what brings the frame's mean grey to
// `target`; a real camera's controller lags the same way.
struct AutoExposureSpec {
  bool enabled = false;
  double target = 0.45;        // mean grey level of the output, 0-1
  double rate = 0.3;           // fraction of the log error corrected per frame
  double min_exposure = 2e-5;  // s
  double max_exposure = 0.02;  // s
  double max_gain = 8;

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("target", target, geometry::in(0, 1, true, true));
    v("rate", rate, geometry::in(0, 1, true, false));
    v("min_exposure", min_exposure, geometry::in(0, 1, true, false));
    v("max_exposure", max_exposure, geometry::in(0, 1, true, false));
    v.check("max_exposure", max_exposure >= min_exposure, "must be at least min_exposure");
    v("max_gain", max_gain, geometry::in(1, 1024));
  }
};

// The image sensor (EMVA 1288's linear model): the rendered image, taken as gamma-encoded scene
// radiance, becomes electrons (full_well at white for an exposure of reference_exposure),
// fixed-pattern gain (PRNU) and offset (DSNU), dark signal, photon shot noise (Poisson), read
// noise, the gain, an ADC of `bits`, and the response curve (gamma) back to 8 bits. Vignetting
// darkens off-axis pixels by the cos^4 law, scaled by `vignetting`.
struct SensorSpec {
  enum class Model { Ideal, Physical };
  Model model = Model::Ideal;
  double full_well = 10000;          // e- at saturation
  double reference_exposure = 0.005;  // s of exposure that fills the well on rendered white
  double read_noise = 5;             // e- rms
  double dark_current = 50;          // e-/s
  double prnu = 0.01;                // relative rms of the per-pixel gain
  double dsnu = 2;                   // e- rms of the per-pixel dark offset
  int bits = 10;                     // ADC
  double gamma = 2.2;                // response curve: output = signal^(1/gamma)
  double gain = 1;                   // analogue gain (auto_exposure may raise it)
  double vignetting = 0;             // 0: none; 1: the full cos^4 falloff
  AutoExposureSpec auto_exposure{};

  template <class V>
  void visit(V& v) {
    v.choice("model", model, {{"ideal", Model::Ideal}, {"physical", Model::Physical}});
    v("full_well", full_well, geometry::in(100, 1e7));
    v("reference_exposure", reference_exposure, geometry::in(0, 1, true, false));
    v("read_noise", read_noise, geometry::in(0, 1000));
    v("dark_current", dark_current, geometry::in(0, 1e6));
    v("prnu", prnu, geometry::in(0, 0.5));
    v("dsnu", dsnu, geometry::in(0, 1000));
    v("bits", bits, geometry::in(1, 16));
    v("gamma", gamma, geometry::in(0.1, 10));
    v("gain", gain, geometry::in(0, 1024, true, false));
    v("vignetting", vignetting, geometry::in(0, 1));
    v.section("auto_exposure", [&](auto& x) { auto_exposure.visit(x); });
  }
  bool physical() const { return model == Model::Physical; }
  // The first frame's exposure: the shutter's (the reference exposure when that is 0), within
  // auto-exposure's range; the ideal sensor keeps the shutter's.
  double initial_exposure(double shutter_exposure) const {
    if (!physical()) return shutter_exposure;
    const double e = shutter_exposure > 0 ? shutter_exposure : reference_exposure;
    return auto_exposure.enabled ? std::clamp(e, auto_exposure.min_exposure, auto_exposure.max_exposure) : e;
  }
};

}  // namespace wingman::sim
