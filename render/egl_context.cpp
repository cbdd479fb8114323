// EGL backend: the device platform (EGL_EXT_platform_device: a GPU with no display, NVIDIA's
// driver included; hardware devices before software ones), then Mesa's surfaceless platform.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "render/gl_context.hpp"

namespace wingman::render {
namespace {

struct EglApi {
  void* lib = nullptr;
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLTERMINATEPROC Terminate = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC QueryDeviceStringEXT = nullptr;
};

template <typename F>
void load(const EglApi& a, F& f, const char* name) {
  f = reinterpret_cast<F>(dlsym(a.lib, name));
  if (!f && a.GetProcAddress) f = reinterpret_cast<F>(a.GetProcAddress(name));
}

std::string egl_error(const EglApi& a) {
  const EGLint e = a.GetError();
  switch (e) {
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error " + std::to_string(e);
  }
}

bool has_ext(const char* list, const std::string& ext) {
  if (!list) return false;
  const std::string s = std::string(" ") + list + " ";
  return s.find(" " + ext + " ") != std::string::npos;
}

class EglContext final : public GlContext {
 public:
  EglContext(EglApi api, EGLDisplay dpy, EGLContext ctx, std::string what)
      : api_(api), dpy_(dpy), ctx_(ctx), what_(std::move(what)) {}
  ~EglContext() override {
    api_.MakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    api_.DestroyContext(dpy_, ctx_);
    // The display is not terminated: other contexts of this process may share it (EGL
    // displays are per platform and device, not per context).
  }
  void* proc_address(const char* name) const override {
    return reinterpret_cast<void*>(api_.GetProcAddress(name));
  }
  void make_current() override {
    if (!api_.MakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_))
      throw GlContextError("eglMakeCurrent failed: " + egl_error(api_));
  }
  std::string description() const override { return what_; }
  GlBackend backend() const override { return GlBackend::Egl; }

 private:
  EglApi api_;
  EGLDisplay dpy_;
  EGLContext ctx_;
  std::string what_;
};

// A core context on an initialised display, made current; empty with `why` on failure.
EGLContext make_context(const EglApi& a, EGLDisplay dpy, std::string& why) {
  EGLint major = 0, minor = 0;
  if (!a.Initialize(dpy, &major, &minor)) {
    why = "eglInitialize failed: " + egl_error(a);
    return EGL_NO_CONTEXT;
  }
  if (!a.BindAPI(EGL_OPENGL_API)) {
    why = "eglBindAPI(EGL_OPENGL_API) failed: " + egl_error(a);
    return EGL_NO_CONTEXT;
  }
  EGLConfig cfg = nullptr;
  if (!has_ext(a.QueryString(dpy, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) {
    const EGLint attrs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
                            EGL_NONE};
    EGLint n = 0;
    if (!a.ChooseConfig(dpy, attrs, &cfg, 1, &n) || n < 1) {
      why = "no EGL config with OpenGL";
      return EGL_NO_CONTEXT;
    }
  }
  const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = a.CreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attrs);
  if (ctx == EGL_NO_CONTEXT) {
    why = "eglCreateContext (OpenGL 3.3 core) failed: " + egl_error(a);
    return EGL_NO_CONTEXT;
  }
  if (!a.MakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
    why = "eglMakeCurrent without a surface failed: " + egl_error(a);
    a.DestroyContext(dpy, ctx);
    return EGL_NO_CONTEXT;
  }
  return ctx;
}

std::string renderer_name(const EglApi& a) {
  using GetString = const unsigned char* (*)(unsigned);
  auto gs = reinterpret_cast<GetString>(a.GetProcAddress("glGetString"));
  const unsigned char* r = gs ? gs(0x1F01 /*GL_RENDERER*/) : nullptr;
  const unsigned char* v = gs ? gs(0x1F02 /*GL_VERSION*/) : nullptr;
  return std::string(r ? reinterpret_cast<const char*>(r) : "?") + ", OpenGL " +
         (v ? reinterpret_cast<const char*>(v) : "?");
}

}  // namespace

