// OSMesa backend: Mesa's pure-software off-screen context. Rendering goes to framebuffer objects;
// the 1x1 buffer OSMesaMakeCurrent needs is never drawn to.
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <string>

#include "render/gl_context.hpp"

namespace wingman::render {
namespace {

using CreateAttribs = OSMesaContext (*)(const int*, OSMesaContext);
using MakeCurrent = GLboolean (*)(OSMesaContext, void*, GLenum, GLsizei, GLsizei);
using Destroy = void (*)(OSMesaContext);
using GetProc = OSMESAproc (*)(const char*);

class OsMesaContext final : public GlContext {
 public:
  OsMesaContext(void* lib, OSMesaContext ctx, MakeCurrent mc, Destroy d, GetProc gp)
      : lib_(lib), ctx_(ctx), make_current_(mc), destroy_(d), get_proc_(gp) {}
  ~OsMesaContext() override { destroy_(ctx_); }
  void* proc_address(const char* name) const override {
    return reinterpret_cast<void*>(get_proc_(name));
  }
  void make_current() override {
    if (!make_current_(ctx_, buffer_, GL_UNSIGNED_BYTE, 1, 1))
      throw GlContextError("OSMesaMakeCurrent failed");
  }
  std::string description() const override { return what_; }
  GlBackend backend() const override { return GlBackend::OsMesa; }
  void set_description(std::string d) { what_ = std::move(d); }

 private:
  void* lib_;
  OSMesaContext ctx_;
  MakeCurrent make_current_;
  Destroy destroy_;
  GetProc get_proc_;
  unsigned char buffer_[4] = {0, 0, 0, 0};
  std::string what_ = "osmesa";
};

}  // namespace

std::unique_ptr<GlContext> create_osmesa_context() {
  void* lib = dlopen("libOSMesa.so.8", RTLD_NOW | RTLD_LOCAL);
  if (!lib) lib = dlopen("libOSMesa.so", RTLD_NOW | RTLD_LOCAL);
  if (!lib)
    throw GlContextError(std::string("cannot load libOSMesa.so.8 (Debian: libosmesa6): ") +
                         dlerror());
  auto create = reinterpret_cast<CreateAttribs>(dlsym(lib, "OSMesaCreateContextAttribs"));
  auto mc = reinterpret_cast<MakeCurrent>(dlsym(lib, "OSMesaMakeCurrent"));
  auto destroy = reinterpret_cast<Destroy>(dlsym(lib, "OSMesaDestroyContext"));
  auto gp = reinterpret_cast<GetProc>(dlsym(lib, "OSMesaGetProcAddress"));
  if (!create || !mc || !destroy || !gp)
    throw GlContextError("libOSMesa lacks OSMesaCreateContextAttribs (needs Mesa >= 11)");
  const int attrs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                       OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                       OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  OSMesaContext ctx = create(attrs, nullptr);
  if (!ctx) throw GlContextError("OSMesaCreateContextAttribs (OpenGL 3.3 core) failed");
  auto c = std::make_unique<OsMesaContext>(lib, ctx, mc, destroy, gp);
  c->make_current();
  using GetString = const unsigned char* (*)(unsigned);
  auto gs = reinterpret_cast<GetString>(c->proc_address("glGetString"));
  const unsigned char* r = gs ? gs(0x1F01) : nullptr;
  const unsigned char* v = gs ? gs(0x1F02) : nullptr;
  c->set_description(std::string("osmesa (") + (r ? reinterpret_cast<const char*>(r) : "?") +
                     ", OpenGL " + (v ? reinterpret_cast<const char*>(v) : "?") + ")");
  return c;
}

}  // namespace wingman::render
