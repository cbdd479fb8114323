// The OpenGL entry points the renderer uses, resolved once per context through the backend's
// GetProcAddress (render/gl_context.hpp) instead of linking libGL.
#pragma once

#include <GL/glcorearb.h>

#include "render/gl_context.hpp"

namespace wingman::render {

#define WINGMAN_GL_FUNCTIONS(X)                                                                 \
  X(PFNGLGETSTRINGPROC, GetString) X(PFNGLGETSTRINGIPROC, GetStringi)                           \
  X(PFNGLGETINTEGERVPROC, GetIntegerv) X(PFNGLGETFLOATVPROC, GetFloatv)                         \
  X(PFNGLGETERRORPROC, GetError) X(PFNGLENABLEPROC, Enable) X(PFNGLDISABLEPROC, Disable)        \
  X(PFNGLVIEWPORTPROC, Viewport) X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                       \
  X(PFNGLDEPTHFUNCPROC, DepthFunc) X(PFNGLGENBUFFERSPROC, GenBuffers)                           \
  X(PFNGLBINDBUFFERPROC, BindBuffer) X(PFNGLBUFFERDATAPROC, BufferData)                         \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers) X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)         \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                  \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                            \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                          \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                  \
  X(PFNGLCREATESHADERPROC, CreateShader) X(PFNGLSHADERSOURCEPROC, ShaderSource)                 \
  X(PFNGLCOMPILESHADERPROC, CompileShader) X(PFNGLGETSHADERIVPROC, GetShaderiv)                 \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog) X(PFNGLCREATEPROGRAMPROC, CreateProgram)       \
  X(PFNGLATTACHSHADERPROC, AttachShader) X(PFNGLLINKPROGRAMPROC, LinkProgram)                   \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv) X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)       \
  X(PFNGLUSEPROGRAMPROC, UseProgram) X(PFNGLDELETESHADERPROC, DeleteShader)                     \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram) X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)   \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv) X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv) \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv) X(PFNGLUNIFORM1FPROC, Uniform1f)                           \
  X(PFNGLUNIFORM2FVPROC, Uniform2fv) X(PFNGLUNIFORM4FVPROC, Uniform4fv)                         \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                                            \
  X(PFNGLUNIFORM1IPROC, Uniform1i) X(PFNGLGENTEXTURESPROC, GenTextures)                         \
  X(PFNGLBINDTEXTUREPROC, BindTexture) X(PFNGLTEXIMAGE2DPROC, TexImage2D)                       \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri) X(PFNGLTEXPARAMETERFPROC, TexParameterf)             \
  X(PFNGLGENERATEMIPMAPPROC, GenerateMipmap) X(PFNGLACTIVETEXTUREPROC, ActiveTexture)           \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                                    \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers) X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)     \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                                        \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                  \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                    \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                            \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers) X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer) \
  X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample)                    \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers) X(PFNGLDRAWBUFFERSPROC, DrawBuffers)     \
  X(PFNGLREADBUFFERPROC, ReadBuffer) X(PFNGLREADPIXELSPROC, ReadPixels)                         \
  X(PFNGLPIXELSTOREIPROC, PixelStorei) X(PFNGLDRAWARRAYSPROC, DrawArrays)                       \
  X(PFNGLDRAWELEMENTSPROC, DrawElements) X(PFNGLFINISHPROC, Finish)                             \
  X(PFNGLMULTIDRAWELEMENTSPROC, MultiDrawElements) X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)   \
  X(PFNGLCOLORMASKPROC, ColorMask) X(PFNGLPOLYGONOFFSETPROC, PolygonOffset)                   \
  X(PFNGLSCISSORPROC, Scissor)                                                                  \
  X(PFNGLTEXPARAMETERFVPROC, TexParameterfv)

struct GlFunctions {
#define WINGMAN_GL_DECLARE(type, name) type name = nullptr;
  WINGMAN_GL_FUNCTIONS(WINGMAN_GL_DECLARE)
#undef WINGMAN_GL_DECLARE
  // Optional: GL 4.5 or ARB_clip_control (reversed-Z depth); null where the context lacks it.
  PFNGLCLIPCONTROLPROC ClipControl = nullptr;
  // Resolves every entry point; throws GlContextError naming the first one missing. The context
  // must be current (the optional ones depend on its version and extensions).
  void load(const GlContext& ctx);
  bool has_version_or_extension(int major, int minor, const char* extension) const;
};

}  // namespace wingman::render