std::unique_ptr<GlContext> create_egl_context() {
  EglApi a;
  a.lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!a.lib) throw GlContextError(std::string("cannot load libEGL.so.1: ") + dlerror());
  a.GetProcAddress = reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(dlsym(a.lib, "eglGetProcAddress"));
  if (!a.GetProcAddress) throw GlContextError("libEGL.so.1 has no eglGetProcAddress");
  load(a, a.QueryString, "eglQueryString");
  load(a, a.GetError, "eglGetError");
  load(a, a.Initialize, "eglInitialize");
  load(a, a.Terminate, "eglTerminate");
  load(a, a.BindAPI, "eglBindAPI");
  load(a, a.ChooseConfig, "eglChooseConfig");
  load(a, a.CreateContext, "eglCreateContext");
  load(a, a.DestroyContext, "eglDestroyContext");
  load(a, a.MakeCurrent, "eglMakeCurrent");
  load(a, a.GetPlatformDisplayEXT, "eglGetPlatformDisplayEXT");
  load(a, a.QueryDevicesEXT, "eglQueryDevicesEXT");
  load(a, a.QueryDeviceStringEXT, "eglQueryDeviceStringEXT");
  if (!a.QueryString || !a.GetError || !a.Initialize || !a.BindAPI || !a.CreateContext ||
      !a.MakeCurrent || !a.ChooseConfig || !a.DestroyContext)
    throw GlContextError("libEGL.so.1 lacks EGL 1.4 core functions");
  if (!a.GetPlatformDisplayEXT)
    throw GlContextError("EGL has no eglGetPlatformDisplayEXT (EGL_EXT_platform_base)");
  const char* client = a.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);

  std::vector<std::string> tried;
  // 1. Device platform; hardware devices first.
  if (has_ext(client, "EGL_EXT_platform_device") && a.QueryDevicesEXT) {
    EGLDeviceEXT devs[16];
    EGLint n = 0;
    if (a.QueryDevicesEXT(16, devs, &n) && n > 0) {
      std::vector<int> order;
      const char* pick = std::getenv("WINGMAN_EGL_DEVICE");
      for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i < n; ++i) {
          if (pick && std::atoi(pick) != i) continue;
          const char* ext = a.QueryDeviceStringEXT ? a.QueryDeviceStringEXT(devs[i], EGL_EXTENSIONS)
                                                   : nullptr;
          const bool software = has_ext(ext, "EGL_MESA_device_software");
          if (software == (pass == 1)) order.push_back(i);
        }
      }
      for (int i : order) {
        EGLDisplay dpy = a.GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devs[i], nullptr);
        std::string why = "eglGetPlatformDisplayEXT failed";
        if (dpy != EGL_NO_DISPLAY) {
          if (EGLContext ctx = make_context(a, dpy, why); ctx != EGL_NO_CONTEXT)
            return std::make_unique<EglContext>(
                a, dpy, ctx, "egl device " + std::to_string(i) + " (" + renderer_name(a) + ")");
        }
        tried.push_back("device " + std::to_string(i) + ": " + why);
      }
    } else {
      tried.push_back("device platform: no EGL devices");
    }
  } else {
    tried.push_back("device platform: EGL_EXT_platform_device not supported");
  }
  // 2. Mesa's surfaceless platform.
  if (has_ext(client, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay dpy = a.GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                                             nullptr);
    std::string why = "eglGetPlatformDisplayEXT failed";
    if (dpy != EGL_NO_DISPLAY) {
      if (EGLContext ctx = make_context(a, dpy, why); ctx != EGL_NO_CONTEXT)
        return std::make_unique<EglContext>(a, dpy, ctx,
                                            "egl surfaceless (" + renderer_name(a) + ")");
    }
    tried.push_back("surfaceless: " + why);
  } else {
    tried.push_back("surfaceless: EGL_MESA_platform_surfaceless not supported");
  }
  std::string msg = "no EGL context";
  for (const auto& t : tried) msg += "; " + t;
  throw GlContextError(msg);
}

}  // namespace wingman::render
