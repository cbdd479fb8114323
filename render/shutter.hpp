// A frame as a shutter takes it (sim/camera_sensor.hpp): the scene integrated over the exposure
// (motion blur, as images at sub-frame instants averaged in linear light) and, under a rolling
// shutter, each row at its own time. The caller draws the scene at a time offset for a band of
// rows; exposure() composes, and knows nothing of what moves.
#pragma once

#include <functional>

#include "render/renderer.hpp"
#include "sim/camera_sensor.hpp"

namespace wingman::render {

// s from the frame's time to the middle of row r's exposure (0 under a global shutter); the middle
// row is at the frame's time.
double row_time(const sim::ShutterSpec& s, double row, int height);

// Rows [row0, row0 + rows) of the image (a Frame of `rows` rows) with the scene at time offset dt.
using BandRenderer = std::function<Frame(double dt, int row0, int rows)>;

// The width x height frame the shutter takes with an exposure of `exposure_s`: `subframes` images
// at instants evenly spread over the exposure, centred on each row's time, averaged in linear light
// (the rendered sRGB-like gamma of 2.2 undone and redone). Depth is that of the middle instant.
// A global shutter with no exposure is one render of the whole frame.
Frame expose(const sim::ShutterSpec& s, double exposure_s, int width, int height, const BandRenderer& render);

}  // namespace wingman::render
