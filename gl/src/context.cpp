#include <haze/core/error.h>
#include <haze/gl/context.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>

#include "loader.h"

#include <vector>

namespace haze::gl {

struct HeadlessContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext egl_context = EGL_NO_CONTEXT;
  OSMesaContext osmesa = nullptr;
  std::vector<unsigned char> osmesa_buffer;
  std::shared_ptr<const internal::Api> api;

  // EGL_MESA_platform_surfaceless + EGL_KHR_surfaceless_context: no window system at all.
  std::string try_egl() {
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) return "EGL: eglGetPlatformDisplayEXT missing";
    display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
      display = EGL_NO_DISPLAY;
      return "EGL: no surfaceless display";
    }
    if (!eglBindAPI(EGL_OPENGL_API)) return "EGL: OpenGL API not bindable";
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    egl_context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (egl_context == EGL_NO_CONTEXT) return "EGL: no OpenGL 3.3 core context";
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_context)) return "EGL: eglMakeCurrent failed";
    return {};
  }

  std::string try_osmesa() {
    const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    osmesa = OSMesaCreateContextAttribs(attributes, nullptr);
    if (!osmesa) return "OSMesa: no OpenGL 3.3 core context";
    osmesa_buffer.assign(4 * 16 * 16, 0);
    if (!OSMesaMakeCurrent(osmesa, osmesa_buffer.data(), GL_UNSIGNED_BYTE, 16, 16)) return "OSMesa: make current failed";
    return {};
  }

  void release() {
    if (egl_context != EGL_NO_CONTEXT) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, egl_context);
      egl_context = EGL_NO_CONTEXT;
    }
    if (display != EGL_NO_DISPLAY) {
      eglTerminate(display);
      display = EGL_NO_DISPLAY;
    }
    if (osmesa) {
      OSMesaDestroyContext(osmesa);
      osmesa = nullptr;
    }
  }
};

HeadlessContext::HeadlessContext() : impl_(std::make_unique<Impl>()) {
  std::string egl_error = impl_->try_egl();
  if (egl_error.empty()) {
    info_.backend = "egl-surfaceless";
  } else {
    impl_->release();
    std::string osmesa_error = impl_->try_osmesa();
    if (!osmesa_error.empty()) {
      impl_->release();
      throw Error("gl context", egl_error + "; " + osmesa_error, "an EGL surfaceless or OSMesa OpenGL 3.3 context");
    }
    info_.backend = "osmesa";
  }
  try {
    impl_->api = internal::load_api(info_.backend == "osmesa" ? internal::ProcLoader(&OSMesaGetProcAddress)
                                                              : internal::ProcLoader(&eglGetProcAddress));
  } catch (...) {
    impl_->release();
    throw;
  }
  internal::set_current(impl_->api.get());
  info_.available = true;
  info_.vendor = internal::gl_string(*impl_->api, internal::kVendor);
  info_.renderer = internal::gl_string(*impl_->api, internal::kRenderer);
  info_.version = internal::gl_string(*impl_->api, internal::kVersion);
}

HeadlessContext::~HeadlessContext() {
  internal::set_current(nullptr);
  impl_->release();
}

void HeadlessContext::finish() const { internal::finish(*impl_->api); }

HeadlessContext::ProcAddress HeadlessContext::proc_address(const char* name) const {
  return info_.backend == "osmesa" ? reinterpret_cast<ProcAddress>(OSMesaGetProcAddress(name))
                                   : reinterpret_cast<ProcAddress>(eglGetProcAddress(name));
}

GlInfo probe() {
  try {
    HeadlessContext context;
    return context.info();
  } catch (const std::exception& e) {
    GlInfo info;
    info.error = e.what();
    return info;
  }
}

}  // namespace haze::gl
