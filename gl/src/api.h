// The OpenGL entry points haze::gl calls, loaded from the current context's driver (EGL or OSMesa
// get-proc-address) into a table: the two backends' libraries both export gl* symbols, so linking
// against either would call the wrong one for the other (internal).
#pragma once

#include <GL/glcorearb.h>

#include "loader.h"

#include <string>

namespace haze::gl::internal {

#define HAZE_GL_FUNCTIONS(X)                                                                                             \
  X(PFNGLGETERRORPROC, GetError)                                                                                         \
  X(PFNGLGETSTRINGPROC, GetString)                                                                                       \
  X(PFNGLGETSTRINGIPROC, GetStringi)                                                                                     \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                                                   \
  X(PFNGLFINISHPROC, Finish)                                                                                             \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                                                   \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                                                                   \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                                                             \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                                                                   \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                                                               \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                                                               \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                                                                     \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                                                               \
  X(PFNGLTEXIMAGE3DPROC, TexImage3D)                                                                                     \
  X(PFNGLTEXSUBIMAGE3DPROC, TexSubImage3D)                                                                               \
  X(PFNGLGETTEXIMAGEPROC, GetTexImage)                                                                                   \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                                                                     \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                                               \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                                                                     \
  X(PFNGLBUFFERDATAPROC, BufferData)                                                                                     \
  X(PFNGLMAPBUFFERRANGEPROC, MapBufferRange)                                                                             \
  X(PFNGLUNMAPBUFFERPROC, UnmapBuffer)                                                                                   \
  X(PFNGLFENCESYNCPROC, FenceSync)                                                                                       \
  X(PFNGLCLIENTWAITSYNCPROC, ClientWaitSync)                                                                             \
  X(PFNGLDELETESYNCPROC, DeleteSync)                                                                                     \
  X(PFNGLCREATESHADERPROC, CreateShader)                                                                                 \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                                                 \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                                                               \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                                                   \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                                                         \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                                                                 \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                                               \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                                                                 \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                                                   \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                                                 \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                                                       \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                                                               \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                                                                     \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                                                     \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                                                                       \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                                                                       \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                                                                       \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                                                                                       \
  X(PFNGLUNIFORM3IPROC, Uniform3i)                                                                                       \
  X(PFNGLUNIFORM1IVPROC, Uniform1iv)                                                                                     \
  X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                                                                     \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                                                                     \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                                                                     \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                                                         \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                                                           \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                                           \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                                                     \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                                                                     \
  X(PFNGLVIEWPORTPROC, Viewport)                                                                                         \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                                                           \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                                                     \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                                                           \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                                                                 \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                                             \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                                                                     \
  X(PFNGLREADPIXELSPROC, ReadPixels)

struct Api {
#define HAZE_GL_DECLARE(type, name) type name = nullptr;
  HAZE_GL_FUNCTIONS(HAZE_GL_DECLARE)
#undef HAZE_GL_DECLARE
  // GL 4.4 / ARB_buffer_storage: immutable buffers that stay mapped while GL reads them.
  PFNGLBUFFERSTORAGEPROC BufferStorage = nullptr;
  int version = 0;  // major * 10 + minor
};

// The table of the context current on this thread (set by HeadlessContext). Throws haze::Error
// when no HeadlessContext is current here.
const Api& api();

// Throws haze::Error naming `what` when glGetError reports an error.
void check(const Api& gl, const char* what);

}  // namespace haze::gl::internal
