#include "render/gl_functions.hpp"

#include <string>

namespace wingman::render {

void GlFunctions::load(const GlContext& ctx) {
#define WINGMAN_GL_LOAD(type, name)                                                        \
  name = reinterpret_cast<type>(ctx.proc_address("gl" #name));                            \
  if (!name) throw GlContextError(ctx.description() + ": OpenGL function gl" #name " missing");
  WINGMAN_GL_FUNCTIONS(WINGMAN_GL_LOAD)
#undef WINGMAN_GL_LOAD
}

}  // namespace wingman::render
