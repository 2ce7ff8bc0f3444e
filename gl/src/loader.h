// Loading the OpenGL entry-point table for a new context, without the GL headers (context.cpp
// includes the EGL and OSMesa ones, which clash with glcorearb.h) (internal).
#pragma once

#include <memory>
#include <string>

namespace haze::gl::internal {

struct Api;
using ProcAddress = void (*)();
using ProcLoader = ProcAddress (*)(const char* name);

// The table from `loader` with the context current; throws haze::Error naming the first missing
// entry point.
std::shared_ptr<const Api> load_api(ProcLoader loader);
// GL_VENDOR, GL_RENDERER, GL_VERSION.
std::string gl_string(const Api& api, int which);
enum : int { kVendor, kRenderer, kVersion };

// glFinish on the current context.
void finish(const Api& api);

// Makes `api` the table api() returns on this thread (nullptr: none).
void set_current(const Api* api);

}  // namespace haze::gl::internal
