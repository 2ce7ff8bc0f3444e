#include "api.h"

#include <haze/core/error.h>

#include <cstdio>

namespace haze::gl::internal {

namespace {
thread_local const Api* current = nullptr;

std::string error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: {
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%04x", e);
      return hex;
    }
  }
}
}  // namespace

std::shared_ptr<const Api> load_api(ProcLoader loader) {
  auto table = std::make_shared<Api>();
  Api& api = *table;
#define HAZE_GL_LOAD(type, name)                                 \
  api.name = reinterpret_cast<type>(loader("gl" #name));         \
  if (!api.name) throw Error("gl entry point", "gl" #name " missing", "an OpenGL 3.3 core driver");
  HAZE_GL_FUNCTIONS(HAZE_GL_LOAD)
#undef HAZE_GL_LOAD
  GLint major = 0, minor = 0;
  api.GetIntegerv(GL_MAJOR_VERSION, &major);
  api.GetIntegerv(GL_MINOR_VERSION, &minor);
  api.version = major * 10 + minor;
  if (api.version >= 44) api.BufferStorage = reinterpret_cast<PFNGLBUFFERSTORAGEPROC>(loader("glBufferStorage"));
  return table;
}

std::string gl_string(const Api& api, int which) {
  const GLenum names[] = {GL_VENDOR, GL_RENDERER, GL_VERSION};
  const auto* s = reinterpret_cast<const char*>(api.GetString(names[which]));
  return s ? s : "";
}

const Api& api() {
  if (!current) throw Error("gl context", "none current on this thread", "a haze::gl::HeadlessContext alive on the calling thread");
  return *current;
}

void set_current(const Api* api) { current = api; }

void finish(const Api& api) { api.Finish(); }

void check(const Api& gl, const char* what) {
  const GLenum e = gl.GetError();
  if (e != GL_NO_ERROR) throw Error(what, error_name(e), "no OpenGL error");
}

}  // namespace haze::gl::internal
