// A frame as a shutter takes it (sim/camera_sensor.hpp): the scene integrated over the exposure
// (motion blur, as images at sub-frame instants averaged in linear light) and, under a rolling
// shutter, each row at its own time. The caller draws the scene at a time offset (the whole frame,
// or a band of rows); expose() composes, and knows nothing of what moves.
#pragma once

#include <functional>

#include "render/renderer.hpp"
#include "sim/camera_sensor.hpp"

namespace wingman::render {

// s from the frame's time to the middle of row r's exposure (0 under a global shutter); the middle
// row is at the frame's time.
double row_time(const sim::ShutterSpec& s, double row, int height);

// The whole image with the scene at sub-frame time offset dt (under a rolling shutter, each row
// at its own time plus dt).
using SubframeRenderer = std::function<Frame(double dt)>;
// Rows [row0, row0 + rows) of the image (a Frame of `rows` rows) with the scene at time offset dt.
using BandRenderer = std::function<Frame(double dt, int row0, int rows)>;
// How many images the exposure takes (odd), given its middle image (which has depth).
using SubframeCount = std::function<int(const Frame& middle)>;

// The images an exposure needs for a predicted image motion of `smear_px` over it: one per
// s.subframe_motion_px of it (odd), one when it is under half of that, at most s.subframes;
// always s.subframes when subframe_motion_px is 0.
int subframes_for(const sim::ShutterSpec& s, double smear_px);

// The frame at sub-frame offset dt drawn in bands of s.rows_per_band rows (row by row for 0, all
// rows at once under a global shutter), each band with the time of its middle row.
Frame draw_in_bands(const sim::ShutterSpec& s, int width, int height, double dt, const BandRenderer& band);

// The frame the shutter takes with an exposure of `exposure_s`: count(middle) images at instants
// evenly spread over the exposure, centred on the frame's time (the middle one, at offset 0, drawn
// first), averaged in linear light (the rendered sRGB-like gamma of 2.2 undone and redone). Depth
// is that of the middle instant. No exposure is one image at the frame's time.
Frame expose(double exposure_s, const SubframeRenderer& render, const SubframeCount& count);
// The same with s.subframes images drawn in bands (draw_in_bands).
Frame expose(const sim::ShutterSpec& s, double exposure_s, int width, int height, const BandRenderer& render);

}  // namespace wingman::render
