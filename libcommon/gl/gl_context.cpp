// OSMesa context management. OSMesa API: Mesa's include/GL/osmesa.h.
#include "libcommon/gl/gl_api.h"
// gl_api.h first: it must define GL_GLEXT_PROTOTYPES before any GL header.
#include "libcommon/gl/gl_context.h"

#include <GL/osmesa.h>

#include <algorithm>

#include "libcommon/core/error.h"

namespace rad {
namespace {

Error environmentError(const std::string& what) {
  return Error(ExitCode::kEnvironment, "osmesa", what);
}

const char* errorName(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    default:
      return "unknown GL error";
  }
}

std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
}

GLuint compileShader(const std::string& name, GLenum type, const std::string& source) {
  GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw Error(ExitCode::kInternal, "glsl " + name,
                std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                    " shader does not compile: " + log.c_str());
  }
  return shader;
}

}  // namespace

GlContext::GlContext() {
  // Core profile 4.5: FBOs, integer targets, GL_DEPTH_COMPONENT32F and glClipControl.
  // No depth/stencil/accum in the dummy default framebuffer: all rendering goes to FBOs.
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         4,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         5,
                         0};
  OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx)
    throw environmentError(
        "cannot create an OpenGL 4.5 core context (OSMesaCreateContextAttribs failed; is "
        "libosmesa6 with llvmpipe installed?)");
  context_ = ctx;
  dummy_.assign(4, 0);
  if (!OSMesaMakeCurrent(ctx, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    OSMesaDestroyContext(ctx);
    context_ = nullptr;
    throw environmentError("cannot make the OpenGL context current (OSMesaMakeCurrent failed)");
  }
  // GL's default for pixel rows is fine for 4-byte texels, but make packing explicit.
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
}

GlContext::~GlContext() {
  if (context_) {
    if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(context_))
      OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
  }
}

void GlContext::makeCurrent() {
  auto ctx = static_cast<OSMesaContext>(context_);
  if (OSMesaGetCurrentContext() == ctx) return;
  if (!OSMesaMakeCurrent(ctx, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1))
    throw environmentError("cannot make the OpenGL context current (OSMesaMakeCurrent failed)");
}

std::string GlContext::renderer() const {
  return glString(GL_RENDERER);
}
std::string GlContext::version() const {
  return glString(GL_VERSION);
}

void* glProcAddress(const char* name) {
  void* p = reinterpret_cast<void*>(OSMesaGetProcAddress(name));
  if (!p) throw environmentError(std::string("the GL driver lacks ") + name);
  return p;
}

unsigned compileProgram(const std::string& name, const std::string& vertexSource,
                        const std::string& fragmentSource) {
  GLuint vs = compileShader(name, GL_VERTEX_SHADER, vertexSource);
  GLuint fs = 0;
  try {
    fs = compileShader(name, GL_FRAGMENT_SHADER, fragmentSource);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  // The program keeps the compiled code; the shader objects can go now.
  glDetachShader(program, vs);
  glDetachShader(program, fs);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    throw Error(ExitCode::kInternal, "glsl " + name, std::string("does not link: ") + log.c_str());
  }
  return program;
}

void checkGlError(const std::string& where) {
  std::string names;
  bool outOfMemory = false;
  // glGetError returns one flag per call; bounded loop in case a broken driver never clears.
  for (int i = 0; i < 16; ++i) {
    GLenum e = glGetError();
    if (e == GL_NO_ERROR) break;
    outOfMemory = outOfMemory || e == GL_OUT_OF_MEMORY;
    names += names.empty() ? errorName(e) : std::string(", ") + errorName(e);
  }
  if (names.empty()) return;
  throw Error(outOfMemory ? ExitCode::kEnvironment : ExitCode::kInternal, "gl: " + where, names);
}

void configureReversedZ() {
  using ClipControlFn = void(APIENTRY*)(GLenum, GLenum);
  // Not exported by libOSMesa (see gl_api.h); core since GL 4.5.
  static const auto clipControl = reinterpret_cast<ClipControlFn>(glProcAddress("glClipControl"));
  clipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glDepthFunc(GL_GREATER);
  glClearDepthf(0.0f);
}

}  // namespace rad
