#include "render/gl_context.hpp"

#include <stdexcept>

namespace wingman::render {

const char* to_string(GlBackend b) {
  switch (b) {
    case GlBackend::Auto: return "auto";
    case GlBackend::Egl: return "egl";
    case GlBackend::OsMesa: return "osmesa";
  }
  return "?";
}

GlBackend gl_backend_from_string(const std::string& s) {
  if (s == "auto") return GlBackend::Auto;
  if (s == "egl") return GlBackend::Egl;
  if (s == "osmesa") return GlBackend::OsMesa;
  throw std::invalid_argument("unknown GL backend '" + s + "' (expected auto, egl or osmesa)");
}

std::unique_ptr<GlContext> create_first_gl_context(
    const std::vector<std::pair<std::string, GlContextFactory>>& factories) {
  std::string why;
  for (const auto& [name, make] : factories) {
    try {
      return make();
    } catch (const GlContextError& e) {
      why += "\n  " + name + ": " + e.what();
    }
  }
  throw GlContextError("no OpenGL context could be created; tried:" + why);
}

std::unique_ptr<GlContext> create_gl_context(GlBackend backend) {
  if (backend == GlBackend::Egl) return create_egl_context();
  if (backend == GlBackend::OsMesa) return create_osmesa_context();
  return create_first_gl_context({{"egl", create_egl_context}, {"osmesa", create_osmesa_context}});
}

}  // namespace wingman::render
