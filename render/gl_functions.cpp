#include "render/gl_functions.hpp"

#include <cstring>
#include <string>

namespace wingman::render {

void GlFunctions::load(const GlContext& ctx) {
#define WINGMAN_GL_LOAD(type, name)                                                        \
  name = reinterpret_cast<type>(ctx.proc_address("gl" #name));                            \
  if (!name) throw GlContextError(ctx.description() + ": OpenGL function gl" #name " missing");
  WINGMAN_GL_FUNCTIONS(WINGMAN_GL_LOAD)
#undef WINGMAN_GL_LOAD
  if (has_version_or_extension(4, 5, "GL_ARB_clip_control"))
    ClipControl = reinterpret_cast<PFNGLCLIPCONTROLPROC>(ctx.proc_address("glClipControl"));
}

bool GlFunctions::has_version_or_extension(int major, int minor, const char* extension) const {
  GLint ma = 0, mi = 0, n = 0;
  GetIntegerv(GL_MAJOR_VERSION, &ma);
  GetIntegerv(GL_MINOR_VERSION, &mi);
  if (ma > major || (ma == major && mi >= minor)) return true;
  GetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i) {
    const auto* e = reinterpret_cast<const char*>(GetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
    if (e && std::strcmp(e, extension) == 0) return true;
  }
  return false;
}

}  // namespace wingman::render
