// Off-screen OpenGL contexts behind one small interface (like pyrender's platforms/): EGL on
// Mesa's surfaceless platform or on a GPU through EGL_EXT_platform_device (egl_context.cpp), and
// OSMesa (osmesa_context.cpp). The libraries are opened with dlopen and every GL entry point is
// resolved through the active backend's GetProcAddress, so libEGL and libOSMesa never clash on
// symbol names and a missing library is an error at run time, not at link time.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace wingman::render {

enum class GlBackend { Auto, Egl, OsMesa };
const char* to_string(GlBackend b);
// "auto", "egl" or "osmesa"; throws std::invalid_argument otherwise.
GlBackend gl_backend_from_string(const std::string& s);

// No context could be made; the message lists each backend tried and why it failed.
class GlContextError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  // The GL function named, or nullptr.
  virtual void* proc_address(const char* name) const = 0;
  virtual void make_current() = 0;
  // "egl (surfaceless, llvmpipe)" and the like: what was made and on which renderer.
  virtual std::string description() const = 0;
  virtual GlBackend backend() const = 0;
};

// An OpenGL >= 3.3 core context. Auto tries EGL (device platform, then surfaceless), then OSMesa.
// Env WINGMAN_EGL_DEVICE=<index> picks an EGL device.
std::unique_ptr<GlContext> create_gl_context(GlBackend backend);

// The first context one of these factories makes, in order; when all fail, a GlContextError
// lists each by name with its reason (what create_gl_context(Auto) does with EGL and OSMesa).
using GlContextFactory = std::unique_ptr<GlContext> (*)();
std::unique_ptr<GlContext> create_first_gl_context(
    const std::vector<std::pair<std::string, GlContextFactory>>& factories);

// One backend only; throws GlContextError naming what failed.
std::unique_ptr<GlContext> create_egl_context();
std::unique_ptr<GlContext> create_osmesa_context();

}  // namespace wingman::render
