// The renderer's GLSL, by pass: each program is the version line and some of these parts in order
// (render/renderer.cpp links them). The vertex shaders take a vertex's camera-frame position from
// eye(), which one of the *Eye parts defines (one view, or a rolling shutter's rows).
#pragma once

namespace wingman::render::shaders {

extern const char* const kVertexInputs;
extern const char* const kSceneVs;
extern const char* const kSceneFs;
extern const char* const kShadowedVs;
extern const char* const kShadowedFs;
extern const char* const kImageLookup;
extern const char* const kStochasticLookup;
extern const char* const kDepthInputs;
extern const char* const kDepthVs;
extern const char* const kOneViewEye;
extern const char* const kRollingEye;
extern const char* const kDepthFs;
// The ground's stochastic tiling baked into a texture (render/ground_bake.hpp): a triangle over
// the target; with kStochasticLookup, each texel the live surface at its centre.
extern const char* const kBakeVs;
extern const char* const kBakeFs;

}  // namespace wingman::render::shaders
